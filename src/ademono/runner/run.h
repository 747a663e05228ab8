#pragma once
// The runner: one sequence through a slam::System (via the prefetching pipeline) into an
// in-memory run report: per-frame records, totals, stage timings, accuracy against the dataset's
// ground truth (through eval). `ademono run`, every `ademono ablate` variant and later callers
// (Python API, HTML report) all go through RunSequence; runner/run_writer.h writes the report.
// The runner orchestrates only: tracking is slam's, metrics are eval's.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "ademono/eval/map_scale.h"
#include "ademono/filter/feature_filter.h"
#include "ademono/io/sequence.h"
#include "ademono/io/trajectory.h"
#include "ademono/perception/depth_provider.h"
#include "ademono/perception/detection.h"
#include "ademono/runner/live_feed.h"
#include "ademono/runner/pipeline.h"
#include "ademono/runner/synthetic_truth.h"
#include "ademono/slam/options.h"
#include "ademono/slam/system.h"

namespace ademono {

// Sum of the per-frame filter statistics.
struct FilterTotals {
  long long boxes_small = 0, boxes_large = 0;
  long long removed_enhancement = 0, removed_small_box = 0, removed_stage1 = 0, removed_stage2 = 0;
  long long removed_box_vote = 0;
  long long removed_distant = 0, distant_candidates = 0, kept = 0, keypoints = 0;
  long long stage1_frames = 0, stage1_compensated_frames = 0;
  void Add(const FilterStats& s, int num_keypoints);
  long long RemovedDynamic() const {
    return removed_small_box + removed_stage1 + removed_stage2 + removed_box_vote;
  }
  nlohmann::json ToJson() const;
};
nlohmann::json FilterStatsJson(const FilterStats& s);

// What a run keeps of each frame (no images, no keypoints).
struct FrameReport {
  size_t frame = 0;  // the sequence's frame index
  double timestamp = 0;
  bool tracked = false;
  TrackingState state = TrackingState::kNotInitialized;
  bool relocalised = false;
  bool keyframe = false;
  int keypoints = 0, kept = 0, with_depth = 0, inliers = 0, dynamic_points_culled = 0;
  // Tracked frames: what the pose rests on ("good", "few_static_points", "motion_model",
  // "depth_odometry"; the static points are `inliers`), and the geometric test's verdicts
  // (slam/static_probability.h).
  PoseQuality quality = PoseQuality::kGood;
  int geometric_dynamic = 0, geometric_culled = 0;
  // Network depth: the factor its depths were corrected by, against the final map (absent for
  // sensor depth and untracked frames).
  std::optional<double> depth_scale;
  // The relative standard error of the run's metric scale as the frame left it (TrackResult).
  std::optional<double> scale_sigma;
  FilterStats filter;
  FrameTiming ms;
};

// ATE with se3 and sim3 alignment and RPE over 30 frames (se3), as `ademono eval` computes them.
struct RunAccuracy {
  size_t matched_poses = 0;
  double ate_se3_rmse_m = 0, ate_sim3_rmse_m = 0, sim3_scale = 1;
  double rpe_30_frames_trans_rmse_m = 0, rpe_30_frames_rot_rmse_deg = 0;
  nlohmann::json ToJson() const;
};
// Accuracy of `estimate` against `ground_truth` (both world_from_cam, associated by timestamp);
// nullopt with `*note` saying why when it cannot be computed (no ground truth, fewer than 3
// tracked frames, alignment failed).
std::optional<RunAccuracy> ComputeAccuracy(const Trajectory& ground_truth,
                                           const Trajectory& estimate, std::string* note);

struct StageTiming {
  double median_ms = 0, p95_ms = 0;
  // Where the stage ran: "prefetch", "tracking" or "mapping" (the mapping thread). *_thread
  // stages are CPU time of that thread per frame, the others wall time (pipeline.h FrameTiming).
  std::string thread;
};

struct RunOptions {
  SystemOptions system;
  PipelineOptions pipeline;  // start, end, overlap; its on_frame is replaced by the runner's
  std::string dataset;       // label for the summary; empty: "<kind>:<path>" of the sequence
  std::string config;        // config file the options were read from ("" = built-in defaults)
  DetectorOptions detector;  // the config's `detector:` node, for config.resolved.yaml
  // Score the filter labels against masks/ when the sequence has them (synthetic sequences).
  bool score_synthetic_truth = false;
  // Map reuse (docs/maps.md): a saved map to start from (relocalise in it; with localize_only
  // never change it) and where to save the final map. Empty paths: none.
  std::filesystem::path load_map;
  bool localize_only = false;
  std::filesystem::path save_map;
  // Real-time input (runner/realtime.h): frames dropped when tracking falls behind.
  std::optional<RealtimeOptions> realtime;
  // Called after each frame, in order, on the calling thread (progress, --viz).
  std::function<void(const FrameData&, const std::vector<Detection>&, const TrackResult&)> on_frame;
  // A live view (src/ademono/live): gets copies of each frame and of the map as it changes, on
  // the tracking thread, and the final map and trajectory at the end. Never changes the outputs.
  RunObserver* observer = nullptr;
};

struct RunReport {
  std::string dataset, config, depth, detector;
  SystemOptions options;  // as run (seed, filter switches, deterministic)
  DetectorOptions detector_options;
  size_t frames = 0, keyframes = 0, map_points = 0;
  int lost = 0;
  std::vector<double> ground_heights;  // depth.camera_height: System::GroundHeights
  std::vector<size_t> ground_height_frames;  // ... and where each was measured
  double wall_seconds = 0;
  // Stopped early (options.pipeline.stop, e.g. Ctrl-C): the report covers the frames done so far.
  bool partial = false;
  std::optional<RealtimeOptions> realtime;  // as run, with what the capture did
  RealtimeStats realtime_stats;
  std::vector<FrameReport> per_frame;
  FilterTotals filter_totals;
  // Keys extraction, depth, detection, filter, tracking, local_mapping.
  std::map<std::string, StageTiming> timing;
  std::optional<RunAccuracy> accuracy;
  std::string accuracy_note;  // why `accuracy` is missing, if it is
  std::optional<TruthCounts> truth;
  Trajectory trajectory;           // every tracked frame
  // How far tracking.smooth_trajectory moved the frames (unset when it is off).
  std::optional<PoseSmoothingReport> smoothing;
  Trajectory keyframe_trajectory;  // keyframes at the end of the run
  // The final map's depths against the dataset's depth images per keyframe (eval/map_scale.h);
  // unset when the dataset has none, no keyframe could be measured, or the run loaded a map.
  std::optional<MapScaleReport> map_scale;
  // The dataset's ground-truth poses associated with `trajectory` (eval's association; empty
  // without ground truth).
  Trajectory ground_truth;
  std::vector<System::ColoredPoint> map_cloud;
  std::vector<LoopEvent> loops;  // closed loops, in order
  // What the live view did (clients, messages sent and dropped); null without one. The caller
  // that owns the view fills it in before writing summary.json.
  nlohmann::json live;

  size_t Tracked() const { return trajectory.size(); }
  double Fps() const { return wall_seconds > 0 ? static_cast<double>(frames) / wall_seconds : 0.0; }
};

// Runs options.pipeline's frames of `sequence` through a new System. `depth` / `detector` may be
// null (none); they can be shared between runs (deterministic per frame). Throws InputError from
// the sequence, the providers or the synthetic truth.
RunReport RunSequence(const Sequence& sequence, DepthProvider* depth, Detector* detector,
                      const RunOptions& options);

// summary.json of a run: schema "ademono.run/1" (docs/slam.md).
nlohmann::json RunSummaryJson(const RunReport& report);

}  // namespace ademono
