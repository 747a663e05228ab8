#include "ademono/slam/frame.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "ademono/slam/map_point.h"

namespace ademono {

ScalePyramid ScalePyramid::Make(int num_levels, float scale_factor) {
  ScalePyramid p;
  p.num_levels = num_levels;
  p.log_scale_factor = std::log(scale_factor);
  p.scale_factors.resize(num_levels);
  p.inv_scale_factors.resize(num_levels);
  p.level_sigma2.resize(num_levels);
  p.inv_level_sigma2.resize(num_levels);
  float s = 1.f;
  for (int i = 0; i < num_levels; ++i) {
    p.scale_factors[i] = s;
    p.inv_scale_factors[i] = 1.f / s;
    p.level_sigma2[i] = s * s;
    p.inv_level_sigma2[i] = 1.f / (s * s);
    s *= scale_factor;
  }
  return p;
}

std::shared_ptr<const FrameFeatures> MakeFrameFeatures(const Camera& camera,
                                                       std::shared_ptr<const ScalePyramid> pyramid,
                                                       double virtual_baseline, double close_depth,
                                                       std::vector<cv::KeyPoint> keypoints,
                                                       cv::Mat descriptors,
                                                       std::vector<float> depth,
                                                       const DepthErrorModel& depth_error,
                                                       bool weight_by_error_model,
                                                       bool monocular) {
  auto f = std::make_shared<FrameFeatures>();
  f->monocular = monocular;
  f->depth_error = depth_error;
  f->weight_by_error_model = weight_by_error_model;
  f->camera = camera;
  f->pyramid = std::move(pyramid);
  f->intrinsics = {camera.fx, camera.fy, camera.cx, camera.cy, virtual_baseline * camera.fx};
  f->close_depth = static_cast<float>(close_depth);
  f->keypoints = std::move(keypoints);
  f->descriptors = std::move(descriptors);
  f->depth = std::move(depth);
  const size_t n = f->keypoints.size();
  f->depth.resize(n, -1.f);

  // Undistorted keypoints and image bounds.
  f->keypoints_un = f->keypoints;
  if (camera.HasDistortion() && n > 0) {
    std::vector<cv::Point2f> pts(n);
    for (size_t i = 0; i < n; ++i) pts[i] = f->keypoints[i].pt;
    const std::vector<cv::Point2f> un = camera.Undistort(pts);
    for (size_t i = 0; i < n; ++i) f->keypoints_un[i].pt = un[i];
  }
  if (camera.HasDistortion()) {
    const std::vector<cv::Point2f> corners{
        {0.f, 0.f},
        {static_cast<float>(camera.width), 0.f},
        {0.f, static_cast<float>(camera.height)},
        {static_cast<float>(camera.width), static_cast<float>(camera.height)}};
    const std::vector<cv::Point2f> un = camera.Undistort(corners);
    f->min_x = std::min(un[0].x, un[2].x);
    f->max_x = std::max(un[1].x, un[3].x);
    f->min_y = std::min(un[0].y, un[1].y);
    f->max_y = std::max(un[2].y, un[3].y);
  } else {
    f->max_x = static_cast<float>(camera.width);
    f->max_y = static_cast<float>(camera.height);
  }

  f->u_right.assign(n, -1.f);
  const double bf = f->intrinsics.bf;
  for (size_t i = 0; i < n; ++i) {
    if (f->depth[i] > 0) {
      if (!monocular)
        f->u_right[i] = static_cast<float>(f->keypoints_un[i].pt.x - bf / f->depth[i]);
    } else {
      f->depth[i] = -1.f;
    }
  }

  // Counting sort by cell, keypoints in index order within each.
  constexpr int kCells = FrameFeatures::kGridCols * FrameFeatures::kGridRows;
  const float cell_w = (f->max_x - f->min_x) / FrameFeatures::kGridCols;
  const float cell_h = (f->max_y - f->min_y) / FrameFeatures::kGridRows;
  std::vector<int> cell_of(n, -1);
  f->grid_begin.assign(kCells + 1, 0);
  for (size_t i = 0; i < n; ++i) {
    const cv::Point2f& p = f->keypoints_un[i].pt;
    // Compared as floats before the cast: a far outlier would overflow int (undefined).
    const float gx = std::floor((p.x - f->min_x) / cell_w);
    const float gy = std::floor((p.y - f->min_y) / cell_h);
    if (!(gx >= 0.f && gx < FrameFeatures::kGridCols && gy >= 0.f && gy < FrameFeatures::kGridRows))
      continue;
    cell_of[i] = static_cast<int>(gy) * FrameFeatures::kGridCols + static_cast<int>(gx);
    ++f->grid_begin[cell_of[i] + 1];
  }
  for (int c = 0; c < kCells; ++c) f->grid_begin[c + 1] += f->grid_begin[c];
  f->grid_entries.resize(f->grid_begin[kCells]);
  std::vector<uint32_t> fill(f->grid_begin.begin(), f->grid_begin.end() - 1);
  for (size_t i = 0; i < n; ++i) {
    if (cell_of[i] < 0) continue;
    const cv::KeyPoint& kp = f->keypoints_un[i];
    f->grid_entries[fill[cell_of[i]]++] = {kp.pt.x, kp.pt.y, kp.octave, static_cast<uint32_t>(i)};
  }
  return f;
}

std::shared_ptr<const FrameFeatures> WithoutKeypoints(const FrameFeatures& features) {
  auto f = std::make_shared<FrameFeatures>();
  f->camera = features.camera;
  f->pyramid = features.pyramid;
  f->intrinsics = features.intrinsics;
  f->close_depth = features.close_depth;
  f->min_x = features.min_x;
  f->max_x = features.max_x;
  f->min_y = features.min_y;
  f->max_y = features.max_y;
  f->descriptors = cv::Mat(0, features.descriptors.cols, features.descriptors.type());
  f->depth_error = features.depth_error;
  f->weight_by_error_model = features.weight_by_error_model;
  f->monocular = features.monocular;
  f->depth_scale = features.depth_scale;
  return f;  // no grid either: FeaturesInArea finds nothing
}

std::shared_ptr<const FrameFeatures> WithoutDepth(const FrameFeatures& features) {
  auto f = std::make_shared<FrameFeatures>(features);
  std::fill(f->depth.begin(), f->depth.end(), -1.f);
  std::fill(f->u_right.begin(), f->u_right.end(), -1.f);
  return f;
}

std::shared_ptr<const FrameFeatures> RescaleDepth(const FrameFeatures& features, float scale) {
  auto f = std::make_shared<FrameFeatures>(features);
  f->depth_scale *= scale;
  const double bf = f->intrinsics.bf;
  for (size_t i = 0; i < f->Size(); ++i) {
    if (!(f->depth[i] > 0)) continue;
    f->depth[i] *= scale;
    if (!f->monocular)
      f->u_right[i] = static_cast<float>(f->keypoints_un[i].pt.x - bf / f->depth[i]);
  }
  return f;
}

std::vector<size_t> FrameFeatures::FeaturesInArea(float u, float v, float r, int min_level,
                                                  int max_level) const {
  std::vector<size_t> result;
  FeaturesInArea(u, v, r, min_level, max_level, &result);
  return result;
}

void FrameFeatures::FeaturesInArea(float u, float v, float r, int min_level, int max_level,
                                   std::vector<size_t>* out) const {
  out->clear();
  if (grid_begin.empty()) return;  // features without keypoints (a culled keyframe)
  const float cell_w = (max_x - min_x) / kGridCols;
  const float cell_h = (max_y - min_y) / kGridRows;
  const int x0 = std::max(0, static_cast<int>(std::floor((u - min_x - r) / cell_w)));
  const int x1 = std::min(kGridCols - 1, static_cast<int>(std::ceil((u - min_x + r) / cell_w)));
  const int y0 = std::max(0, static_cast<int>(std::floor((v - min_y - r) / cell_h)));
  const int y1 = std::min(kGridRows - 1, static_cast<int>(std::ceil((v - min_y + r) / cell_h)));
  if (x0 > x1 || y0 > y1) return;
  const int lo = min_level >= 0 ? min_level : std::numeric_limits<int>::min();
  const int hi = max_level >= 0 ? max_level : std::numeric_limits<int>::max();
  for (int y = y0; y <= y1; ++y) {
    // Cells x0..x1 of a row are contiguous.
    const GridEntry* e = grid_entries.data() + grid_begin[y * kGridCols + x0];
    const GridEntry* end = grid_entries.data() + grid_begin[y * kGridCols + x1 + 1];
    for (; e != end; ++e) {
      if (e->octave < lo || e->octave > hi) continue;
      if (std::abs(e->x - u) < r && std::abs(e->y - v) < r) out->push_back(e->index);
    }
  }
  std::sort(out->begin(), out->end());
}

ImageObservation FrameFeatures::Observation(size_t i) const {
  ImageObservation o;
  o.pixel = Eigen::Vector2d(keypoints_un[i].pt.x, keypoints_un[i].pt.y);
  o.u_right = u_right[i];
  o.inv_sigma2 = pyramid->inv_level_sigma2[keypoints_un[i].octave];
  if (depth_error.Enabled() && weight_by_error_model && depth[i] > 0) {
    // sigma(u_right) = bf * sigma_z / z^2 for u_right = u - bf / z.
    const double z = depth[i];
    o.depth_inv_sigma = z * z / (intrinsics.bf * depth_error.Sigma(z));
  }
  return o;
}

ImageObservation FrameFeatures::PriorObservation(size_t i, double z, double sigma_z) const {
  ImageObservation o = Observation(i);
  o.u_right = keypoints_un[i].pt.x - intrinsics.bf / z;
  // sigma(u_right) = bf * sigma_z / z^2 for u_right = u - bf / z.
  if (sigma_z > 0) o.depth_inv_sigma = z * z / (intrinsics.bf * sigma_z);
  return o;
}

Eigen::Vector3d FrameFeatures::UnprojectCamera(size_t i) const {
  return camera.Unproject(Eigen::Vector2d(keypoints_un[i].pt.x, keypoints_un[i].pt.y), depth[i]);
}

Frame::Frame(uint64_t id, size_t index, double timestamp,
             std::shared_ptr<const FrameFeatures> features)
    : id(id), index(index), timestamp(timestamp), features(std::move(features)) {
  map_points.resize(this->features->Size());
  outlier.assign(this->features->Size(), false);
}

bool Frame::InFrustum(const MapPoint& point, float view_cos_limit,
                      ProjectionPrediction* prediction) const {
  const Eigen::Vector3d pc = *cam_from_world * point.position;
  if (pc.z() <= 0) return false;
  const FrameFeatures& f = *features;
  const double inv_z = 1.0 / pc.z();
  const float u = static_cast<float>(f.intrinsics.fx * pc.x() * inv_z + f.intrinsics.cx);
  const float v = static_cast<float>(f.intrinsics.fy * pc.y() * inv_z + f.intrinsics.cy);
  if (!f.InBounds(u, v)) return false;
  const Eigen::Vector3d po = point.position - CameraCenter();
  const float dist = static_cast<float>(po.norm());
  if (dist < 0.8f * point.min_distance || dist > 1.2f * point.max_distance) return false;
  const float view_cos = static_cast<float>(po.dot(point.normal) / dist);
  if (view_cos < view_cos_limit) return false;
  prediction->u = u;
  prediction->v = v;
  prediction->u_right = static_cast<float>(u - f.intrinsics.bf * inv_z);
  prediction->level = point.PredictScale(dist, f.pyramid->log_scale_factor, f.pyramid->num_levels);
  prediction->view_cos = view_cos;
  return true;
}

int Frame::NumTrackedInliers() const {
  int n = 0;
  for (size_t i = 0; i < map_points.size(); ++i) {
    if (map_points[i] && !outlier[i]) ++n;
  }
  return n;
}

}  // namespace ademono
