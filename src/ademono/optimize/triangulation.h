#pragma once
// Two-view triangulation of a point from its normalised image coordinates (x / z, y / z) and the
// two cameras' cam_from_world poses: the linear (DLT) solution, as ORB-SLAM's and COLMAP's
// TriangulatePoint, plus the checks a new map point must pass.

#include <optional>

#include "ademono/core/geometry.h"

namespace ademono {

// The world point whose projections are `normalized1` in camera 1 and `normalized2` in camera 2,
// or nullopt when the system is degenerate (parallel rays through the same centre, or a point at
// infinity).
std::optional<Eigen::Vector3d> TriangulatePoint(const Rigid3d& cam1_from_world,
                                                const Rigid3d& cam2_from_world,
                                                const Eigen::Vector2d& normalized1,
                                                const Eigen::Vector2d& normalized2);

// Cosine of the angle between the two viewing rays of `point_world` (1 = no parallax).
double ParallaxCosine(const Rigid3d& cam1_from_world, const Rigid3d& cam2_from_world,
                      const Eigen::Vector3d& point_world);

}  // namespace ademono
