// `ademono ground`: the camera's height above the road and the road's normal, frame by frame,
// from a depth source (optimize/ground_plane.h): what a vehicle's rig reads through a depth
// network, and how steadily. --from:
//   dense      a plane fitted to the dense depth map's corridor ahead
//   keypoints  the same to the ORB keypoints with depth in it (what tracking had)
//   level      the height along the camera's up axis (a level rig), median over the corridor
//   two-view   the road's homography between frame k and k + --gap under the ground-truth
//              relative pose (no depth but the start: the level fit), in metres; with
//              --poses FILE under a run's relative pose instead (its trajectory file, matched by
//              timestamp), in that trajectory's units (near metres: the level fit in metres
//              starts the search)
// each off the detector's boxes.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>

#include "ademono/core/error.h"
#include "ademono/core/file_util.h"
#include "ademono/core/statistics.h"
#include "ademono/depth/depth_factory.h"
#include "ademono/detect/detector_factory.h"
#include "ademono/feature/orb_extractor.h"
#include "ademono/io/sequence.h"
#include "ademono/io/timed_poses.h"
#include "ademono/io/trajectory.h"
#include "ademono/optimize/ground_plane.h"
#include "command.h"
#include "run_options.h"

namespace fs = std::filesystem;

namespace {

struct GroundArgs {
  std::string dataset;
  std::string camera;
  std::string depth;
  std::string detector = "none";
  std::string from = "dense";
  int every = 1;
  std::string frames;
  int gap = 2;
  ademono::TwoViewGroundOptions two_view;
  int orb_features = 2000;
  double reference_height = 0.0;
  ademono::GroundFromDepthOptions options;
  std::string json;
  std::string poses;  // two-view: a run's trajectory instead of the ground truth
};

// Pitch (about x, positive: the road's normal leans towards +z, the camera looks down) and roll
// (about z) of the road's normal in the camera frame, degrees.
double PitchDeg(const Eigen::Vector3d& n) { return std::atan2(n.z(), -n.y()) * 180.0 / M_PI; }
double RollDeg(const Eigen::Vector3d& n) { return std::atan2(n.x(), -n.y()) * 180.0 / M_PI; }

int RunGround(const GroundArgs& args) {
  if (args.from != "dense" && args.from != "keypoints" && args.from != "level" &&
      args.from != "two-view")
    throw ademono::InputError("--from '" + args.from +
                              "': expected dense, keypoints, level or two-view");
  if (args.every < 1) throw ademono::InputError("--every must be >= 1");
  try {
    args.options.Check();
  } catch (const std::invalid_argument& e) {
    throw ademono::InputError(e.what());
  }
  std::optional<fs::path> camera_yaml;
  if (!args.camera.empty()) camera_yaml = args.camera;
  const auto sequence = ademono::OpenSequence(args.dataset, camera_yaml);
  if (!args.poses.empty() && args.from != "two-view")
    throw ademono::InputError("--poses is for --from two-view");
  if (args.from == "two-view" && args.poses.empty() && !sequence->HasGroundTruth())
    throw ademono::InputError(args.dataset +
                              ": --from two-view needs ground-truth poses (or --poses FILE)");
  ademono::Trajectory poses;
  if (!args.poses.empty()) {
    if (!fs::is_regular_file(args.poses))
      throw ademono::InputError(args.poses + ": --poses: no such file");
    poses = ademono::ReadTrajectory(args.poses, ademono::DetectTrajectoryFormat(args.poses));
    std::sort(poses.begin(), poses.end(),
              [](const auto& a, const auto& b) { return a.timestamp < b.timestamp; });
  }
  const ademono::Camera& camera = sequence->GetCamera();
  ademono::DepthFactoryContext context;
  context.sequence = sequence.get();
  const auto depth = ademono::MakeDepthProvider(args.depth, context);
  ademono::DetectorOptions detector_options;
  const auto detector = ademono::MakeDetector(args.detector, detector_options);
  ademono::OrbOptions orb;
  orb.num_features = args.orb_features;
  const ademono::OrbExtractor extractor(orb);

  nlohmann::json frames = nlohmann::json::array();
  std::vector<double> heights;
  size_t total = 0;
  std::cout << "frame  valid  height_m  pitch_deg  roll_deg  points  inliers  share  sigma  "
               "height_sigma  confidence\n";
  size_t start = 0, end = sequence->Size();
  if (!args.frames.empty()) ademono::cli::ParseFrames(args.frames, sequence->Size(), &start, &end);
  end = std::min(end, sequence->Size());
  for (size_t i = start; i < end; i += static_cast<size_t>(args.every)) {
    const ademono::FrameData frame = sequence->Load(i);
    const cv::Mat map = depth->Depth(frame, camera);
    std::vector<cv::Rect2d> boxes;
    if (detector) {
      for (const ademono::Detection& d : detector->Detect(frame))
        boxes.emplace_back(d.box.x, d.box.y, d.box.width, d.box.height);
    }
    ademono::GroundPlane plane;
    if (args.from == "dense") {
      plane = ademono::EstimateGroundFromDepth(map, camera, boxes, args.options);
    } else if (args.from == "level" || args.from == "two-view") {
      plane = ademono::GroundHeightAlong(ademono::RoadCandidates(map, camera, boxes, args.options),
                                         Eigen::Vector3d(0, -1, 0), args.options.plane);
      const size_t j = i + static_cast<size_t>(args.gap);
      if (args.from == "two-view") {
        if (j >= sequence->Size()) break;
        const ademono::FrameData other = sequence->Load(j);
        std::optional<ademono::Rigid3d> world_from_a = frame.world_from_cam_gt;
        std::optional<ademono::Rigid3d> world_from_b = other.world_from_cam_gt;
        if (!poses.empty()) {
          // The run's own pose of each frame (within 1 ms), never one interpolated across frames
          // it did not track.
          ademono::PoseLookupOptions lookup;
          lookup.max_interpolation_gap = 0;
          lookup.max_nearest_diff = 1e-3;
          world_from_a = ademono::LookupPose(poses, frame.timestamp, lookup);
          world_from_b = ademono::LookupPose(poses, other.timestamp, lookup);
        }
        if (!world_from_a || !world_from_b) {
          plane = ademono::GroundPlane();  // a frame the run did not track
          ++total;
          std::cout << fmt::format("{:5d}  no  (no pose)\n", frame.index);
          frames.push_back(
              {{"frame", frame.index}, {"valid", false}, {"height_m", 0.0}, {"no_pose", true}});
          continue;
        }
        const ademono::Rigid3d b_from_a = world_from_b->inverse() * *world_from_a;
        // The level fit only starts it (its height within about 20 %).
        plane = plane.height > 0 ? ademono::EstimateGroundFromTwoViews(
                                       frame.image, other.image, b_from_a, camera, plane, boxes,
                                       args.two_view)
                                 : ademono::GroundPlane();
      }
    } else {
      std::vector<cv::KeyPoint> keypoints;
      cv::Mat descriptors;
      extractor.Extract(frame.image, keypoints, descriptors);
      std::vector<cv::Point2f> points;
      std::vector<float> depths;
      for (const cv::KeyPoint& k : keypoints) {
        const int u = static_cast<int>(std::lround(k.pt.x));
        const int v = static_cast<int>(std::lround(k.pt.y));
        points.push_back(k.pt);
        depths.push_back(u >= 0 && v >= 0 && u < map.cols && v < map.rows ? map.at<float>(v, u)
                                                                           : 0.f);
      }
      plane = ademono::EstimateGroundPlane(
          ademono::RoadCandidates(points, depths, camera, boxes, args.options),
          args.options.plane);
    }
    ++total;
    if (plane.valid) heights.push_back(plane.height);
    std::cout << fmt::format(
        "{:5d}  {:5}  {:8.3f}  {:9.2f}  {:8.2f}  {:6d}  {:7d}  {:.2f}  {:.3f}  {:12.4f}  {:.3f}\n",
        frame.index, plane.valid ? "yes" : "no", plane.height, PitchDeg(plane.normal),
        RollDeg(plane.normal), plane.num_points, plane.num_inliers, plane.inlier_share,
        plane.residual_sigma, plane.height_sigma, plane.confidence);
    frames.push_back({{"frame", frame.index},
                      {"valid", plane.valid},
                      {"height_m", plane.height},
                      {"normal", {plane.normal.x(), plane.normal.y(), plane.normal.z()}},
                      {"pitch_deg", PitchDeg(plane.normal)},
                      {"roll_deg", RollDeg(plane.normal)},
                      {"points", plane.num_points},
                      {"inliers", plane.num_inliers},
                      {"inlier_share", plane.inlier_share},
                      {"residual_sigma", plane.residual_sigma},
                      {"height_sigma", plane.height_sigma},
                      {"confidence", plane.confidence},
                      {"boxes", boxes.size()}});
  }
  const double median = ademono::Median(heights);
  size_t within = 0;
  for (double h : heights) within += std::abs(h / median - 1.0) <= 0.03 ? 1 : 0;
  std::cout << fmt::format(
      "{} frames, {} with a ground plane; median height {:.3f} m; within 3 % of it: {} "
      "({:.1f} % of the frames)\n",
      total, heights.size(), median, within, total > 0 ? 100.0 * within / total : 0.0);
  if (args.reference_height > 0) {
    std::cout << fmt::format("median / reference {:.3f} m: {:.3f}\n", args.reference_height,
                             median / args.reference_height);
  }
  if (!args.json.empty()) {
    nlohmann::json j = {{"dataset", args.dataset},
                        {"depth", args.depth},
                        {"detector", args.detector},
                        {"from", args.from},
                        {"every", args.every},
                        {"corridor",
                         {{"min_depth", args.options.min_depth},
                          {"max_depth", args.options.max_depth},
                          {"max_lateral", args.options.max_lateral},
                          {"stride", args.options.stride}}},
                        {"median_height_m", median},
                        {"frames_with_plane", heights.size()},
                        {"frames_within_3_percent", within},
                        {"frames", frames}};
    ademono::WriteTextFileAtomic(args.json, j.dump(1) + "\n");
  }
  return 0;
}

const bool kRegistered = ademono::cli::RegisterCommand(
    "ground", "The camera's height above the road, per frame, from a depth source",
    [](CLI::App& app) -> ademono::cli::Runner {
      auto args = std::make_shared<GroundArgs>();
      app.add_option("--dataset", args->dataset, "KIND:PATH")->required();
      app.add_option("--camera", args->camera, "camera YAML (overrides the dataset's)");
      app.add_option("--depth", args->depth, "cache:DIR | model:FILE.onnx[,spec=Y] | sensor")
          ->required();
      app.add_option("--detector", args->detector,
                     "none | cache:FILE.jsonl | model:FILE.onnx: boxes kept out of the fit")
          ->capture_default_str();
      app.add_option("--from", args->from, "dense (the depth map) | keypoints (ORB with depth)")
          ->capture_default_str();
      app.add_option("--frames", args->frames, "START:END frame range (END exclusive)");
      app.add_option("--every", args->every, "every Nth frame")->capture_default_str();
      app.add_option("--gap", args->gap, "two-view: the second view is this many frames later")
          ->capture_default_str();
      app.add_flag("!--fixed-normal", args->two_view.fit_normal,
                   "two-view: keep the level normal, fit the height only");
      app.add_option("--finest-level", args->two_view.finest_level, "two-view: pyramid level")
          ->capture_default_str();
      app.add_option("--view-min-depth", args->two_view.min_depth, "two-view corridor: nearest")
          ->capture_default_str();
      app.add_option("--view-max-depth", args->two_view.max_depth, "two-view corridor: farthest")
          ->capture_default_str();
      app.add_option("--view-max-lateral", args->two_view.max_lateral,
                     "two-view corridor: to either side")
          ->capture_default_str();
      app.add_option("--orb-features", args->orb_features, "--from keypoints: ORB features")
          ->capture_default_str();
      app.add_option("--min-depth", args->options.min_depth, "corridor: nearest (m)")
          ->capture_default_str();
      app.add_option("--max-depth", args->options.max_depth, "corridor: farthest (m)")
          ->capture_default_str();
      app.add_option("--max-lateral", args->options.max_lateral, "corridor: to either side (m)")
          ->capture_default_str();
      app.add_option("--stride", args->options.stride, "dense: one pixel in N")
          ->capture_default_str();
      app.add_option("--inlier-ratio", args->options.plane.inlier_ratio,
                     "inliers within this fraction of the height")
          ->capture_default_str();
      app.add_option("--max-tilt", args->options.plane.max_tilt_deg,
                     "the road's normal within this of the camera's up axis (deg)")
          ->capture_default_str();
      app.add_option("--min-inliers", args->options.plane.min_inliers, "fewer: no estimate")
          ->capture_default_str();
      app.add_option("--reference-height", args->reference_height,
                     "the rig's camera height (m), to print the median's ratio to it");
      app.add_option("--json", args->json, "write every frame's estimate here");
      app.add_option("--poses", args->poses,
                     "two-view: the relative motion from this trajectory (a run's trajectory.tum "
                     "or .kitti, matched by timestamp) instead of the ground truth");
      return [args] { return RunGround(*args); };
    });

}  // namespace
