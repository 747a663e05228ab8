#include "ademono/runner/run.h"

#include <spdlog/spdlog.h>

#include <memory>
#include <stdexcept>
#include <unordered_map>

#include "ademono/core/error.h"
#include "ademono/core/statistics.h"
#include "ademono/eval/trajectory_eval.h"

namespace ademono {

void FilterTotals::Add(const FilterStats& s, int num_keypoints) {
  boxes_small += s.boxes_small;
  boxes_large += s.boxes_large;
  removed_enhancement += s.removed_enhancement;
  removed_small_box += s.removed_small_box;
  removed_stage1 += s.removed_stage1;
  removed_stage2 += s.removed_stage2;
  removed_box_vote += s.removed_box_vote;
  removed_distant += s.removed_distant;
  distant_candidates += s.distant_candidates;
  kept += s.kept;
  keypoints += num_keypoints;
  stage1_frames += s.stage1_ran;
  stage1_compensated_frames += s.stage1_compensated;
}

nlohmann::json FilterTotals::ToJson() const {
  nlohmann::json j{{"keypoints", keypoints},
                   {"kept", kept},
                   {"boxes_small", boxes_small},
                   {"boxes_large", boxes_large},
                   {"removed_enhancement", removed_enhancement},
                   {"removed_small_box", removed_small_box},
                   {"removed_stage1", removed_stage1},
                   {"removed_stage2", removed_stage2},
                   {"removed_box_vote", removed_box_vote},
                   {"removed_dynamic", RemovedDynamic()},
                   {"removed_distant", removed_distant},
                   {"distant_candidates", distant_candidates},
                   {"stage1_frames", stage1_frames},
                   {"stage1_compensated_frames", stage1_compensated_frames}};
  j["distant_drop_rate"] =
      distant_candidates > 0
          ? nlohmann::json(static_cast<double>(removed_distant) / distant_candidates)
          : nlohmann::json(nullptr);
  return j;
}

nlohmann::json FilterStatsJson(const FilterStats& s) {
  return {{"boxes_small", s.boxes_small},
          {"boxes_large", s.boxes_large},
          {"removed_enhancement", s.removed_enhancement},
          {"removed_small_box", s.removed_small_box},
          {"removed_stage1", s.removed_stage1},
          {"removed_stage2", s.removed_stage2},
          {"removed_box_vote", s.removed_box_vote},
          {"removed_distant", s.removed_distant},
          {"distant_candidates", s.distant_candidates},
          {"stage1_compensated", s.stage1_compensated},
          {"kept", s.kept}};
}

nlohmann::json RunAccuracy::ToJson() const {
  return {{"matched_poses", matched_poses},
          {"ate_se3_rmse_m", ate_se3_rmse_m},
          {"ate_sim3_rmse_m", ate_sim3_rmse_m},
          {"sim3_scale", sim3_scale},
          {"rpe_30_frames_trans_rmse_m", rpe_30_frames_trans_rmse_m},
          {"rpe_30_frames_rot_rmse_deg", rpe_30_frames_rot_rmse_deg}};
}

std::optional<RunAccuracy> ComputeAccuracy(const Trajectory& ground_truth,
                                           const Trajectory& estimate, std::string* note) {
  if (ground_truth.empty()) {
    *note = "dataset has no ground truth";
    return std::nullopt;
  }
  if (estimate.size() < 3) {
    *note = "fewer than 3 tracked frames";
    return std::nullopt;
  }
  try {
    EvalOptions options;
    options.alignment = Alignment::kSe3;
    const EvalResult se3 = EvaluateTrajectories(ground_truth, estimate, options);
    options.alignment = Alignment::kSim3;
    const EvalResult sim3 = EvaluateTrajectories(ground_truth, estimate, options);
    options.alignment = Alignment::kSe3;
    options.rpe_delta = 30;
    const EvalResult rpe = EvaluateTrajectories(ground_truth, estimate, options);
    RunAccuracy a;
    a.matched_poses = se3.matched_poses;
    a.ate_se3_rmse_m = se3.ape.rmse;
    a.ate_sim3_rmse_m = sim3.ape.rmse;
    a.sim3_scale = sim3.gt_from_est.scale;
    a.rpe_30_frames_trans_rmse_m = rpe.rpe_trans.rmse;
    a.rpe_30_frames_rot_rmse_deg = rpe.rpe_rot_deg.rmse;
    return a;
  } catch (const std::exception& e) {
    *note = std::string("ATE not computed: ") + e.what();
    return std::nullopt;
  }
}

namespace {

// Ground-truth poses at the estimate's frames, with the association the accuracy uses.
Trajectory AssociatedGroundTruth(const Trajectory& ground_truth, const Trajectory& estimate) {
  if (ground_truth.empty() || estimate.empty()) return {};
  std::vector<double> gt_stamps, est_stamps;
  for (const StampedPose& p : ground_truth) gt_stamps.push_back(p.timestamp);
  for (const StampedPose& p : estimate) est_stamps.push_back(p.timestamp);
  Trajectory associated;
  for (const auto& [i, j] : AssociateLikeEvo(gt_stamps, est_stamps, EvalOptions().max_diff)) {
    (void)j;
    associated.push_back(ground_truth[i]);
  }
  return associated;
}

// The final map against the dataset's depth images: each keyframe's observed points at their
// depth in it, against the sensor's reading under the keypoint (eval/map_scale.h).
std::optional<MapScaleReport> MeasureMapScale(const Sequence& sequence, const MapFileData& map) {
  std::unordered_map<uint64_t, const MapKeyFrameRecord*> keyframes;
  for (const MapKeyFrameRecord& k : map.keyframes) keyframes[k.id] = &k;
  std::map<uint64_t, std::vector<MapDepthObservation>> observations;  // by keyframe id
  for (const MapPointRecord& p : map.points) {
    const Eigen::Vector3d world(p.position[0], p.position[1], p.position[2]);
    for (const auto& [keyframe_id, keypoint] : p.observations) {
      const auto it = keyframes.find(keyframe_id);
      if (it == keyframes.end() || keypoint >= it->second->keypoints.size()) continue;
      const MapKeyFrameRecord& k = *it->second;
      const std::array<double, 12>& m = k.cam_from_world;  // 3x4 row-major
      const double depth = m[8] * world.x() + m[9] * world.y() + m[10] * world.z() + m[11];
      observations[keyframe_id].push_back(
          {Eigen::Vector2d(k.keypoints[keypoint].x, k.keypoints[keypoint].y), depth});
    }
  }
  std::vector<KeyFrameMapScale> measured;
  for (const auto& [keyframe_id, list] : observations) {
    const size_t frame = keyframes.at(keyframe_id)->index;
    if (frame >= sequence.Size()) continue;
    // The run did not need this file (its depth came from elsewhere): a broken one costs this
    // keyframe's measurement, not the run.
    cv::Mat depth;
    try {
      depth = sequence.LoadDepth(frame);
    } catch (const InputError& e) {
      spdlog::warn("map scale: keyframe at frame {} not measured: {}", frame, e.what());
      continue;
    }
    if (auto scale = MeasureKeyFrameScale(frame, list, depth)) measured.push_back(*scale);
  }
  return SummarizeMapScale(std::move(measured));
}

StageTiming Timing(const std::vector<FrameReport>& frames, double FrameTiming::*stage,
                   std::string thread) {
  std::vector<double> values;
  values.reserve(frames.size());
  for (const FrameReport& f : frames) values.push_back(f.ms.*stage);
  return {Percentile(values, 0.5), Percentile(std::move(values), 0.95), std::move(thread)};
}

}  // namespace

RunReport RunSequence(const Sequence& sequence, DepthProvider* depth, Detector* detector,
                      const RunOptions& options) {
  RunReport report;
  report.dataset =
      options.dataset.empty() ? sequence.Kind() + ":" + sequence.Path().string() : options.dataset;
  report.config = options.config;
  report.depth = depth != nullptr ? depth->Name() : "none";
  report.detector = detector != nullptr ? detector->Name() : "none";
  report.options = options.system;
  report.detector_options = options.detector;

  System system(sequence.GetCamera(), options.system);
  if (!options.load_map.empty()) {
    system.LoadMap(options.load_map, options.localize_only);
  }
  const SyntheticTruth truth(sequence.Path());
  const bool score = options.score_synthetic_truth && truth.Available();
  if (score) report.truth = TruthCounts{};
  std::vector<PendingPoint> pending_points;  // new map points whose fate the run's end decides
  LiveFeed live(options.observer);
  PipelineOptions pipeline = options.pipeline;
  pipeline.on_frame = [&](const FrameData& frame, const cv::Mat&,
                          const std::vector<Detection>& detections, const TrackResult& r) {
    FrameReport f;
    f.frame = frame.index;
    f.timestamp = frame.timestamp;
    f.tracked = r.tracked;
    f.state = r.state;
    f.relocalised = r.relocalised;
    f.keyframe = r.new_keyframe;
    f.keypoints = r.num_keypoints;
    f.kept = r.num_kept;
    f.with_depth = r.num_with_depth;
    f.inliers = r.inliers;
    f.dynamic_points_culled = r.dynamic_points_culled;
    f.quality = r.quality;
    f.geometric_dynamic = r.geometric_dynamic;
    f.geometric_culled = r.geometric_culled;
    f.filter = r.filter_stats;
    f.scale_sigma = r.scale_sigma;
    report.per_frame.push_back(f);
    report.filter_totals.Add(r.filter_stats, r.num_keypoints);
    if (score)
      truth.Score(frame, detections, r.keypoints, r.labels, &*report.truth, &r.match_state,
                  &r.created_points, &pending_points);
    if (options.on_frame) options.on_frame(frame, detections, r);
    live.Frame(system, frame, detections, r);
  };
  std::unique_ptr<RealtimeFeed> feed;
  if (options.realtime) {
    feed = MakeRealtimeFeed(sequence, pipeline.start, pipeline.end, *options.realtime,
                            ReadsSequenceDepth(depth));
    pipeline.feed = feed.get();
  }
  const PipelineResult run = RunPipeline(sequence, depth, detector, system, pipeline);
  system.Shutdown();
  if (score) {
    SyntheticTruth::Resolve(pending_points, &*report.truth);
    pending_points.clear();
  }
  if (!options.save_map.empty()) system.SaveMap(options.save_map);
  if (feed) {
    report.realtime = options.realtime;
    report.realtime_stats = feed->Stats();
  }

  // The pipeline measured depth and detection (prepared ahead); the rest came with each frame.
  for (size_t i = 0; i < report.per_frame.size() && i < run.timings.size(); ++i)
    report.per_frame[i].ms = run.timings[i];
  report.frames = run.frames;
  report.partial = run.stopped;
  report.wall_seconds = run.wall_seconds;
  report.lost = system.NumLost();
  report.keyframes = system.NumKeyFrames();
  report.map_points = system.NumMapPoints();
  PoseSmoothingReport smoothing;
  report.trajectory = system.FrameTrajectory(FramePoses::kWritten, &smoothing);
  if (options.system.tracking.smooth_trajectory) report.smoothing = smoothing;
  report.keyframe_trajectory = system.KeyFrameTrajectory();
  report.ground_heights = system.GroundHeights();
  report.ground_height_frames = system.GroundHeightFrames();
  if (options.system.depth.IsPrior() || options.system.depth.GroundScale()) {
    std::map<size_t, double> scales;
    for (const auto& [index, scale] : system.DepthScales()) scales[index] = scale;
    for (FrameReport& f : report.per_frame) {
      if (auto it = scales.find(f.frame); f.tracked && it != scales.end())
        f.depth_scale = it->second;
    }
  }
  report.map_cloud = system.MapPointCloud();
  // A loaded map's keyframes index another run's frames.
  if (sequence.HasDepth() && options.load_map.empty())
    report.map_scale = MeasureMapScale(sequence, system.MapRecords());
  report.loops = system.Loops();
  live.End(system, {report.frames, report.Tracked(), report.keyframes, report.map_points,
                    report.lost, report.partial});
  // Which thread each stage ran on (the first frame is always prepared on the tracking thread).
  const std::string prep = run.prefetched ? "prefetch" : "tracking";
  const std::string mapper = options.system.mapping.threaded ? "mapping" : "tracking";
  report.timing = {
      {"decode", Timing(report.per_frame, &FrameTiming::decode_ms, prep)},
      {"extraction", Timing(report.per_frame, &FrameTiming::extraction_ms, prep)},
      {"keypoint_depth", Timing(report.per_frame, &FrameTiming::keypoint_depth_ms, prep)},
      {"depth", Timing(report.per_frame, &FrameTiming::depth_ms, prep)},
      {"detection", Timing(report.per_frame, &FrameTiming::detection_ms, prep)},
      {"filter", Timing(report.per_frame, &FrameTiming::filter_ms, "tracking")},
      {"tracking", Timing(report.per_frame, &FrameTiming::tracking_ms, "tracking")},
      // Structure and merge run on the tracking thread, the BA solve on `mapper`.
      {"local_mapping", Timing(report.per_frame, &FrameTiming::mapping_ms, mapper)},
      {"prefetch_wait", Timing(report.per_frame, &FrameTiming::prefetch_wait_ms, "tracking")},
      {"tracking_thread", Timing(report.per_frame, &FrameTiming::tracking_thread_ms, "tracking")},
      {"prefetch_thread", Timing(report.per_frame, &FrameTiming::prefetch_thread_ms, prep)}};

  Trajectory ground_truth;
  for (const FrameData& f : run.ground_truth_frames) {
    if (f.world_from_cam_gt) ground_truth.push_back({f.timestamp, *f.world_from_cam_gt});
  }
  report.accuracy = ComputeAccuracy(ground_truth, report.trajectory, &report.accuracy_note);
  report.ground_truth = AssociatedGroundTruth(ground_truth, report.trajectory);
  return report;
}

nlohmann::json RunSummaryJson(const RunReport& report) {
  const SystemOptions& o = report.options;
  nlohmann::json j;
  j["schema"] = "ademono.run/1";
  j["dataset"] = report.dataset;
  j["config"] = report.config;
  j["depth"] = report.depth;
  j["detector"] = report.detector;
  j["seed"] = o.filter.seed;
  // Every mapping schedule is deterministic (slam/local_mapping.h); the key stays for the schema.
  j["deterministic"] = true;
  j["filters"] = {{"enhancement", o.filter.enable_enhancement},
                  {"dynamic_removal", o.filter.enable_dynamic_removal},
                  {"distant", o.filter.enable_distant_filter}};
  j["frames"] = report.frames;
  j["partial"] = report.partial;
  if (report.realtime) {
    // Frames the capture took, and those it dropped because tracking was still busy.
    j["realtime"] = {{"speed", report.realtime->speed},
                     {"queue", report.realtime->queue},
                     {"captured", report.realtime_stats.captured},
                     {"dropped", report.realtime_stats.dropped},
                     {"max_queued", report.realtime_stats.max_queued}};
  }
  j["tracked"] = report.Tracked();
  j["untracked"] = report.frames - report.Tracked();
  j["lost"] = report.lost;
  {
    // Tracked frames by what their pose rests on, and the geometric test's totals.
    int few = 0, motion = 0, odometry = 0, geometric_dynamic = 0, geometric_culled = 0;
    for (const FrameReport& f : report.per_frame) {
      few += f.tracked && f.quality == PoseQuality::kFewInliers;
      motion += f.tracked && f.quality == PoseQuality::kMotionModel;
      odometry += f.tracked && f.quality == PoseQuality::kDepthOdometry;
      geometric_dynamic += f.geometric_dynamic;
      geometric_culled += f.geometric_culled;
    }
    j["weak_poses"] = {
        {"few_static_points", few}, {"motion_model", motion}, {"depth_odometry", odometry}};
    j["geometric_test"] = {{"enabled", o.tracking.static_test},
                           {"matches_judged_dynamic", geometric_dynamic},
                           {"map_points_culled", geometric_culled}};
  }
  j["keyframes"] = report.keyframes;
  j["map_points"] = report.map_points;
  j["wall_seconds"] = report.wall_seconds;
  j["fps"] = report.Fps();
  nlohmann::json timing = nlohmann::json::object();
  for (const auto& [stage, t] : report.timing)
    timing[stage] = {{"median_ms", t.median_ms}, {"p95_ms", t.p95_ms}, {"thread", t.thread}};
  j["timing"] = std::move(timing);
  j["filter_counts"] = report.filter_totals.ToJson();
  if (report.accuracy) j["accuracy"] = report.accuracy->ToJson();
  std::vector<double> depth_scales;
  for (const FrameReport& f : report.per_frame) {
    if (f.depth_scale) depth_scales.push_back(*f.depth_scale);
  }
  if (!depth_scales.empty()) {
    // How far each frame's network depth had to be corrected (1 = it agreed with the map).
    j["depth_scale"] = {{"median", Percentile(depth_scales, 0.5)},
                        {"p10", Percentile(depth_scales, 0.1)},
                        {"p90", Percentile(depth_scales, 0.9)}};
  }
  std::optional<double> scale_sigma;
  for (const FrameReport& f : report.per_frame) {
    if (f.scale_sigma) scale_sigma = f.scale_sigma;
  }
  if (scale_sigma) {
    // How well the run pinned its scale source down (the last frame's per_frame[].scale_sigma:
    // relative standard error; the source's own bias is not in it, docs/slam.md).
    j["metric_scale"] = {{"source", o.depth.GroundScale() ? "ground" : "network"},
                         {"sigma", *scale_sigma}};
  }
  if (report.map_scale) {
    // The map's metric scale read where the map is: the factor from its depths to the dataset's
    // depth images, per keyframe (1 = metric; compare accuracy.sim3_scale).
    j["map_scale"] = report.map_scale->ToJson();
  }
  if (report.smoothing) {
    // The written frames against the frames as tracked and resolved (docs/slam.md "Frames
    // smoothed").
    j["trajectory_smoothing"] = {{"segments", report.smoothing->segments},
                                 {"rms_shift_m", report.smoothing->rms_shift_m},
                                 {"max_shift_m", report.smoothing->max_shift_m}};
  }
  if (o.depth.GroundScale()) {
    // The map's scale from the known camera height: how often the ground was found and the
    // camera's median height above it in the final map (camera_height when it worked; the
    // scale it gave the depths is depth_scale).
    nlohmann::json per_keyframe = nlohmann::json::array();
    for (size_t k = 0; k < report.ground_heights.size(); ++k) {
      per_keyframe.push_back(
          {{"frame", k < report.ground_height_frames.size() ? report.ground_height_frames[k] : 0},
           {"height", report.ground_heights[k]}});
    }
    j["ground_scale"] = {{"camera_height", o.depth.camera_height},
                         {"estimates", report.ground_heights.size()},
                         {"map_height", Median(report.ground_heights)},
                         {"per_keyframe", per_keyframe}};
  }
  nlohmann::json per_frame = nlohmann::json::array();
  for (const FrameReport& f : report.per_frame) {
    per_frame.push_back({{"frame", f.frame},
                         {"timestamp", f.timestamp},
                         {"tracked", f.tracked},
                         {"state", TrackingStateName(f.state)},
                         {"relocalised", f.relocalised},
                         {"keyframe", f.keyframe},
                         {"keypoints", f.keypoints},
                         {"kept", f.kept},
                         {"with_depth", f.with_depth},
                         {"inliers", f.inliers},
                         {"dynamic_points_culled", f.dynamic_points_culled},
                         {"pose_quality", f.tracked ? PoseQualityName(f.quality) : "none"},
                         {"static_points", f.tracked ? f.inliers : 0},
                         {"geometric_dynamic", f.geometric_dynamic},
                         {"geometric_culled", f.geometric_culled},
                         {"filter", FilterStatsJson(f.filter)},
                         {"ms",
                          {{"decode", f.ms.decode_ms},
                           {"extraction", f.ms.extraction_ms},
                           {"keypoint_depth", f.ms.keypoint_depth_ms},
                           {"depth", f.ms.depth_ms},
                           {"detection", f.ms.detection_ms},
                           {"filter", f.ms.filter_ms},
                           {"tracking", f.ms.tracking_ms},
                           {"mapping", f.ms.mapping_ms},
                           {"prefetch_wait", f.ms.prefetch_wait_ms},
                           {"tracking_thread_cpu", f.ms.tracking_thread_ms},
                           {"prefetch_thread_cpu", f.ms.prefetch_thread_ms}}}});
    if (f.depth_scale) per_frame.back()["depth_scale"] = *f.depth_scale;
    if (f.scale_sigma) per_frame.back()["scale_sigma"] = *f.scale_sigma;
  }
  j["per_frame"] = std::move(per_frame);
  nlohmann::json loops = nlohmann::json::array();
  for (const LoopEvent& e : report.loops) {
    loops.push_back({{"query_keyframe", e.query_keyframe},
                     {"match_keyframe", e.match_keyframe},
                     {"query_frame", e.query_frame},
                     {"match_frame", e.match_frame},
                     {"timestamp", e.query_timestamp},
                     {"transform", e.sim3 ? "sim3" : "se3"},
                     {"scale", e.scale},
                     {"inliers", e.inliers},
                     {"matches", e.matches},
                     {"fused_points", e.fused_points},
                     {"correction_m", e.correction_m},
                     {"correction_deg", e.correction_deg},
                     {"graph_keyframes", e.graph_keyframes},
                     {"graph_edges", e.graph_edges},
                     {"ms", e.milliseconds},
                     {"global_ba", e.global_ba},
                     {"global_ba_merged", e.global_ba_merged},
                     {"global_ba_keyframes", e.global_ba_keyframes},
                     {"global_ba_points", e.global_ba_points},
                     {"global_ba_merged_at_keyframe", e.global_ba_merged_at_keyframe},
                     {"global_ba_ms", e.global_ba_ms}});
  }
  j["loops"] = std::move(loops);
  if (!report.live.is_null()) j["live"] = report.live;
  return j;
}

}  // namespace ademono
