#include "ademono/slam/options.h"

#include <stdexcept>
#include <string>

#include "ademono/core/error.h"
#include "ademono/core/file_util.h"
#include "ademono/core/options_table.h"

namespace ademono {
namespace {

void Require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument(message);
}

}  // namespace

const OptionsTable<FrameDepthOptions>& FrameDepthOptions::Table() {
  using D = FrameDepthOptions;
  static const auto table = OptionsTable<D>("depth")
                                .Add("min_depth", &D::min_depth, Range::AtLeast(0))
                                .Add("max_depth", &D::max_depth)
                                .Add("virtual_baseline", &D::virtual_baseline, Range::Above(0))
                                .Add("close_depth_factor", &D::close_depth_factor, Range::Above(0))
                                .Add("edge_radius", &D::edge_radius, Range::Closed(0, 10))
                                .Add("edge_relative_jump", &D::edge_relative_jump, Range::Above(0))
                                .Add("error_relative", &D::error_relative, Range::AtLeast(0))
                                .Add("error_per_metre", &D::error_per_metre, Range::AtLeast(0))
                                .Add("uncertainty_weighting", &D::uncertainty_weighting)
                                .Add("scale_correction", &D::scale_correction)
                                .Add("scale_min_points", &D::scale_min_points, Range::AtLeast(3))
                                .Add("anchor_scale", &D::anchor_scale)
                                .Add("anchor_tolerance", &D::anchor_tolerance, Range::AtLeast(0))
                                .Add("edge_relative_slope", &D::edge_relative_slope,
                                     Range::AtLeast(0))
                                .Add("camera_height", &D::camera_height, Range::AtLeast(0))
                                .Add("ground_max_depth", &D::ground_max_depth, Range::Above(0))
                                .Add("ground_max_lateral", &D::ground_max_lateral,
                                     Range::Above(0))
                                .Add("ground_max_tilt_deg", &D::ground_max_tilt_deg,
                                     Range::OpenClosed(0, 80))
                                .Add("ground_inlier_ratio", &D::ground_inlier_ratio,
                                     Range::Above(0))
                                .Add("ground_min_inliers", &D::ground_min_inliers,
                                     Range::AtLeast(3))
                                .Add("ground_tolerance", &D::ground_tolerance, Range::AtLeast(0))
                                .Add("ground_min_parallax_deg", &D::ground_min_parallax_deg,
                                     Range::AtLeast(0))
                                .Add("ground_in_ba", &D::ground_in_ba)
                                .Add("ground_point_sigma", &D::ground_point_sigma,
                                     Range::Above(0))
                                .Add("ground_free_normal", &D::ground_free_normal);
  return table;
}

void FrameDepthOptions::Check() const {
  Table().CheckRanges(*this);
  Require(max_depth > min_depth, "depth: need 0 <= min_depth < max_depth");
}

FrameDepthOptions FrameDepthOptions::FromYaml(const YAML::Node& node) {
  return ReadOptions<FrameDepthOptions>(node);
}

YAML::Node FrameDepthOptions::ToYaml() const { return Table().Write(*this); }

const OptionsTable<TrackingOptions>& TrackingOptions::Table() {
  using T = TrackingOptions;
  static const auto table =
      OptionsTable<T>("tracking")
          .Add("monocular", &T::monocular)
          .Add("init_min_matches", &T::init_min_matches, Range::AtLeast(8))
          .Add("init_search_radius", &T::init_search_radius, Range::Above(0))
          .Add("min_init_points", &T::min_init_points, Range::AtLeast(10))
          .Add("motion_search_radius", &T::motion_search_radius, Range::Above(0))
          .Add("min_motion_matches", &T::min_motion_matches, Range::Above(0))
          .Add("local_search_radius", &T::local_search_radius, Range::Above(0))
          .Add("min_inliers", &T::min_inliers, Range::Above(0))
          .Add("min_inliers_after_reloc", &T::min_inliers_after_reloc, Range::Above(0))
          .Add("max_local_keyframes", &T::max_local_keyframes, Range::Above(0))
          .Add("min_frames_between_keyframes", &T::min_frames_between_keyframes, Range::AtLeast(0))
          .Add("max_frames_between_keyframes", &T::max_frames_between_keyframes)
          .Add("min_keyframe_spacing", &T::min_keyframe_spacing, Range::AtLeast(0))
          .Add("keyframe_ref_ratio", &T::keyframe_ref_ratio, Range::OpenClosed(0, 1))
          .Add("keyframe_parallax_baseline", &T::keyframe_parallax_baseline)
          .Add("keyframe_ref_min_observations", &T::keyframe_ref_min_observations,
               Range::AtLeast(0))
          .Add("close_tracked_min", &T::close_tracked_min, Range::AtLeast(0))
          .Add("close_untracked_min", &T::close_untracked_min, Range::AtLeast(0))
          .Add("mapped_place_ratio", &T::mapped_place_ratio, Range::Closed(0, 1))
          .Add("new_keyframe_min_points", &T::new_keyframe_min_points, Range::AtLeast(0))
          .Add("relocalisation_keyframes", &T::relocalisation_keyframes, Range::Above(0))
          .Add("reinit_after_lost_frames", &T::reinit_after_lost_frames, Range::AtLeast(0))
          .Add("reseed_after_odometry_frames", &T::reseed_after_odometry_frames, Range::AtLeast(0))
          .Add("dynamic_cull_hits", &T::dynamic_cull_hits, Range::Above(0))
          .Add("static_test", &T::static_test)
          .AddFlat(&T::static_params, StaticTestParams::Table())
          .Add("first_map_box_prior", &T::first_map_box_prior)
          .Add("weak_pose_max_frames", &T::weak_pose_max_frames, Range::AtLeast(0))
          .Add("weak_pose_min_inliers", &T::weak_pose_min_inliers, Range::AtLeast(3))
          .Add("weak_pose_sets_velocity", &T::weak_pose_sets_velocity)
          .Add("depth_odometry", &T::depth_odometry)
          .Add("interpolate_trajectory", &T::interpolate_trajectory)
          .Add("follow_local_scale", &T::follow_local_scale)
          .Add("smooth_trajectory", &T::smooth_trajectory)
          .Add("temporary_map", &T::temporary_map);
  return table;
}

void TrackingOptions::Check() const {
  Table().CheckRanges(*this);
  Require(max_frames_between_keyframes >= min_frames_between_keyframes,
          "tracking: need 0 <= min_frames_between_keyframes <= max_frames_between_keyframes");
}

TrackingOptions TrackingOptions::FromYaml(const YAML::Node& node) {
  return ReadOptions<TrackingOptions>(node);
}

YAML::Node TrackingOptions::ToYaml() const { return Table().Write(*this); }

const OptionsTable<MappingOptions>& MappingOptions::Table() {
  using M = MappingOptions;
  static const auto table =
      OptionsTable<M>("mapping")
          .Add("threaded", &M::threaded)
          .Add("handoff_frames", &M::handoff_frames, Range::AtLeast(0))
          .Add("local_ba", &M::local_ba)
          .Add("cull_found_ratio", &M::cull_found_ratio, Range::ClosedOpen(0, 1))
          .Add("cull_min_observations", &M::cull_min_observations, Range::AtLeast(1))
          .Add("fuse_neighbours", &M::fuse_neighbours, Range::AtLeast(0))
          .Add("fuse_radius", &M::fuse_radius, Range::Above(0))
          .Add("ba_max_keyframes", &M::ba_max_keyframes, Range::AtLeast(0))
          .Add("ba_max_fixed_keyframes", &M::ba_max_fixed_keyframes, Range::AtLeast(0))
          .Add("redundant_ratio", &M::redundant_ratio, Range::OpenClosed(0, 1))
          .Add("redundant_observers", &M::redundant_observers, Range::AtLeast(1))
          .Add("triangulation", &M::triangulation)
          .Add("triangulation_neighbours", &M::triangulation_neighbours, Range::AtLeast(1))
          .Add("triangulation_min_parallax_deg", &M::triangulation_min_parallax_deg,
               Range::ClosedOpen(0, 90))
          .Add("triangulation_depth_sigmas", &M::triangulation_depth_sigmas, Range::AtLeast(0))
          .Add("network_priors", &M::network_priors)
          .Add("network_error_model", &M::network_error_model)
          .Add("network_shared_error", &M::network_shared_error)
          .Add("network_scale_prior", &M::network_scale_prior)
          .Add("triangulation_match_ratio", &M::triangulation_match_ratio,
               Range::OpenClosed(0, 1))
          .Add("triangulation_min_baseline_ratio", &M::triangulation_min_baseline_ratio,
               Range::AtLeast(0))
          .AddFlat(&M::ba, BundleAdjustmentOptions::Table());
  return table;
}

void MappingOptions::Check() const { Table().CheckRanges(*this); }

MappingOptions MappingOptions::FromYaml(const YAML::Node& node) {
  return ReadOptions<MappingOptions>(node);
}

YAML::Node MappingOptions::ToYaml() const { return Table().Write(*this); }

const OptionsTable<LoopOptions>& LoopOptions::Table() {
  using L = LoopOptions;
  static const auto table =
      OptionsTable<L>("loop")
          .Add("enabled", &L::enabled)
          .Add("min_keyframes", &L::min_keyframes, Range::AtLeast(2))
          .Add("recent_keyframes", &L::recent_keyframes, Range::AtLeast(1))
          .Add("max_candidates", &L::max_candidates, Range::AtLeast(1))
          .Add("min_matches", &L::min_matches, Range::AtLeast(3))
          .Add("ransac_iterations", &L::ransac_iterations, Range::AtLeast(1))
          .Add("min_inliers", &L::min_inliers, Range::AtLeast(3))
          .Add("min_projection_matches", &L::min_projection_matches, Range::AtLeast(3))
          .Add("search_radius", &L::search_radius, Range::Above(0))
          .Add("consistency", &L::consistency, Range::AtLeast(1))
          .Add("strong_edge_weight", &L::strong_edge_weight, Range::AtLeast(1))
          .Add("pose_graph_iterations", &L::pose_graph_iterations, Range::AtLeast(1))
          .Add("edge_information", &L::edge_information)
          .Add("transform", &L::transform)
          .Add("global_ba", &L::global_ba)
          .Add("global_ba_iterations", &L::global_ba_iterations, Range::AtLeast(1))
          .Add("global_ba_handoff_keyframes", &L::global_ba_handoff_keyframes, Range::AtLeast(1))
          .Add("global_ba_on_save", &L::global_ba_on_save)
          .Add("global_ba_at_end", &L::global_ba_at_end);
  return table;
}

void LoopOptions::Check() const {
  Table().CheckRanges(*this);
  Require(transform == "auto" || transform == "sim3" || transform == "se3",
          "loop: transform must be auto, sim3 or se3");
  Require(edge_information == "depth" || edge_information == "identity",
          "loop: edge_information must be depth or identity");
  Require(min_projection_matches >= min_inliers,
          "loop: need min_projection_matches >= min_inliers");
}

const OptionsTable<SystemOptions>& SystemOptions::Table() {
  using S = SystemOptions;
  static const auto table = OptionsTable<S>("(root)")
                                .AddIgnored("camera")    // read by the dataset's reader
                                .AddIgnored("detector")  // DetectorOptions, checked in FromYaml
                                .AddSection("orb", &S::orb, OrbOptions::Table())
                                .AddSection("filter", &S::filter, FilterOptions::Table())
                                .AddSection("depth", &S::depth, FrameDepthOptions::Table())
                                .AddSection("tracking", &S::tracking, TrackingOptions::Table())
                                .AddSection("mapping", &S::mapping, MappingOptions::Table())
                                .AddSection("optimizer", &S::pose, PoseOptimizerOptions::Table())
                                .AddSection("place", &S::place, KeyFrameDatabaseOptions::Table())
                                .AddSection("loop", &S::loop, LoopOptions::Table())
                                .AddSection("initializer", &S::initializer,
                                            TwoViewOptions::Table());
  return table;
}

void SystemOptions::SetSeed(uint64_t seed) { filter.seed = initializer.seed = seed; }

void SystemOptions::Check() const {
  orb.Check();
  filter.Check();
  depth.Check();
  tracking.Check();
  mapping.Check();
  pose.Check();
  place.Check();
  loop.Check();
  initializer.Check();
}

SystemOptions SystemOptions::FromYaml(const YAML::Node& root, const std::filesystem::path& path) {
  SystemOptions o;
  try {
    Table().Read(root, o);
    if (root && root.IsMap()) DetectorOptions::FromYaml(root["detector"]);  // unknown keys, ranges
    o.Check();
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    ThrowInputError(path, e.what());
  }
  return o;
}

YAML::Node SystemOptions::ToYaml() const { return Table().Write(*this); }

std::string ResolvedConfigText(const SystemOptions& system, const DetectorOptions& detector) {
  YAML::Node root = system.ToYaml();
  root["detector"] = detector.ToYaml();
  return "# ademono resolved options: every key, as the run used them\n" + YamlToText(root);
}

void WriteResolvedConfig(const std::filesystem::path& path, const SystemOptions& system,
                         const DetectorOptions& detector) {
  WriteTextFileAtomic(path, ResolvedConfigText(system, detector));
}

}  // namespace ademono
