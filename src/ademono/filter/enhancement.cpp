#include "ademono/filter/enhancement.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace ademono {
namespace {

bool KnownDepth(float d) { return std::isfinite(d) && d > 0.f; }

// Child (0..3) of a block centred at (xm, ym): top-left, top-right, bottom-right, bottom-left.
int Quadrant(const cv::Point2f& p, double xm, double ym) {
  const bool right = p.x >= xm, bottom = p.y >= ym;
  if (!bottom) return right ? 1 : 0;
  return right ? 2 : 3;
}

}  // namespace

double DefaultPPercent(cv::Size image_size) {
  const double diag2 = static_cast<double>(image_size.width) * image_size.width +
                       static_cast<double>(image_size.height) * image_size.height;
  if (diag2 <= 0) throw std::invalid_argument("DefaultPPercent: image size must be positive");
  return 100.0 / diag2;
}

double EnhancementWeight(const cv::Point2f& current, const cv::Point2f& candidate,
                         float candidate_depth, float min_depth, float max_depth, double p_percent,
                         double q_percent) {
  const double dx = static_cast<double>(candidate.x) - current.x;
  const double dy = static_cast<double>(candidate.y) - current.y;
  double depth_term = 0.0;
  if (KnownDepth(candidate_depth) && max_depth > min_depth)
    depth_term = (static_cast<double>(candidate_depth) - min_depth) / (max_depth - min_depth);
  return (dx * dx + dy * dy) * (p_percent / 100.0) * std::exp(depth_term) * (q_percent / 100.0);
}

std::vector<int> SelectInBlock(const std::vector<int>& members,
                               const std::vector<cv::Point2f>& points,
                               const std::vector<float>& depths, double keep_ratio,
                               double p_percent, double q_percent) {
  const size_t n = members.size();
  if (n == 0) return {};
  auto depth_of = [&](int i) { return depths.empty() ? 0.f : depths[static_cast<size_t>(i)]; };
  // ceil, with a small tolerance so that e.g. 0.75 * 4 = 3.0000000001 does not round up to 4.
  const size_t keep =
      std::min(n, static_cast<size_t>(std::ceil(keep_ratio * static_cast<double>(n) - 1e-9)));

  float min_depth = std::numeric_limits<float>::infinity();
  float max_depth = -std::numeric_limits<float>::infinity();
  size_t start = 0;
  for (size_t k = 0; k < n; ++k) {
    const float d = depth_of(members[k]);
    if (!KnownDepth(d)) continue;
    if (d < min_depth) {
      min_depth = d;
      start = k;
    }
    max_depth = std::max(max_depth, d);
  }
  if (!std::isfinite(min_depth)) min_depth = max_depth = 0.f;  // no known depth in the block

  std::vector<int> chosen;
  chosen.reserve(keep);
  std::vector<char> taken(n, 0);
  size_t current = start;
  taken[current] = 1;
  chosen.push_back(members[current]);
  while (chosen.size() < keep) {
    size_t best = n;
    double best_weight = -std::numeric_limits<double>::infinity();
    const cv::Point2f& from = points[static_cast<size_t>(members[current])];
    for (size_t k = 0; k < n; ++k) {
      if (taken[k]) continue;
      const int idx = members[k];
      double w = EnhancementWeight(from, points[static_cast<size_t>(idx)], depth_of(idx), min_depth,
                                   max_depth, p_percent, q_percent);
      // A NaN position gives a NaN weight: rank it below every real candidate (weights are >= 0)
      // so the walk still picks exactly `keep` points.
      if (std::isnan(w)) w = -1.0;
      // Strictly greater: ties keep the earlier member (members are in ascending index order).
      if (w > best_weight) {
        best_weight = w;
        best = k;
      }
    }
    current = best;
    taken[current] = 1;
    chosen.push_back(members[current]);
  }
  return chosen;
}

std::vector<int> QuadtreeLeafBlocks(const std::vector<cv::Point2f>& points, cv::Size image_size,
                                    int levels) {
  if (levels < 0) throw std::invalid_argument("QuadtreeLeafBlocks: levels must be >= 0");
  std::vector<int> blocks(points.size(), 0);
  for (size_t i = 0; i < points.size(); ++i) {
    double x0 = 0, y0 = 0, x1 = image_size.width, y1 = image_size.height;
    int block = 0;
    for (int l = 0; l < levels; ++l) {
      const double xm = 0.5 * (x0 + x1), ym = 0.5 * (y0 + y1);
      const int q = Quadrant(points[i], xm, ym);  // NaN coordinates land top-left
      block = block * 4 + q;
      if (q == 1 || q == 2)
        x0 = xm;
      else
        x1 = xm;
      if (q >= 2)
        y0 = ym;
      else
        y1 = ym;
    }
    blocks[i] = block;
  }
  return blocks;
}

std::vector<bool> SelectEnhancedFeatures(const std::vector<cv::Point2f>& points,
                                         const std::vector<float>& depths,
                                         const std::vector<bool>& active, cv::Size image_size,
                                         const EnhancementParams& params) {
  if (!depths.empty() && depths.size() != points.size())
    throw std::invalid_argument("SelectEnhancedFeatures: one depth per point expected");
  if (!active.empty() && active.size() != points.size())
    throw std::invalid_argument("SelectEnhancedFeatures: one active flag per point expected");
  const double p = params.p_percent < 0 ? DefaultPPercent(image_size) : params.p_percent;
  const double q = params.q_percent < 0 ? kDefaultQPercent : params.q_percent;

  const std::vector<int> blocks = QuadtreeLeafBlocks(points, image_size, params.levels);
  int num_blocks = 1;
  for (int l = 0; l < params.levels; ++l) num_blocks *= 4;
  std::vector<std::vector<int>> members(static_cast<size_t>(num_blocks));
  for (size_t i = 0; i < points.size(); ++i)
    if (active.empty() || active[i])
      members[static_cast<size_t>(blocks[i])].push_back(static_cast<int>(i));

  std::vector<bool> kept(points.size(), false);
  for (const auto& block : members)
    for (int i : SelectInBlock(block, points, depths, params.keep_ratio, p, q))
      kept[static_cast<size_t>(i)] = true;
  return kept;
}

}  // namespace ademono
