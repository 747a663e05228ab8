#pragma once
// Pose-graph optimisation over similarity transforms (ORB-SLAM's OptimizeEssentialGraph) with
// Ceres: one Sim(3) vertex per keyframe (cam_from_world), one relative-pose edge per graph link,
// identity information unless an edge carries its own (diagonal). With `fix_scale` every scale
// stays at its start value, which is SE(3) pose-graph optimisation (sensor depth: metric scale
// is observed, it cannot drift).
// Single-threaded with blocks added in vertex order: identical results run to run.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

#include "ademono/core/geometry.h"
#include "ademono/optimize/optimizer_types.h"

namespace ademono {

// b_from_a as a similarity: x_b = scale * rotation * x_a + translation.
struct Sim3d {
  double scale = 1.0;
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  static Sim3d FromRigid(const Rigid3d& rigid);
  Sim3d Inverse() const;
  Sim3d operator*(const Sim3d& other) const;
  Eigen::Vector3d operator*(const Eigen::Vector3d& x) const {
    return scale * (rotation * x) + translation;
  }
  // The rigid part with the translation divided by the scale: the metric pose of a camera whose
  // world was scaled by 1 / scale (ORB-SLAM's Sim3 -> SE3 after the essential graph).
  Rigid3d ToRigid() const;
};

struct PoseGraphEdge {
  size_t i = 0, j = 0;  // vertex indices
  Sim3d i_from_j;       // measured relative pose: cam_i_from_cam_j
  // Square-root information (diagonal) of the residual (rotation x3, translation x3, log scale).
  Eigen::Matrix<double, 7, 1> sqrt_information = Eigen::Matrix<double, 7, 1>::Ones();
};

struct PoseGraphProblem {
  std::vector<Sim3d> cam_from_world;  // one per vertex, the start values
  std::vector<bool> fixed;            // same size; at least one vertex should be fixed
  std::vector<PoseGraphEdge> edges;
  bool fix_scale = false;  // SE(3) instead of Sim(3)
  int iterations = 20;
};

struct PoseGraphResult {
  std::vector<Sim3d> cam_from_world;
  double initial_cost = 0, final_cost = 0;
};

// Throws std::invalid_argument for bad indices or sizes.
PoseGraphResult SolvePoseGraph(const PoseGraphProblem& problem);

// A point of one camera observed by a keypoint of the other (ORB-SLAM's OptimizeSim3 edges).
struct Sim3Observation {
  Eigen::Vector3d point;  // in the source camera's frame
  Eigen::Vector2d pixel;  // undistorted keypoint in the target camera
  double inv_sigma2 = 1;  // 1 / sigma^2 of the keypoint's level
};

// Refines b_from_a (a Sim(3), or SE(3) with fix_scale) by reprojection: `in_b` are points of a
// seen in b's image, `in_a` points of b seen in a's image. Huber loss (chi2 5.99 at one sigma of
// the level); returns the refined transform.
Sim3d RefineSim3(const Sim3d& b_from_a, const PinholeIntrinsics& intrinsics_a,
                 const PinholeIntrinsics& intrinsics_b, const std::vector<Sim3Observation>& in_b,
                 const std::vector<Sim3Observation>& in_a, bool fix_scale, int iterations = 10);

}  // namespace ademono
