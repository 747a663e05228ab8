#include "ademono/optimize/ground_plane.h"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <opencv2/imgproc.hpp>

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

bool OnPlane(const Plane& plane, const Eigen::Vector3d& p, double tolerance) {
  return std::abs(Distance(plane, p)) <= tolerance;
}

// RANSAC's score: counts without collecting (the final fit collects, InlierIndices).
int CountInliers(const Plane& plane, const std::vector<Eigen::Vector3d>& points, double tolerance) {
  int n = 0;
  for (const Eigen::Vector3d& p : points) n += OnPlane(plane, p, tolerance) ? 1 : 0;
  return n;
}

std::vector<int> InlierIndices(const Plane& plane, const std::vector<Eigen::Vector3d>& points,
                               double tolerance) {
  std::vector<int> inliers;
  for (size_t i = 0; i < points.size(); ++i) {
    if (OnPlane(plane, points[i], tolerance)) inliers.push_back(static_cast<int>(i));
  }
  return inliers;
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
  std::vector<int> inliers = InlierIndices(best, points_cam, options.inlier_ratio * best.height);
  const int count = static_cast<int>(inliers.size());
  if (count < options.min_inliers || count < options.min_inlier_share * static_cast<double>(n)) {
    return result;
  }
  result.valid = true;
  result.normal = best.normal;
  result.height = best.height;
  result.num_inliers = count;
  result.inliers = std::move(inliers);
  result.num_points = static_cast<int>(n);
  result.inlier_share = static_cast<double>(count) / static_cast<double>(n);
  // Spread of the last refit's residuals, and the height's standard error at that spread:
  // log height = log k - log(1 + a^2 + c^2) / 2.
  result.residual_sigma = RobustSpread(residuals, Median(residuals));
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

GroundPlane GroundHeightAlong(const std::vector<Eigen::Vector3d>& points_cam,
                              const Eigen::Vector3d& normal, const GroundPlaneOptions& options) {
  GroundPlane result;
  const Eigen::Vector3d n = normal.normalized();
  std::vector<double> heights;
  for (const Eigen::Vector3d& p : points_cam) {
    const double h = -n.dot(p);
    if (h > 0) heights.push_back(h);
  }
  if (static_cast<int>(heights.size()) < options.min_inliers) return result;
  const double height = Median(heights);
  std::vector<double> log_residuals;
  for (double h : heights) {
    if (std::abs(std::log(h / height)) <= options.inlier_ratio)
      log_residuals.push_back(std::log(h / height));
  }
  result.normal = n;
  result.height = height;
  result.num_points = static_cast<int>(points_cam.size());
  result.num_inliers = static_cast<int>(log_residuals.size());
  result.inlier_share = static_cast<double>(result.num_inliers) / result.num_points;
  result.residual_sigma = RobustSpread(log_residuals);
  result.height_sigma =
      result.num_inliers > 0 ? result.residual_sigma / std::sqrt(result.num_inliers) : 0.0;
  result.confidence = result.inlier_share * std::exp(-result.height_sigma / 0.01);
  result.valid = result.num_inliers >= options.min_inliers &&
                 result.inlier_share >= options.min_inlier_share;
  return result;
}

GroundPlane EstimateGroundFromDepth(const cv::Mat& depth, const Camera& camera,
                                    const std::vector<cv::Rect2d>& exclude,
                                    const GroundFromDepthOptions& options) {
  return EstimateGroundPlane(RoadCandidates(depth, camera, exclude, options), options.plane);
}

}  // namespace ademono

namespace ademono {

void TwoViewGroundOptions::Check() const {
  if (!(min_depth > 0 && max_depth > min_depth))
    throw std::invalid_argument("two-view ground: need 0 < min_depth < max_depth");
  if (!(max_lateral > 0)) throw std::invalid_argument("two-view ground: max_lateral must be > 0");
  if (finest_level < 0 || coarsest_level < finest_level || coarsest_level > 5)
    throw std::invalid_argument("two-view ground: need 0 <= finest_level <= coarsest_level <= 5");
  if (iterations < 1) throw std::invalid_argument("two-view ground: iterations must be >= 1");
  if (!(huber > 0)) throw std::invalid_argument("two-view ground: huber must be > 0");
  if (min_pixels < 10) throw std::invalid_argument("two-view ground: min_pixels must be >= 10");
  if (!(min_gradient >= 0))
    throw std::invalid_argument("two-view ground: min_gradient must be >= 0");
  if (!(min_inlier_share >= 0 && min_inlier_share <= 1))
    throw std::invalid_argument("two-view ground: min_inlier_share must be in [0, 1]");
  if (!(max_tilt_deg > 0 && max_tilt_deg < 90))
    throw std::invalid_argument("two-view ground: max_tilt_deg must be in (0, 90)");
}

namespace {

cv::Mat GreyFloat(const cv::Mat& image) {
  cv::Mat grey;
  if (image.channels() == 3) {
    cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  } else if (image.channels() == 1) {
    grey = image;
  } else {
    throw std::invalid_argument("EstimateGroundFromTwoViews: image must be grey or BGR");
  }
  cv::Mat out;
  grey.convertTo(out, CV_32F);
  return out;
}

// Bilinear sample of a CV_32F image at (x, y); false outside.
bool Sample(const cv::Mat& image, double x, double y, float* value) {
  if (!(x >= 0 && y >= 0 && x < image.cols - 1 && y < image.rows - 1)) return false;
  const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
  const double fx = x - x0, fy = y - y0;
  const float* r0 = image.ptr<float>(y0);
  const float* r1 = image.ptr<float>(y0 + 1);
  *value = static_cast<float>((1 - fy) * ((1 - fx) * r0[x0] + fx * r0[x0 + 1]) +
                              fy * ((1 - fx) * r1[x0] + fx * r1[x0 + 1]));
  return true;
}

}  // namespace

GroundPlane EstimateGroundFromTwoViews(const cv::Mat& image_a, const cv::Mat& image_b,
                                       const Rigid3d& b_from_a, const Camera& camera,
                                       const GroundPlane& initial,
                                       const std::vector<cv::Rect2d>& exclude,
                                       const TwoViewGroundOptions& options) {
  options.Check();
  if (image_a.size() != image_b.size() ||
      (camera.width > 0 && (image_a.cols != camera.width || image_a.rows != camera.height)))
    throw std::invalid_argument("EstimateGroundFromTwoViews: images and camera differ in size");
  GroundPlane result;
  if (!(initial.height > 0)) return result;
  const Eigen::Matrix3d rotation = b_from_a.linear();
  const Eigen::Vector3d t = b_from_a.translation();
  if (!(t.norm() > 0)) return result;
  // m = n / h with n pointing from the camera to the plane: a road point X has m.X = 1.
  Eigen::Vector3d m = -initial.normal.normalized() / initial.height;
  const Eigen::Vector3d up = initial.normal.normalized();

  // Pyramids of both images and of b's gradients.
  std::vector<cv::Mat> pa(1, GreyFloat(image_a)), pb(1, GreyFloat(image_b));
  for (int l = 1; l <= options.coarsest_level; ++l) {
    cv::Mat a, b;
    cv::pyrDown(pa.back(), a);
    cv::pyrDown(pb.back(), b);
    pa.push_back(a);
    pb.push_back(b);
  }
  const bool distorted = camera.HasDistortion();
  double gain = 1.0, bias = 0.0;
  std::vector<double> residuals;
  Eigen::Matrix<double, 5, 5> normal_matrix = Eigen::Matrix<double, 5, 5>::Zero();
  int used = 0, inliers = 0;
  double gradient_energy = 0;  // sum of |grad b|^2 over the pixels used (texture)
  for (int level = options.coarsest_level; level >= options.finest_level; --level) {
    const double s = 1.0 / (1 << level);
    const cv::Mat& ia = pa[level];
    const cv::Mat& ib = pb[level];
    cv::Mat gx, gy;
    cv::Sobel(ib, gx, CV_32F, 1, 0, 3, 1.0 / 8);
    cv::Sobel(ib, gy, CV_32F, 0, 1, 3, 1.0 / 8);
    // pyrDown's pixel c is centred on pixel 2c of the level below: c / s at full resolution.
    const double fx = camera.fx * s, fy = camera.fy * s;
    const double cx = camera.cx * s, cy = camera.cy * s;
    // The corridor, placed with the plane as it stands at the start of this level.
    struct Pixel {
      Eigen::Vector3d ray;  // normalised ray of view a, (x, y, 1)
      float value;
    };
    std::vector<Pixel> pixels;
    for (int r = 0; r < ia.rows; ++r) {
      for (int c = 0; c < ia.cols; ++c) {
        const double u0 = c / s, v0 = r / s;
        if (InAnyBox(u0, v0, exclude)) continue;
        Eigen::Vector2d px(u0, v0);
        if (distorted) px = camera.Undistort(px);
        const Eigen::Vector3d ray((px.x() - camera.cx) / camera.fx,
                                  (px.y() - camera.cy) / camera.fy, 1.0);
        const double inverse_depth = m.dot(ray);
        if (!(inverse_depth > 0)) continue;
        const double z = 1.0 / inverse_depth;
        if (z < options.min_depth || z > options.max_depth ||
            std::abs(ray.x() * z) > options.max_lateral)
          continue;
        pixels.push_back({ray, ia.at<float>(r, c)});
      }
    }
    for (int iteration = 0; iteration < options.iterations; ++iteration) {
      Eigen::Matrix<double, 5, 5> h = Eigen::Matrix<double, 5, 5>::Zero();
      Eigen::Matrix<double, 5, 1> g = Eigen::Matrix<double, 5, 1>::Zero();
      residuals.clear();
      used = inliers = 0;
      gradient_energy = 0;
      for (const Pixel& p : pixels) {
        const double d = m.dot(p.ray);
        const Eigen::Vector3d w = rotation * p.ray + t * d;
        if (!(w.z() > 1e-6)) continue;
        // Undistorted projection into b at this level (distortion is small where the road is;
        // b's image is sampled without it, as a's corridor was undistorted).
        const double qx = fx * w.x() / w.z() + cx, qy = fy * w.y() / w.z() + cy;
        float value, dx, dy;
        if (!Sample(ib, qx, qy, &value) || !Sample(gx, qx, qy, &dx) || !Sample(gy, qx, qy, &dy))
          continue;
        const double r = value - (gain * p.value + bias);
        // dq/dw, then dw/dm = t ray^T.
        const double iz = 1.0 / w.z();
        const Eigen::RowVector3d dqx(fx * iz, 0, -fx * w.x() * iz * iz);
        const Eigen::RowVector3d dqy(0, fy * iz, -fy * w.y() * iz * iz);
        const Eigen::RowVector3d dw = dx * dqx + dy * dqy;
        Eigen::Matrix<double, 1, 5> j;
        j << dw.dot(t) * p.ray.transpose(), -p.value, -1.0;
        const double weight = std::abs(r) <= options.huber ? 1.0 : options.huber / std::abs(r);
        h += weight * j.transpose() * j;
        g += weight * j.transpose() * r;
        residuals.push_back(r);
        gradient_energy += static_cast<double>(dx) * dx + static_cast<double>(dy) * dy;
        ++used;
        inliers += std::abs(r) <= options.huber ? 1 : 0;
      }
      if (used < 10) return result;
      if (!options.fit_normal) {
        // Only the length of m along the initial normal: reduce to (alpha, gain, bias) and put
        // the solution back as a step along `up`.
        Eigen::Matrix<double, 5, 3> basis = Eigen::Matrix<double, 5, 3>::Zero();
        basis.block<3, 1>(0, 0) = -up;
        basis(3, 1) = basis(4, 2) = 1.0;
        const Eigen::Matrix3d hr = basis.transpose() * h * basis;
        const Eigen::Vector3d reduced = hr.ldlt().solve(-basis.transpose() * g);
        if (!reduced.allFinite()) return result;
        const Eigen::Matrix<double, 5, 1> step = basis * reduced;
        m += step.head<3>();
        gain += step(3);
        bias += step(4);
        normal_matrix = h;
        if (step.head<3>().norm() < 1e-7 * m.norm()) break;
        continue;
      }
      const Eigen::Matrix<double, 5, 1> step = h.ldlt().solve(-g);
      if (!step.allFinite()) return result;
      m += step.head<3>();
      gain += step(3);
      bias += step(4);
      normal_matrix = h;
      if (step.head<3>().norm() < 1e-7 * m.norm()) break;
    }
  }
  const double norm = m.norm();
  if (!(norm > 0)) return result;
  const Eigen::Vector3d normal = -m / norm;
  if (normal.dot(up) < std::cos(options.max_tilt_deg * M_PI / 180.0)) return result;
  result.normal = normal;
  result.height = 1.0 / norm;
  result.num_points = used;
  result.num_inliers = inliers;
  result.inlier_share = used > 0 ? static_cast<double>(inliers) / used : 0.0;
  result.residual_sigma = RobustSpread(residuals);
  // The height's standard error at that spread: log h = -log |m|.
  const Eigen::Matrix<double, 5, 5> covariance =
      normal_matrix.ldlt().solve(Eigen::Matrix<double, 5, 5>::Identity());
  Eigen::Matrix<double, 5, 1> dlog_height = Eigen::Matrix<double, 5, 1>::Zero();
  dlog_height.head<3>() = -m / (norm * norm);
  result.height_sigma = result.residual_sigma *
                        std::sqrt(std::max(0.0, dlog_height.dot(covariance * dlog_height)));
  result.confidence = result.inlier_share * std::exp(-result.height_sigma / 0.01);
  // A road without texture (or a uniform image) does not constrain the plane.
  const double rms_gradient = used > 0 ? std::sqrt(gradient_energy / used) : 0.0;
  result.valid = used >= options.min_pixels && result.inlier_share >= options.min_inlier_share &&
                 rms_gradient >= options.min_gradient && std::isfinite(result.height_sigma);
  return result;
}

}  // namespace ademono
