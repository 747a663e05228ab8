#include "ademono/io/timed_poses.h"

#include <algorithm>
#include <cmath>
#include <tuple>

namespace ademono {

Rigid3d InterpolatePose(const Rigid3d& a, const Rigid3d& b, double alpha) {
  const Eigen::Quaterniond qa(a.linear());
  const Eigen::Quaterniond qb(b.linear());
  Rigid3d out = Rigid3d::Identity();
  out.linear() = qa.slerp(alpha, qb).normalized().toRotationMatrix();
  out.translation() = (1.0 - alpha) * a.translation() + alpha * b.translation();
  return out;
}

std::optional<Rigid3d> LookupPose(const Trajectory& trajectory, double timestamp,
                                  const PoseLookupOptions& options) {
  if (trajectory.empty()) return std::nullopt;
  const auto upper =
      std::lower_bound(trajectory.begin(), trajectory.end(), timestamp,
                       [](const StampedPose& pose, double t) { return pose.timestamp < t; });
  if (upper != trajectory.end() && upper->timestamp == timestamp) return upper->world_from_cam;
  if (upper != trajectory.begin() && upper != trajectory.end()) {
    const StampedPose& a = *(upper - 1);
    const StampedPose& b = *upper;
    const double gap = b.timestamp - a.timestamp;
    if (gap > 0 && gap <= options.max_interpolation_gap) {
      return InterpolatePose(a.world_from_cam, b.world_from_cam, (timestamp - a.timestamp) / gap);
    }
  }
  // Nearest neighbour of the two candidates around the query.
  std::optional<Rigid3d> best;
  double best_diff = options.max_nearest_diff;
  for (auto it : {upper, upper == trajectory.begin() ? trajectory.end() : upper - 1}) {
    if (it == trajectory.end()) continue;
    const double diff = std::abs(it->timestamp - timestamp);
    if (diff <= best_diff) {
      best_diff = diff;
      best = it->world_from_cam;
    }
  }
  return best;
}

std::vector<std::pair<size_t, size_t>> AssociateTimestamps(const std::vector<double>& a,
                                                           const std::vector<double>& b,
                                                           double max_diff) {
  // Candidates via a window search on sorted `b` (associate.py tests all pairs; same result).
  std::vector<std::tuple<double, size_t, size_t>> candidates;
  size_t start = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    while (start < b.size() && b[start] <= a[i] - max_diff) ++start;
    for (size_t j = start; j < b.size() && b[j] < a[i] + max_diff; ++j) {
      const double diff = std::abs(a[i] - b[j]);
      if (diff < max_diff) candidates.emplace_back(diff, i, j);
    }
  }
  std::sort(candidates.begin(), candidates.end());
  std::vector<bool> used_a(a.size(), false), used_b(b.size(), false);
  std::vector<std::pair<size_t, size_t>> matches;
  for (const auto& [diff, i, j] : candidates) {
    if (used_a[i] || used_b[j]) continue;
    used_a[i] = used_b[j] = true;
    matches.emplace_back(i, j);
  }
  std::sort(matches.begin(), matches.end());
  return matches;
}

}  // namespace ademono
