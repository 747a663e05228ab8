#include "ademono/optimize/ground_plane.h"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <stdexcept>

#include "ademono/core/statistics.h"

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
  Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
  std::vector<double> residuals;
  for (int iteration = 0; iteration < 10; ++iteration) {
    h.setZero();
    residuals.clear();
    Eigen::Vector3d g = Eigen::Vector3d::Zero();
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
      residuals.push_back(r);
    }
    if (residuals.size() < 3) return result;
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
  result.num_points = static_cast<int>(n);
  result.inlier_share = static_cast<double>(count) / static_cast<double>(n);
  // Spread of the last refit's residuals, and the height's standard error at that spread:
  // log height = log k - log(1 + a^2 + c^2) / 2.
  std::vector<double> absolute(residuals.size());
  const double centre = Median(residuals);
  for (size_t i = 0; i < residuals.size(); ++i) absolute[i] = std::abs(residuals[i] - centre);
  result.residual_sigma = 1.4826 * Median(absolute);
  const double q = 1.0 + a * a + c * c;
  const Eigen::Vector3d dlog_height(1.0, -a / q, -c / q);
  const Eigen::Matrix3d covariance = h.ldlt().solve(Eigen::Matrix3d::Identity());
  const double variance = dlog_height.dot(covariance * dlog_height);
  result.height_sigma =
      result.residual_sigma * std::sqrt(std::max(0.0, variance));
  result.confidence = result.inlier_share * std::exp(-result.height_sigma / 0.01);
  return result;
}

void GroundFromDepthOptions::Check() const {
  plane.Check();
  if (!(min_depth >= 0 && max_depth > min_depth))
    throw std::invalid_argument("ground from depth: need 0 <= min_depth < max_depth");
  if (!(max_lateral > 0)) throw std::invalid_argument("ground from depth: max_lateral must be > 0");
  if (stride < 1) throw std::invalid_argument("ground from depth: stride must be >= 1");
}

namespace {

bool InAnyBox(double x, double y, const std::vector<cv::Rect2d>& boxes) {
  for (const cv::Rect2d& b : boxes) {
    if (x >= b.x && x < b.x + b.width && y >= b.y && y < b.y + b.height) return true;
  }
  return false;
}

// The point at undistorted pixel `px` and depth `z`, if it lies in the corridor.
void AddIfInCorridor(const Camera& camera, const Eigen::Vector2d& px, double z,
                     const GroundFromDepthOptions& options, std::vector<Eigen::Vector3d>* out) {
  if (!(z >= options.min_depth && z <= options.max_depth) || !std::isfinite(z)) return;
  const Eigen::Vector3d p = camera.Unproject(px, z);
  if (p.y() > 0 && std::abs(p.x()) <= options.max_lateral) out->push_back(p);
}

}  // namespace

std::vector<Eigen::Vector3d> RoadCandidates(const cv::Mat& depth, const Camera& camera,
                                            const std::vector<cv::Rect2d>& exclude,
                                            const GroundFromDepthOptions& options) {
  options.Check();
  if (depth.type() != CV_32FC1)
    throw std::invalid_argument("RoadCandidates: depth must be CV_32FC1 metres");
  if (camera.width > 0 && (depth.cols != camera.width || depth.rows != camera.height))
    throw std::invalid_argument("RoadCandidates: depth map and camera differ in size");
  std::vector<Eigen::Vector3d> points;
  const int first_row = std::max(0, static_cast<int>(std::ceil(camera.cy)));
  const bool distorted = camera.HasDistortion();
  for (int r = first_row; r < depth.rows; r += options.stride) {
    const float* d = depth.ptr<float>(r);
    for (int c = 0; c < depth.cols; c += options.stride) {
      if (!(d[c] > 0) || InAnyBox(c, r, exclude)) continue;
      const Eigen::Vector2d px(c, r);
      AddIfInCorridor(camera, distorted ? camera.Undistort(px) : px, d[c], options, &points);
    }
  }
  return points;
}

std::vector<Eigen::Vector3d> RoadCandidates(const std::vector<cv::Point2f>& keypoints,
                                            const std::vector<float>& depths,
                                            const Camera& camera,
                                            const std::vector<cv::Rect2d>& exclude,
                                            const GroundFromDepthOptions& options) {
  options.Check();
  if (keypoints.size() != depths.size())
    throw std::invalid_argument("RoadCandidates: one depth per keypoint");
  std::vector<Eigen::Vector3d> points;
  for (size_t i = 0; i < keypoints.size(); ++i) {
    if (!(depths[i] > 0) || InAnyBox(keypoints[i].x, keypoints[i].y, exclude)) continue;
    const Eigen::Vector2d px(keypoints[i].x, keypoints[i].y);
    AddIfInCorridor(camera, camera.HasDistortion() ? camera.Undistort(px) : px, depths[i], options,
                    &points);
  }
  return points;
}

GroundPlane EstimateGroundFromDepth(const cv::Mat& depth, const Camera& camera,
                                    const std::vector<cv::Rect2d>& exclude,
                                    const GroundFromDepthOptions& options) {
  return EstimateGroundPlane(RoadCandidates(depth, camera, exclude, options), options.plane);
}

}  // namespace ademono
