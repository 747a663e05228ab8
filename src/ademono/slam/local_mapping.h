#pragma once
// Local mapping (ORB-SLAM's LocalMapping for RGB-D): for each new keyframe, registers its map
// points, culls recently created points that are rarely found, fuses duplicates with the
// covisible keyframes, runs a local bundle adjustment and culls redundant keyframes.
//
// One code path, two modes: keyframes always queue to the mapping thread, which processes them in
// order (the local BA solved outside the map lock). Deterministic mode waits in InsertKeyFrame
// until the keyframe is mapped (outputs identical run to run and under any load); threaded mode
// returns at once and tracking continues concurrently.

#include <condition_variable>
#include <deque>
#include <exception>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "ademono/slam/loop_closing.h"
#include "ademono/slam/map.h"
#include "ademono/slam/options.h"

namespace ademono {

class LocalMapping {
 public:
  LocalMapping(Map& map, const MappingOptions& options);
  ~LocalMapping();
  LocalMapping(const LocalMapping&) = delete;
  LocalMapping& operator=(const LocalMapping&) = delete;

  // Loop closing runs on each keyframe right after its local mapping step (same thread, same
  // point in the sequence in deterministic mode). Null disables it. Set before the first keyframe.
  void SetLoopClosing(LoopClosing* loop_closing) { loop_closing_ = loop_closing; }

  // The caller must not hold map.mutex.
  void InsertKeyFrame(const std::shared_ptr<KeyFrame>& keyframe);
  // True when no keyframe is queued or being processed (always true in deterministic mode).
  bool Idle() const;
  size_t QueueSize() const;
  // Blocks until the queue is empty (threaded mode), then stops the worker.
  void Shutdown();
  // Wall time (ms) of the keyframes whose processing finished since the last call, each counted
  // once: in threaded mode a frame reports the mapping work that completed while it was tracked.
  double TakeFinishedMilliseconds();

 private:
  void Run();
  void Process(const std::shared_ptr<KeyFrame>& keyframe);
  void ProcessNewKeyFrame(KeyFrame& keyframe);
  void CullMapPoints(const KeyFrame& keyframe);
  // Triangulates new map points with the best covisible keyframes; returns how many.
  int CreateNewMapPoints(KeyFrame& keyframe);
  void FuseNeighbours(KeyFrame& keyframe);
  void LocalBundleAdjustment(KeyFrame& keyframe);
  void CullKeyFrames(KeyFrame& keyframe);

  Map& map_;
  MappingOptions options_;
  std::vector<std::shared_ptr<MapPoint>> recent_points_;
  LoopClosing* loop_closing_ = nullptr;

  mutable std::mutex queue_mutex_;
  std::condition_variable queue_cv_;
  std::condition_variable idle_cv_;  // a keyframe finished (deterministic mode waits on it)
  std::exception_ptr failure_;       // an exception of the mapping thread, rethrown to tracking
  std::deque<std::shared_ptr<KeyFrame>> queue_;
  bool busy_ = false;
  bool stop_ = false;
  double finished_ms_ = 0;  // guarded by queue_mutex_
  std::thread worker_;
};

}  // namespace ademono
