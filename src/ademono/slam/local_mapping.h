#pragma once
// Local mapping (ORB-SLAM's LocalMapping for RGB-D): for each new keyframe, registers its map
// points, culls recently created points that are rarely found, fuses duplicates with the
// covisible keyframes, runs a local bundle adjustment and culls redundant keyframes.
//
// Deterministic and concurrent: a fixed hand-off schedule. When tracking makes keyframe k at
// frame f, the map-editing steps (point registration, culling, triangulation, fusion) run at once
// on the tracking thread and the local BA problem is gathered there; the BA is then solved on the
// mapping thread from that snapshot, while tracking goes on against the unchanged map, and its
// result is merged (poses, points, outliers, then keyframe culling) under the map lock exactly
// when the mapping.handoff_frames-th frame after f starts (frames counted by HandOff calls, not by
// their numbers), or earlier when the next keyframe comes. Tracking
// never sees a half-applied BA and every decision depends only on the data, never on whether the
// mapper happens to be idle: outputs are identical run to run, under any load, and with
// mapping.threaded false (the solve runs on the tracking thread instead). handoff_frames 0 is the
// synchronous schedule (BA merged before the next frame).

#include <chrono>
#include <condition_variable>
#include <exception>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "ademono/core/worker_pool.h"
#include "ademono/optimize/bundle_adjustment.h"
#include "ademono/slam/loop_closing.h"
#include "ademono/slam/map.h"
#include "ademono/slam/options.h"

namespace ademono {

class LocalMapping {
 public:
  // `monocular`: the monocular core (tracking.monocular): every point counts in keyframe
  // culling, and triangulation keeps away from the epipole.
  // `configured_sigma_log`: the network's relative depth error as configured (0: no network).
  LocalMapping(Map& map, const MappingOptions& options, bool monocular = false,
               double configured_sigma_log = 0.0);
  ~LocalMapping();
  LocalMapping(const LocalMapping&) = delete;
  LocalMapping& operator=(const LocalMapping&) = delete;

  // Loop closing runs on each keyframe right after its merge (on the tracking thread, at the
  // keyframe's hand-off frame: a fixed point in the sequence). Null disables it. Set before the
  // first keyframe.
  void SetLoopClosing(LoopClosing* loop_closing) { loop_closing_ = loop_closing; }

  // Tracking thread, map.mutex not held, once at the start of every frame: advances the hand-off
  // clock and merges the pending keyframe's BA when this frame is its hand-off frame (waits for
  // the mapping thread if it is not done). The clock counts these calls, not the frames' numbers
  // (a run may start at frame 300; a camera's counter jumps).
  void HandOff();
  // Tracking thread, map.mutex not held: a keyframe made at the current frame. Merges a pending
  // keyframe first, maps this one's structure and starts its BA.
  void InsertKeyFrame(const std::shared_ptr<KeyFrame>& keyframe);
  // True when no keyframe waits for its hand-off. A function of the frame count alone (never
  // of the mapping thread's progress), so tracking may decide on it deterministically.
  bool Idle() const;
  size_t QueueSize() const { return Idle() ? 0 : 1; }
  // Merges the pending keyframe and stops the worker. Idempotent.
  void Shutdown();
  // Monocular core with a network: the network's per-point error (robust spread of log depth
  // after each keyframe's affine map, InverseDepthAffine::sigma_log) measured so far against
  // triangulated points, or the configured error model's until there is a measurement.
  double NetworkSigmaLog() const;
  // The part of that error a view's points share (InverseDepthAffine::shared_sigma_log, recent
  // keyframes' median; 0 until measured or with mapping.network_shared_error off).
  double NetworkSharedSigmaLog() const;
  // Monocular core with a network: keypoint i of `kf` with its network depth as a prior
  // observation (the keyframe's fitted error model applied when it has one). `priors_in_view`:
  // how many of kf's priors enter the same solve; their shared error counts once among them
  // (relative sigma sqrt(sigma_log^2 + n * shared^2)).
  ImageObservation NetworkPrior(const KeyFrame& kf, size_t i, int priors_in_view = 1) const
      ADEMONO_REQUIRES(map_.mutex);
  // Monocular core with a network: whether point `p`'s network-depth prior still enters local BA
  // (geometry's depth of it less certain than the network's: too little parallax).
  bool PriorActive(const MapPoint& p) const ADEMONO_REQUIRES(map_.mutex);
  // Whether keyframe `kf`'s observation i of `p` enters local BA as the network's depth prior.
  bool IsNetworkPrior(const MapPoint& p, const KeyFrame& kf, size_t i) const
      ADEMONO_REQUIRES(map_.mutex);
  // Monocular core with a network: the robust spread (1.4826 MAD) of the map's keyframes' log
  // depth scales (network against map), or nullopt with fewer than 5 keyframes to measure it.
  std::optional<double> KeyFrameScaleSpread() const ADEMONO_REQUIRES(map_.mutex);
  // Milliseconds of mapping work (structure, BA solve, merge) of the keyframes merged since the
  // last call, each counted once, at its hand-off frame.
  double TakeFinishedMilliseconds();

 private:
  // A keyframe between its insertion and its hand-off.
  struct Pending {
    std::shared_ptr<KeyFrame> keyframe;
    size_t handoff_frame = 0;  // on the HandOff clock
    bool has_ba = false;
    BundleAdjustmentProblem problem;
    std::vector<std::shared_ptr<KeyFrame>> cameras;
    std::vector<std::shared_ptr<MapPoint>> points;
    std::vector<std::pair<KeyFrame*, size_t>> observation_refs;  // (keyframe, keypoint index)
    std::optional<BundleAdjustmentResult> result;
    std::exception_ptr failure;
    double ms = 0;  // structure + gather (tracking thread) + solve
  };

  void Run();
  void Solve(Pending& pending) const;
  // Waits for the pending BA, applies it and culls keyframes (map lock taken here).
  void Merge();
  // The map-editing steps, on the tracking thread under the map lock.
  void ProcessNewKeyFrame(KeyFrame& keyframe) ADEMONO_REQUIRES(map_.mutex);
  void CullMapPoints(const KeyFrame& keyframe) ADEMONO_REQUIRES(map_.mutex);
  // Triangulates new map points with the best covisible keyframes; returns how many.
  int CreateNewMapPoints(KeyFrame& keyframe) ADEMONO_REQUIRES(map_.mutex);
  void FuseNeighbours(KeyFrame& keyframe) ADEMONO_REQUIRES(map_.mutex);
  // Gathers the local BA around the keyframe (map.mutex held); false: nothing to optimise.
  bool GatherBundleAdjustment(KeyFrame& keyframe, Pending& pending) ADEMONO_REQUIRES(map_.mutex);
  void ApplyBundleAdjustment(const Pending& pending) ADEMONO_REQUIRES(map_.mutex);
  void CullKeyFrames(KeyFrame& keyframe) ADEMONO_REQUIRES(map_.mutex);
  // Fits each BA keyframe's network error model against its triangulated points (monocular core
  // with a network) and updates the measured per-point spread.
  void MeasureNetworkErrors(const Pending& pending) ADEMONO_REQUIRES(map_.mutex);

  Map& map_;
  MappingOptions options_;
  bool monocular_ = false;
  double configured_sigma_log_ = 0.0;  // the options' error model, until measured
  std::vector<double> sigma_logs_;     // per fitted keyframe (tracking thread)
  std::vector<double> shared_sigma_logs_;  // the same fits' shared part
  std::vector<std::shared_ptr<MapPoint>> recent_points_;
  LoopClosing* loop_closing_ = nullptr;
  std::unique_ptr<Pending> pending_;  // tracking thread only, apart from the solve below

  std::mutex job_mutex_;  // a std::mutex for the condition variable: not annotated
  std::condition_variable job_cv_;
  Pending* job_ = nullptr;  // handed to the mapping thread; guarded by job_mutex_
  bool job_done_ = false;   // guarded by job_mutex_
  bool stop_ = false;       // guarded by job_mutex_
  double finished_ms_ = 0;  // tracking thread only
  size_t frames_ = 0;       // HandOff calls so far, the current frame's included: the clock
  bool shut_down_ = false;
  std::thread worker_;
  // Threaded: scans half of each triangulation search on the tracking thread's behalf (the
  // mapping thread is busy with the last BA at most until the keyframe's first step merges it).
  std::optional<WorkerPool> search_helper_;
};

}  // namespace ademono
