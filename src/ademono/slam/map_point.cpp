#include "ademono/slam/map_point.h"

#include <algorithm>
#include <cmath>

#include "ademono/feature/orb_extractor.h"
#include "ademono/slam/keyframe.h"

namespace ademono {

bool KeyFrameIdLess::operator()(const KeyFrame* a, const KeyFrame* b) const {
  return a->id < b->id;
}

MapPoint::MapPoint(uint64_t id, const Eigen::Vector3d& position, KeyFrame* reference,
                   uint64_t first_frame_id)
    : id(id),
      position(position),
      reference(reference),
      first_keyframe_id(reference != nullptr ? reference->id : 0),
      first_frame_id(first_frame_id) {}

void MapPoint::AddObservation(KeyFrame* keyframe, size_t index) { observations[keyframe] = index; }

void MapPoint::EraseObservation(KeyFrame* keyframe) {
  observations.erase(keyframe);
  if (reference == keyframe)
    reference = observations.empty() ? nullptr : observations.begin()->first;
}

void MapPoint::ComputeDistinctiveDescriptor() {
  if (frozen) return;  // a loaded map's point keeps its descriptor (localisation only)
  // Raw row pointers and one flat distance table: this runs for every point a keyframe touches,
  // and cv::Mat row headers and per-row vectors dominated its cost.
  std::vector<const uchar*> rows;
  rows.reserve(observations.size());
  for (const auto& [kf, idx] : observations) {
    if (!kf->bad) rows.push_back(kf->F().descriptors.ptr<uchar>(static_cast<int>(idx)));
  }
  if (rows.empty()) return;
  const size_t n = rows.size();
  std::vector<int> distances(n * n, 0);
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = i + 1; j < n; ++j) {
      distances[i * n + j] = distances[j * n + i] = DescriptorDistance(rows[i], rows[j]);
    }
  }
  int best_median = INT32_MAX;
  size_t best = 0;
  std::vector<int> row(n);
  for (size_t i = 0; i < n; ++i) {
    std::copy(distances.begin() + i * n, distances.begin() + (i + 1) * n, row.begin());
    std::nth_element(row.begin(), row.begin() + (n - 1) / 2, row.end());
    const int median = row[(n - 1) / 2];
    if (median < best_median) {
      best_median = median;
      best = i;
    }
  }
  descriptor = cv::Mat(1, 32, CV_8UC1);
  std::copy(rows[best], rows[best] + 32, descriptor.ptr<uchar>());
}

void MapPoint::UpdateNormalAndDepth() {
  if (frozen) return;  // as ComputeDistinctiveDescriptor
  if (observations.empty() || reference == nullptr) return;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int n = 0;
  for (const auto& [kf, idx] : observations) {
    const Eigen::Vector3d dir = position - kf->CameraCenter();
    const double norm = dir.norm();
    if (norm > 0) {
      sum += dir / norm;
      ++n;
    }
  }
  if (n > 0 && sum.norm() > 0) normal = sum.normalized();
  const auto it = observations.find(reference);
  if (it == observations.end()) return;
  const float dist = static_cast<float>((position - reference->CameraCenter()).norm());
  const ScalePyramid& pyramid = *reference->F().pyramid;
  const int level = reference->F().keypoints_un[it->second].octave;
  max_distance = dist * pyramid.scale_factors[level];
  min_distance = max_distance / pyramid.scale_factors[pyramid.num_levels - 1];
}

int MapPoint::PredictScale(float distance, float log_scale_factor, int num_levels) const {
  if (distance <= 0) return 0;
  const float ratio = max_distance / distance;
  int level = static_cast<int>(std::ceil(std::log(ratio) / log_scale_factor));
  return std::clamp(level, 0, num_levels - 1);
}

std::shared_ptr<MapPoint> MapPoint::Resolve(std::shared_ptr<MapPoint> point) {
  int guard = 0;
  while (point && point->replaced_by && guard++ < 100) point = point->replaced_by;
  return point;
}

}  // namespace ademono
