#pragma once
// Options of the SLAM system, one struct per YAML sub-node (ORB-SLAM3-settings-like config):
//   camera:   (optional) pinhole camera, overrides the dataset's
//   orb:      OrbOptions            filter:   FilterOptions
//   depth:    FrameDepthOptions     tracking: TrackingOptions
//   mapping:  MappingOptions        optimizer: pose/BA iteration counts
// Absent keys keep their defaults; a key of the wrong type or a bad value is an InputError naming
// the config file. Every field is documented in configs/7scenes.yaml and docs/slam.md.

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <string>

#include "ademono/core/depth_error.h"
#include "ademono/perception/detector_options.h"
#include "ademono/feature/orb_extractor.h"
#include "ademono/filter/feature_filter.h"
#include "ademono/initializer/two_view.h"
#include "ademono/optimize/bundle_adjustment.h"
#include "ademono/optimize/pose_optimizer.h"
#include "ademono/place/keyframe_database.h"
#include "ademono/slam/static_probability.h"

namespace ademono {

template <typename Options>
class OptionsTable;

// Each struct's keys are one field table (Table(), core/options_table.h) that drives FromYaml
// (strict: unknown keys rejected), the range part of Check() and ToYaml().

// How per-keypoint depth is read from the depth map (`depth:` node).
struct FrameDepthOptions {
  double min_depth = 0.1;            // m; nearer readings are invalid
  double max_depth = 10.0;           // m; farther readings are invalid (no depth residual)
  double virtual_baseline = 0.08;    // m; bf = virtual_baseline * fx for the u_right residual
  double close_depth_factor = 40.0;  // ThDepth: points nearer than factor * baseline are "close"
  // Depth discontinuities: a reading is dropped when the depth range in its
  // (2 * edge_radius + 1)^2 neighbourhood exceeds edge_relative_jump * depth. This matters for
  // unregistered depth (7-Scenes, raw Kinect), where edges are shifted against the colour image.
  int edge_radius = 2;  // 0 disables the test
  double edge_relative_jump = 0.05;
  // Network depth (a prior, not a sensor). error_relative > 0 switches it on:
  // sigma_z = z * (error_relative + error_per_metre * z) weighs every depth residual instead of
  // the virtual baseline's pixel sigma (a model spec's `uncertainty:` overrides these two).
  double error_relative = 0.0;
  double error_per_metre = 0.0;
  // false: depth residuals keep the virtual baseline's pixel weighting even with an error model
  // (the ablation of uncertainty weighting; scale correction and the rest stay on).
  bool uncertainty_weighting = true;
  // Each frame's depths are multiplied by the robust ratio of its tracked map points' depths to
  // its own (network scale wanders from frame to frame) before they seed points or enter
  // optimisation; at least scale_min_points pairs are needed.
  bool scale_correction = true;
  int scale_min_points = 20;
  // The map's scale follows the long-run average of the network's, not its first frame: when the
  // mean log correction drifts beyond anchor_tolerance, map and trajectory are rescaled.
  bool anchor_scale = true;
  double anchor_tolerance = 0.01;
  // Smooth network depth: a keypoint whose depth changes by more than this fraction over
  // edge_radius pixels sits on a blurred object boundary and gets no depth (0 disables). Replaces
  // the hole / range test of sensor depth when the error model is on.
  double edge_relative_slope = 0.0;
  // Known camera height above a flat ground (a vehicle's mounting height; KITTI 1.65 m), 0: off.
  // The ground plane is fitted to the keypoints below the horizon (optimize/ground_plane.h) at
  // initialisation and at every keyframe, and the map's scale is anchored to camera_height over
  // the median of the measured heights instead of to the network's own mean: a network's
  // constant scale bias becomes observable. Not with a loaded map (it keeps its scale).
  double camera_height = 0.0;
  // The region fitted: the road ahead, up to ground_max_depth ahead and ground_max_lateral to
  // either side (m, the source's units): kerbs and sidewalks beside it are 10-20 cm higher, and
  // a plane tilted to take them in too reads the height several per cent off.
  double ground_max_depth = 25.0;
  double ground_max_lateral = 4.0;
  // Monocular core: a network-placed map point measures the ground only once two of its views
  // are this far apart (triangulated, not the network's reading of the road).
  double ground_min_parallax_deg = 1.0;
  // Local BA holds each keyframe's road points at camera_height below it (residual sigma
  // ground_point_sigma x camera_height per point, Huber): the known height observes the scale in
  // every window, so scale drift is corrected where it happens, not only on average.
  bool ground_in_ba = false;
  double ground_point_sigma = 0.05;
  // With ground_in_ba: local BA solves for each keyframe's road normal from its road points
  // (on the unit sphere) instead of holding the one measured at the keyframe, so the known
  // height observes only the scale and a misread tilt does not bend the map.
  bool ground_free_normal = false;
  double ground_max_tilt_deg = 15.0;  // the ground's normal within this of the camera's up axis
  double ground_inlier_ratio = 0.05;  // inliers within this fraction of the height
  int ground_min_inliers = 50;
  // The map is rescaled when the median height strays from camera_height by more than this
  // fraction (log). Far tighter than anchor_tolerance: the ground is measured, not a mean of
  // noise, and over a 150 m drive 0.3 % of scale is already about 0.1 m of se3 error.
  double ground_tolerance = 0.001;
  bool GroundScale() const { return camera_height > 0; }
  DepthErrorModel ErrorModel() const { return {error_relative, error_per_metre}; }
  bool IsPrior() const { return ErrorModel().Enabled(); }
  double CloseDepth() const { return close_depth_factor * virtual_baseline; }
  void Check() const;  // throws std::invalid_argument
  static FrameDepthOptions FromYaml(const YAML::Node& node);
  YAML::Node ToYaml() const;
  static const OptionsTable<FrameDepthOptions>& Table();
  bool operator==(const FrameDepthOptions&) const = default;
};

struct TrackingOptions {
  // The monocular core (docs/slam.md): map points come from triangulation between keyframes and
  // the pose from 2-dof reprojection residuals alone. Without depth the map starts from a
  // two-view initialisation (initializer/two_view) and has no metric scale; with a network's
  // depth the first frame's depths seed the map, and after that the depths only measure the
  // scale and hold the points geometry cannot place yet (low parallax) as priors.
  bool monocular = false;
  int init_min_matches = 100;        // two-view: matches with the reference frame to go on
  double init_search_radius = 100;   // two-view: px around the last matched position
  int min_init_points = 500;         // points with depth needed to initialise the map
  double motion_search_radius = 15;  // px at level 0 for the constant-velocity search
  int min_motion_matches = 20;       // below this the window is doubled and searched again
  double local_search_radius = 3;    // px at level 0 for the local-map search
  int min_inliers = 30;              // inliers after local-map tracking to count as tracked
  int min_inliers_after_reloc = 50;
  int max_local_keyframes = 80;
  int min_frames_between_keyframes = 0;
  int max_frames_between_keyframes = 30;  // about one second at 30 Hz
  // Frames after a keyframe during which only weak tracking (inliers below a quarter of the
  // reference keyframe's points) may make another one: with metric depth every keyframe maps
  // the whole view, so the close-point rule need not fire every few frames. 0: off (ORB-SLAM).
  int min_keyframe_spacing = 0;
  double keyframe_ref_ratio = 0.75;  // tracked/reference-keyframe point ratio for a new keyframe
  // Monocular: a new keyframe's baseline to its reference keyframe must give a point at the
  // median scene depth mapping.triangulation_min_parallax_deg of parallax, the least a new point
  // is triangulated with. false: mapping.triangulation_min_baseline_ratio alone (ORB-SLAM's 1 %,
  // a keyframe at a quarter of that parallax adds views but no structure of its own).
  bool keyframe_parallax_baseline = true;
  // Reference-keyframe points count when seen by this many keyframes (0: ORB-SLAM's 2 or 3).
  int keyframe_ref_min_observations = 0;
  int close_tracked_min = 100;        // fewer tracked close points than this ...
  int close_untracked_min = 70;       // ... and more untracked ones: new keyframe
  // The close-point rule does not fire on an already mapped place: when more than this share of
  // the tracked close points are each seen by at least mapping.redundant_observers keyframes
  // (keyframe culling's test), a keyframe there would be redundant. 0: off (ORB-SLAM).
  double mapped_place_ratio = 0.0;
  int new_keyframe_min_points = 100;  // map points created from a new keyframe's depth at least
  int relocalisation_keyframes = 20;  // most recent keyframes tried when lost
  int reinit_after_lost_frames = 10;  // lost this long: restart tracking from the last pose
  // This many frames in a row posed on the last frame's depths (PoseQuality::kDepthOdometry: the
  // local map has nothing left where the camera looks), the last by at least
  // min_inliers_after_reloc points, re-seed the map there from the frame's depths, as a restart
  // after reinit_after_lost_frames does, without first losing frames. 0: off.
  int reseed_after_odometry_frames = 0;
  int dynamic_cull_hits = 3;          // map points seen this often inside dynamic boxes are culled
  // Geometric test for movers without a box: each map point's static probability, judged by
  // every frame that matches it; points below static_threshold are not used for the pose
  // (slam/static_probability.h, docs/slam.md).
  bool static_test = true;
  StaticTestParams static_params;  // keys static_prior, static_threshold, ...
  // The first map's (and a restart's) points inside a detector's dynamic box start at the box
  // prior, as a keyframe's new points do, when at least min_inliers_after_reloc points with depth
  // lie outside the boxes; without the static test (the network families) they are left out,
  // since nothing would judge them later. A domain's prior: indoors a person in the first frame
  // usually walks, outdoors a car in it is usually parked and much of the near structure. false:
  // every first-map point starts usable (nothing to judge it against yet).
  bool first_map_box_prior = false;
  // Degrade instead of dropping a frame: when tracking fails while the last frame was tracked,
  // the pose is still reported (weak) for up to weak_pose_max_frames frames in a row: optimised
  // on its few static points when it keeps at least weak_pose_min_inliers, else the
  // constant-velocity prediction. Weak frames make no keyframe. 0 disables.
  int weak_pose_max_frames = 30;
  int weak_pose_min_inliers = 10;
  // Whether a pose on a few static points sets the constant velocity. With sensor depth it
  // should: it is the best guess of the motion through a crowd. With network depth a pose on
  // ten-odd points inherits their depth errors, and a jump it teaches is repeated by the next
  // weak frames (bonn-crowd-a, FastDepth: 0.4-0.9 m excursions within 10 frames).
  bool weak_pose_sets_velocity = true;
  // Off the map (nothing for the motion model's pose to rest on), the pose measured on the last
  // frame's depths, if it has any, instead of the constant-velocity prediction.
  bool depth_odometry = true;
  // The trajectory's frames between two keyframes follow both keyframes' later corrections,
  // blended by time (ResolveFramePose), instead of their reference keyframe's alone. On in
  // network_indoor.yaml, whose young triangulated points move most after a frame is tracked.
  bool interpolate_trajectory = false;
  // A frame's pose relative to its keyframe is in the map's units of that moment: the
  // trajectory's frames follow a later change of the local scale around the keyframe (local BA,
  // a loop's Sim(3)), measured on the keyframe's points (KeyFrame::LocalScaleSince).
  bool follow_local_scale = false;
  // The trajectory's frames re-estimated after the run under a motion model (a smoothing spline
  // per coordinate, its strength chosen from the run's own poses by cross-validation:
  // optimize/trajectory_smoothing.h). A frame's pose from one image scatters by millimetres
  // where a sideways step and a turn look alike. On in the monocular families.
  bool smooth_trajectory = false;
  // Localisation only (--load-map --localize-only), where the camera leaves the loaded map:
  // true keeps a temporary local map in memory (keyframes and points made there, local BA with
  // the loaded keyframes and points held fixed; never saved, no loop closed), as ORB-SLAM3's
  // Atlas starts a new map; false tracks frame-to-frame odometry on the previous frame's depth
  // (ORB-SLAM2's localisation mode). On in the network-depth configs, off with sensor depth
  // (measured, docs/maps.md).
  bool temporary_map = false;
  void Check() const;
  static TrackingOptions FromYaml(const YAML::Node& node);
  YAML::Node ToYaml() const;
  static const OptionsTable<TrackingOptions>& Table();
  bool operator==(const TrackingOptions&) const = default;
};

struct MappingOptions {
  // Local mapping's schedule (slam/local_mapping.h). Every setting is deterministic: outputs are
  // identical run to run and under any load. threaded: the local BA is solved on the mapping
  // thread (false: on the tracking thread, same result). handoff_frames: the BA of a keyframe
  // made at frame f is merged when frame f + handoff_frames starts (or the next keyframe comes);
  // 0 merges it before the next frame (the synchronous schedule).
  bool threaded = true;
  int handoff_frames = 0;
  bool local_ba = true;
  int ba_max_keyframes = 0;        // free keyframes in the local BA (best covisibles); 0 = all
  // Fixed keyframes in the local BA (those seeing the most local points); 0 = every keyframe that
  // sees a local point, as ORB-SLAM. Their residuals are most of the solve's cost.
  int ba_max_fixed_keyframes = 0;
  double cull_found_ratio = 0.25;  // found / visible below this: point culled
  int cull_min_observations = 2;   // fewer observations two keyframes after creation: culled
  int fuse_neighbours = 10;        // covisible keyframes searched for duplicates
  double fuse_radius = 3;          // px at level 0
  double redundant_ratio = 0.9;    // keyframe culled when this fraction of its points ...
  int redundant_observers = 3;     // ... is seen by this many other keyframes
  // Structure from geometry: keypoints of a new keyframe without a map point are matched along
  // epipolar lines with its best covisible keyframes and triangulated (ORB-SLAM's
  // CreateNewMapPoints), so points without usable depth still enter the map. A keypoint with a
  // depth prior only searches within triangulation_depth_sigmas of it.
  bool triangulation = false;
  int triangulation_neighbours = 10;
  double triangulation_min_parallax_deg = 1.0;
  double triangulation_depth_sigmas = 3.0;
  // Ratio test of the epipolar search (best / second-best Hamming distance among the candidates
  // along the epipolar band; 1 disables it).
  double triangulation_match_ratio = 0.6;
  // A covisible keyframe is triangulated with only when the baseline is at least this fraction
  // of its median scene depth (ORB-SLAM's 0.01); the monocular core makes no keyframe (unless
  // tracking is weak) before the frame is that far from its reference keyframe.
  double triangulation_min_baseline_ratio = 0.01;
  // Monocular core with a network (tracking.monocular, depth with an error model): a point made
  // from the network's depth keeps it as a prior in local BA while its parallax leaves geometry
  // less certain (network_priors); each keyframe's network error is fitted against its
  // triangulated points (an affine map in inverse depth) and the measured spread replaces the
  // configured error model (network_error_model). Off: the ablation of each.
  bool network_priors = true;
  bool network_error_model = true;
  // The measured error's part a keyframe's points share (InverseDepthAffine::shared_sigma_log:
  // a depth-dependent bias the affine map leaves) held as one observation among that keyframe's
  // n priors in a solve, not n: each prior's relative sigma sqrt(sigma^2 + n * shared^2), as
  // network_scale_prior does with the scale. Off in both families: over four draws of every
  // development row it helped KITTI (`kitti_late` 1.15x -> 1.10x `none`) and seq-a from frame 400
  // (se3 0.0787 -> 0.0679 m) but cost Bonn (0.0142 -> 0.0157 m; `bonn_late` 0.0186 -> 0.0346 m at
  // scale 0.85), the office and the street (docs/slam.md "Tried 2026-12-03 (evening)").
  bool network_shared_error = false;
  // The network's scale per keyframe in local BA: every network depth of a free keyframe enters
  // as a prior whose sigma is the keyframe scale's measured spread (robust, over the map's
  // keyframes) times sqrt(n) of its n depths, so together they hold the keyframe's scale as one
  // observation and alone none pulls a point's shape (the network's error is correlated).
  bool network_scale_prior = false;
  BundleAdjustmentOptions ba;  // keys ba_first_iterations, ba_second_iterations
  void Check() const;
  static MappingOptions FromYaml(const YAML::Node& node);
  YAML::Node ToYaml() const;
  static const OptionsTable<MappingOptions>& Table();
  bool operator==(const MappingOptions&) const = default;
};

// Loop closing (`loop:` node, docs/loops.md): place recognition on each new keyframe, geometric
// verification, then a pose-graph correction over the essential graph and point fusion.
struct LoopOptions {
  bool enabled = true;
  int min_keyframes = 12;        // map size before any loop is searched
  int recent_keyframes = 20;     // the query keyframe's last this-many keyframe ids are excluded
  int max_candidates = 3;        // place-recognition candidates verified per keyframe
  int min_matches = 25;          // descriptor matches (ratio test) with a candidate
  int ransac_iterations = 300;   // 3-point Umeyama hypotheses
  int min_inliers = 20;          // of the 3D-3D RANSAC (reprojection chi2 in both views)
  int min_projection_matches = 40;  // after the guided projection search (RANSAC inliers included)
  double search_radius = 10;     // px at level 0 for the projection search
  int consistency = 3;           // consecutive keyframes verified against the same place
  int strong_edge_weight = 100;  // covisibility edges kept in the essential graph
  int pose_graph_iterations = 20;
  // Information of the essential graph's edges: "depth" divides each edge's translation residual
  // by the scene depth of its keyframes (a translation error then weighs what it shifts in the
  // image, like a rotation error in radians); "identity" weighs a metre like a radian (ORB-SLAM).
  std::string edge_information = "depth";
  // "auto": Sim(3) when depth is a network's prior (its scale drifts), SE(3) with sensor depth;
  // "sim3" | "se3" force one.
  std::string transform = "auto";
  // Global bundle adjustment after each loop, on its own thread, merged once loop closing has
  // seen `global_ba_handoff_keyframes` more keyframes (or at the end); Ceres iterations per solve.
  bool global_ba = false;
  int global_ba_iterations = 10;
  int global_ba_handoff_keyframes = 2;
  // A global bundle adjustment of the whole map before `--save-map` writes it (the run's
  // trajectory follows it): the map a later session inherits (docs/maps.md).
  bool global_ba_on_save = false;
  // The same over the whole map when the run ends, before the trajectory is read (every frame
  // follows its keyframe): the last keyframes' structure gets the views that came after them.
  bool global_ba_at_end = false;
  bool UseSim3(bool depth_is_prior) const {
    return transform == "sim3" || (transform == "auto" && depth_is_prior);
  }
  void Check() const;
  static const OptionsTable<LoopOptions>& Table();
  bool operator==(const LoopOptions&) const = default;
};

struct SystemOptions {
  OrbOptions orb;
  FilterOptions filter;
  FrameDepthOptions depth;
  TrackingOptions tracking;
  MappingOptions mapping;
  PoseOptimizerOptions pose;  // the `optimizer:` node
  KeyFrameDatabaseOptions place;  // place recognition index (relocalisation, loops)
  LoopOptions loop;
  TwoViewOptions initializer;  // the monocular two-view initialisation
  // A run's one seed (`--seed`, Python `seed=`): every random draw's, the distant filter's and the
  // two-view initialiser's RANSAC's.
  void SetSeed(uint64_t seed);
  void Check() const;
  // Reads every sub-node of a config file's root. InputError "path: ..." on any problem, also for
  // an unknown key in `detector:` (DetectorOptions, read by the caller) and an unknown section.
  static SystemOptions FromYaml(const YAML::Node& root, const std::filesystem::path& path);
  // Every key of every section, the resolved options: FromYaml(ToYaml()) == *this.
  YAML::Node ToYaml() const;
  static const OptionsTable<SystemOptions>& Table();
  bool operator==(const SystemOptions&) const = default;
};

// The resolved options of a run as a config file: every key of every section, `detector:`
// included, so that SystemOptions::FromYaml and DetectorOptions::FromYaml read it back to the
// same values (a run repeated exactly). WriteResolvedConfig writes it atomically
// (config.resolved.yaml in a run's output folder).
std::string ResolvedConfigText(const SystemOptions& system, const DetectorOptions& detector);
void WriteResolvedConfig(const std::filesystem::path& path, const SystemOptions& system,
                         const DetectorOptions& detector);

}  // namespace ademono
