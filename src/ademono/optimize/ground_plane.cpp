#include "ademono/optimize/ground_plane.h"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>

#include <cmath>
#include <cstdint>
#include <random>
#include <stdexcept>

namespace ademono {
namespace {

struct Plane {
  Eigen::Vector3d normal;  // unit, camera side positive
  double height;           // the camera's distance above the plane
};

// Signed distance of p above the plane (towards the camera side): the camera (origin) is at
// `height`, a point on the plane at 0.
double Distance(const Plane& plane, const Eigen::Vector3d& p) {
  return plane.height + plane.normal.dot(p);
}

// Orients the plane so that the camera is on its positive side; false when degenerate.
bool Orient(Eigen::Vector3d normal, double offset, Plane* plane) {
  const double norm = normal.norm();
  if (!(norm > 1e-12)) return false;
  normal /= norm;
  offset /= norm;
  if (offset < 0) {
    normal = -normal;
    offset = -offset;
  }
  *plane = {normal, offset};
  return true;
}

int CountInliers(const Plane& plane, const std::vector<Eigen::Vector3d>& points, double tolerance) {
  int n = 0;
  for (const Eigen::Vector3d& p : points) n += std::abs(Distance(plane, p)) <= tolerance ? 1 : 0;
  return n;
}

}  // namespace

void GroundPlaneOptions::Check() const {
  if (!(max_tilt_deg > 0 && max_tilt_deg < 90))
    throw std::invalid_argument("ground plane: max_tilt_deg must be in (0, 90)");
  if (!(inlier_ratio > 0)) throw std::invalid_argument("ground plane: inlier_ratio must be > 0");
  if (min_inliers < 3) throw std::invalid_argument("ground plane: min_inliers must be >= 3");
  if (!(min_inlier_share >= 0 && min_inlier_share <= 1))
    throw std::invalid_argument("ground plane: min_inlier_share must be in [0, 1]");
  if (iterations < 1) throw std::invalid_argument("ground plane: iterations must be >= 1");
}

GroundPlane EstimateGroundPlane(const std::vector<Eigen::Vector3d>& points_cam,
                                const GroundPlaneOptions& options) {
  GroundPlane result;
  const size_t n = points_cam.size();
  if (n < 3 || static_cast<int>(n) < options.min_inliers) return result;
  const double min_up = std::cos(options.max_tilt_deg * M_PI / 180.0);
  const Eigen::Vector3d up(0, -1, 0);
  std::mt19937 rng(20261125u);
  Plane best{up, 0};
  int best_count = -1;
  for (int it = 0; it < options.iterations; ++it) {
    const size_t a = rng() % n, b = rng() % n, c = rng() % n;
    if (a == b || b == c || a == c) continue;
    const Eigen::Vector3d normal =
        (points_cam[b] - points_cam[a]).cross(points_cam[c] - points_cam[a]);
    Plane plane;
    if (!Orient(normal, -normal.dot(points_cam[a]), &plane)) continue;
    if (plane.normal.dot(up) < min_up || !(plane.height > 0)) continue;
    const int count = CountInliers(plane, points_cam, options.inlier_ratio * plane.height);
    if (count > best_count) {
      best_count = count;
      best = plane;
    }
  }
  if (best_count < options.min_inliers) return result;

  // Refit by maximum likelihood for depth errors proportional to depth (a network's): with the
  // plane written as y = a x + c z + k (camera frame, y down), the depth it predicts along the
  // ray (u, v) = (x, y) / z is k / (v - a u - c), and each inlier's residual is the log of its
  // measured over that depth. Gauss-Newton on (log k, a, c). A least-squares fit of the points
  // instead (errors along the rays, mostly forward) is pulled: 1.3 % low at 3 % depth noise.
  double a = -best.normal.x() / best.normal.y(), c = -best.normal.z() / best.normal.y();
  double log_k = std::log(-best.height / best.normal.y());
  for (int iteration = 0; iteration < 10; ++iteration) {
    Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
    Eigen::Vector3d g = Eigen::Vector3d::Zero();
    int m = 0;
    for (const Eigen::Vector3d& p : points_cam) {
      if (!(p.z() > 0)) continue;
      const double u = p.x() / p.z(), v = p.y() / p.z();
      const double denominator = v - a * u - c;
      if (!(denominator > 0)) continue;
      const double r = std::log(p.z()) - log_k + std::log(denominator);
      if (std::abs(r) > options.inlier_ratio) continue;
      const Eigen::Vector3d j(-1.0, -u / denominator, -1.0 / denominator);
      h += j * j.transpose();
      g += j * r;
      ++m;
    }
    if (m < 3) return result;
    const Eigen::Vector3d step = h.ldlt().solve(-g);
    if (!step.allFinite()) return result;
    log_k += step(0);
    a += step(1);
    c += step(2);
    if (step.norm() < 1e-12) break;
  }
  Plane refit;
  if (!Orient(Eigen::Vector3d(-a, 1.0, -c), -std::exp(log_k), &refit) ||
      refit.normal.dot(up) < min_up) {
    return result;
  }
  best = refit;
  const int count = CountInliers(best, points_cam, options.inlier_ratio * best.height);
  if (count < options.min_inliers || count < options.min_inlier_share * static_cast<double>(n)) {
    return result;
  }
  result.valid = true;
  result.normal = best.normal;
  result.height = best.height;
  result.num_inliers = count;
  return result;
}

}  // namespace ademono
