#include "ademono/slam/options.h"

#include <stdexcept>
#include <string>

#include "ademono/core/error.h"
#include "ademono/core/yaml_util.h"

namespace ademono {
namespace {

void Require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument(message);
}

}  // namespace

void FrameDepthOptions::Check() const {
  Require(min_depth >= 0 && max_depth > min_depth, "depth: need 0 <= min_depth < max_depth");
  Require(virtual_baseline > 0, "depth: virtual_baseline must be > 0");
  Require(close_depth_factor > 0, "depth: close_depth_factor must be > 0");
  Require(edge_radius >= 0 && edge_radius <= 10, "depth: edge_radius must be in [0, 10]");
  Require(edge_relative_jump > 0, "depth: edge_relative_jump must be > 0");
  Require(error_relative >= 0 && error_per_metre >= 0,
          "depth: error_relative and error_per_metre must be >= 0");
  Require(scale_min_points >= 3, "depth: scale_min_points must be >= 3");
  Require(anchor_tolerance >= 0, "depth: anchor_tolerance must be >= 0");
  Require(edge_relative_slope >= 0, "depth: edge_relative_slope must be >= 0");
}

FrameDepthOptions FrameDepthOptions::FromYaml(const YAML::Node& node) {
  CheckYamlKeys(node, "depth",
                {"min_depth", "max_depth", "virtual_baseline", "close_depth_factor", "edge_radius",
                 "edge_relative_jump", "error_relative", "error_per_metre", "scale_correction",
                 "scale_min_points", "anchor_scale", "anchor_tolerance", "edge_relative_slope"});
  FrameDepthOptions o;
  o.min_depth = ReadYamlKey(node, "depth", "min_depth", o.min_depth);
  o.max_depth = ReadYamlKey(node, "depth", "max_depth", o.max_depth);
  o.virtual_baseline = ReadYamlKey(node, "depth", "virtual_baseline", o.virtual_baseline);
  o.close_depth_factor = ReadYamlKey(node, "depth", "close_depth_factor", o.close_depth_factor);
  o.edge_radius = ReadYamlKey(node, "depth", "edge_radius", o.edge_radius);
  o.edge_relative_jump = ReadYamlKey(node, "depth", "edge_relative_jump", o.edge_relative_jump);
  o.error_relative = ReadYamlKey(node, "depth", "error_relative", o.error_relative);
  o.error_per_metre = ReadYamlKey(node, "depth", "error_per_metre", o.error_per_metre);
  o.scale_correction = ReadYamlKey(node, "depth", "scale_correction", o.scale_correction);
  o.scale_min_points = ReadYamlKey(node, "depth", "scale_min_points", o.scale_min_points);
  o.anchor_scale = ReadYamlKey(node, "depth", "anchor_scale", o.anchor_scale);
  o.anchor_tolerance = ReadYamlKey(node, "depth", "anchor_tolerance", o.anchor_tolerance);
  o.edge_relative_slope =
      ReadYamlKey(node, "depth", "edge_relative_slope", o.edge_relative_slope);
  o.Check();
  return o;
}

void TrackingOptions::Check() const {
  Require(min_init_points >= 10, "tracking: min_init_points must be >= 10");
  Require(motion_search_radius > 0 && local_search_radius > 0,
          "tracking: search radii must be > 0");
  Require(min_motion_matches > 0 && min_inliers > 0 && min_inliers_after_reloc > 0,
          "tracking: match thresholds must be > 0");
  Require(max_local_keyframes > 0, "tracking: max_local_keyframes must be > 0");
  Require(min_frames_between_keyframes >= 0 &&
              max_frames_between_keyframes >= min_frames_between_keyframes,
          "tracking: need 0 <= min_frames_between_keyframes <= max_frames_between_keyframes");
  Require(keyframe_ref_ratio > 0 && keyframe_ref_ratio <= 1,
          "tracking: keyframe_ref_ratio in (0, 1]");
  Require(close_tracked_min >= 0 && close_untracked_min >= 0 && new_keyframe_min_points >= 0,
          "tracking: close point counts must be >= 0");
  Require(keyframe_ref_min_observations >= 0,
          "tracking: keyframe_ref_min_observations must be >= 0");
  Require(relocalisation_keyframes > 0, "tracking: relocalisation_keyframes must be > 0");
  Require(reinit_after_lost_frames >= 0, "tracking: reinit_after_lost_frames must be >= 0");
  Require(dynamic_cull_hits > 0, "tracking: dynamic_cull_hits must be > 0");
}

TrackingOptions TrackingOptions::FromYaml(const YAML::Node& node) {
  CheckYamlKeys(
      node, "tracking",
      {"min_init_points", "motion_search_radius", "min_motion_matches", "local_search_radius",
       "min_inliers", "min_inliers_after_reloc", "max_local_keyframes",
       "min_frames_between_keyframes", "max_frames_between_keyframes", "keyframe_ref_ratio",
       "keyframe_ref_min_observations", "close_tracked_min", "close_untracked_min",
       "new_keyframe_min_points", "relocalisation_keyframes", "reinit_after_lost_frames",
       "dynamic_cull_hits"});
  TrackingOptions o;
  o.min_init_points = ReadYamlKey(node, "tracking", "min_init_points", o.min_init_points);
  o.motion_search_radius =
      ReadYamlKey(node, "tracking", "motion_search_radius", o.motion_search_radius);
  o.min_motion_matches = ReadYamlKey(node, "tracking", "min_motion_matches", o.min_motion_matches);
  o.local_search_radius =
      ReadYamlKey(node, "tracking", "local_search_radius", o.local_search_radius);
  o.min_inliers = ReadYamlKey(node, "tracking", "min_inliers", o.min_inliers);
  o.min_inliers_after_reloc =
      ReadYamlKey(node, "tracking", "min_inliers_after_reloc", o.min_inliers_after_reloc);
  o.max_local_keyframes =
      ReadYamlKey(node, "tracking", "max_local_keyframes", o.max_local_keyframes);
  o.min_frames_between_keyframes =
      ReadYamlKey(node, "tracking", "min_frames_between_keyframes", o.min_frames_between_keyframes);
  o.max_frames_between_keyframes =
      ReadYamlKey(node, "tracking", "max_frames_between_keyframes", o.max_frames_between_keyframes);
  o.keyframe_ref_ratio = ReadYamlKey(node, "tracking", "keyframe_ref_ratio", o.keyframe_ref_ratio);
  o.keyframe_ref_min_observations = ReadYamlKey(node, "tracking", "keyframe_ref_min_observations",
                                                o.keyframe_ref_min_observations);
  o.close_tracked_min = ReadYamlKey(node, "tracking", "close_tracked_min", o.close_tracked_min);
  o.close_untracked_min =
      ReadYamlKey(node, "tracking", "close_untracked_min", o.close_untracked_min);
  o.new_keyframe_min_points =
      ReadYamlKey(node, "tracking", "new_keyframe_min_points", o.new_keyframe_min_points);
  o.relocalisation_keyframes =
      ReadYamlKey(node, "tracking", "relocalisation_keyframes", o.relocalisation_keyframes);
  o.reinit_after_lost_frames =
      ReadYamlKey(node, "tracking", "reinit_after_lost_frames", o.reinit_after_lost_frames);
  o.dynamic_cull_hits = ReadYamlKey(node, "tracking", "dynamic_cull_hits", o.dynamic_cull_hits);
  o.Check();
  return o;
}

void MappingOptions::Check() const {
  Require(cull_found_ratio >= 0 && cull_found_ratio < 1, "mapping: cull_found_ratio in [0, 1)");
  Require(ba_max_keyframes >= 0, "mapping: ba_max_keyframes must be >= 0");
  Require(cull_min_observations >= 1, "mapping: cull_min_observations must be >= 1");
  Require(fuse_neighbours >= 0 && fuse_radius > 0, "mapping: fuse settings must be positive");
  Require(redundant_ratio > 0 && redundant_ratio <= 1, "mapping: redundant_ratio in (0, 1]");
  Require(redundant_observers >= 1, "mapping: redundant_observers must be >= 1");
  Require(triangulation_neighbours >= 1, "mapping: triangulation_neighbours must be >= 1");
  Require(triangulation_min_parallax_deg >= 0 && triangulation_min_parallax_deg < 90,
          "mapping: triangulation_min_parallax_deg in [0, 90)");
  Require(triangulation_depth_sigmas >= 0, "mapping: triangulation_depth_sigmas must be >= 0");
  ba.Check();
}

MappingOptions MappingOptions::FromYaml(const YAML::Node& node) {
  CheckYamlKeys(node, "mapping",
                {"deterministic", "local_ba", "cull_found_ratio", "cull_min_observations",
                 "fuse_neighbours", "fuse_radius", "ba_max_keyframes", "redundant_ratio",
                 "redundant_observers", "ba_first_iterations", "ba_second_iterations",
                 "triangulation", "triangulation_neighbours", "triangulation_min_parallax_deg",
                 "triangulation_depth_sigmas"});
  MappingOptions o;
  o.deterministic = ReadYamlKey(node, "mapping", "deterministic", o.deterministic);
  o.local_ba = ReadYamlKey(node, "mapping", "local_ba", o.local_ba);
  o.cull_found_ratio = ReadYamlKey(node, "mapping", "cull_found_ratio", o.cull_found_ratio);
  o.cull_min_observations =
      ReadYamlKey(node, "mapping", "cull_min_observations", o.cull_min_observations);
  o.fuse_neighbours = ReadYamlKey(node, "mapping", "fuse_neighbours", o.fuse_neighbours);
  o.fuse_radius = ReadYamlKey(node, "mapping", "fuse_radius", o.fuse_radius);
  o.ba_max_keyframes = ReadYamlKey(node, "mapping", "ba_max_keyframes", o.ba_max_keyframes);
  o.redundant_ratio = ReadYamlKey(node, "mapping", "redundant_ratio", o.redundant_ratio);
  o.redundant_observers =
      ReadYamlKey(node, "mapping", "redundant_observers", o.redundant_observers);
  o.triangulation = ReadYamlKey(node, "mapping", "triangulation", o.triangulation);
  o.triangulation_neighbours =
      ReadYamlKey(node, "mapping", "triangulation_neighbours", o.triangulation_neighbours);
  o.triangulation_min_parallax_deg = ReadYamlKey(node, "mapping", "triangulation_min_parallax_deg",
                                                 o.triangulation_min_parallax_deg);
  o.triangulation_depth_sigmas =
      ReadYamlKey(node, "mapping", "triangulation_depth_sigmas", o.triangulation_depth_sigmas);
  o.ba.first_iterations =
      ReadYamlKey(node, "mapping", "ba_first_iterations", o.ba.first_iterations);
  o.ba.second_iterations =
      ReadYamlKey(node, "mapping", "ba_second_iterations", o.ba.second_iterations);
  o.Check();
  return o;
}

void SystemOptions::Check() const {
  orb.Check();
  filter.Check();
  depth.Check();
  tracking.Check();
  mapping.Check();
  pose.Check();
}

SystemOptions SystemOptions::FromYaml(const YAML::Node& root, const std::filesystem::path& path) {
  SystemOptions o;
  try {
    if (root && !root.IsNull() && !root.IsMap()) throw std::invalid_argument("root must be a map");
    CheckYamlKeys(
        root, "(root)",
        {"camera", "orb", "filter", "depth", "tracking", "mapping", "optimizer", "detector"});
    if (root["orb"]) o.orb = OrbOptions::FromYaml(root["orb"]);
    if (root["filter"]) o.filter = FilterOptions::FromYaml(root["filter"]);
    o.depth = FrameDepthOptions::FromYaml(root["depth"]);
    o.tracking = TrackingOptions::FromYaml(root["tracking"]);
    o.mapping = MappingOptions::FromYaml(root["mapping"]);
    const YAML::Node optimizer = root["optimizer"];
    CheckYamlKeys(optimizer, "optimizer", {"pose_rounds", "pose_iterations_per_round"});
    o.pose.rounds = ReadYamlKey(optimizer, "optimizer", "pose_rounds", o.pose.rounds);
    o.pose.iterations_per_round = ReadYamlKey(optimizer, "optimizer", "pose_iterations_per_round",
                                              o.pose.iterations_per_round);
    o.Check();
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    ThrowInputError(path, e.what());
  }
  return o;
}

}  // namespace ademono
