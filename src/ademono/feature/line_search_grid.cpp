#include "ademono/feature/line_search_grid.h"

#include <algorithm>
#include <cmath>

namespace ademono {

LineSearchGrid::LineSearchGrid(const std::vector<cv::KeyPoint>& keypoints,
                               const std::vector<size_t>& indices) {
  if (indices.empty()) return;
  double max_x = -INFINITY, max_y = -INFINITY;
  min_x_ = INFINITY;
  min_y_ = INFINITY;
  for (size_t i : indices) {
    const cv::Point2f& p = keypoints[i].pt;
    min_x_ = std::min(min_x_, static_cast<double>(p.x));
    min_y_ = std::min(min_y_, static_cast<double>(p.y));
    max_x = std::max(max_x, static_cast<double>(p.x));
    max_y = std::max(max_y, static_cast<double>(p.y));
  }
  // About two keypoints a cell: finer cells cost more visits, coarser ones more tests. At most
  // kMaxCells a side (a far outlier keypoint), and one cell when the bounds are not finite.
  constexpr double kMaxCells = 1024;
  const double width = max_x - min_x_, height = max_y - min_y_;
  if (!std::isfinite(width) || !std::isfinite(height)) {
    cols_ = rows_ = 1;
    offsets_ = {0, indices.size()};
    indices_ = indices;
    return;
  }
  const double area = std::max(1.0, width * height);
  cell_ = std::max({4.0, std::sqrt(2.0 * area / static_cast<double>(indices.size())),
                    width / kMaxCells, height / kMaxCells});
  cols_ = static_cast<int>(std::floor(width / cell_)) + 1;
  rows_ = static_cast<int>(std::floor(height / cell_)) + 1;
  std::vector<size_t> cell_of(indices.size());
  offsets_.assign(static_cast<size_t>(cols_) * static_cast<size_t>(rows_) + 1, 0);
  for (size_t k = 0; k < indices.size(); ++k) {
    const cv::Point2f& p = keypoints[indices[k]].pt;
    const int cx = std::min(cols_ - 1, static_cast<int>((p.x - min_x_) / cell_));
    const int cy = std::min(rows_ - 1, static_cast<int>((p.y - min_y_) / cell_));
    cell_of[k] = static_cast<size_t>(cy) * static_cast<size_t>(cols_) + static_cast<size_t>(cx);
    ++offsets_[cell_of[k] + 1];
  }
  for (size_t c = 1; c < offsets_.size(); ++c) offsets_[c] += offsets_[c - 1];
  indices_.resize(indices.size());
  std::vector<size_t> fill(offsets_.begin(), offsets_.end() - 1);
  for (size_t k = 0; k < indices.size(); ++k) indices_[fill[cell_of[k]]++] = indices[k];
}

void LineSearchGrid::Near(const Eigen::Vector3d& line, double radius,
                          std::vector<size_t>* out) const {
  out->clear();
  if (indices_.empty()) return;
  const double a = line.x(), b = line.y(), c = line.z();
  const double norm = std::hypot(a, b);
  if (!(norm > 0) || !std::isfinite(norm) || !std::isfinite(c)) return;
  if (cols_ == 1 && rows_ == 1) {  // one cell: every keypoint is a candidate
    *out = indices_;
    return;
  }
  // Walk the strips across the line's main direction; in each, the band spans the line's
  // extent over the strip plus the radius measured along the strip (radius * norm / |the
  // larger coefficient|). A pixel of slack covers rounding.
  const bool across_columns = std::abs(b) >= std::abs(a);
  const double along = across_columns ? b : a, other = across_columns ? a : b;
  const double half_width = (radius + 1.0) * norm / std::abs(along);
  const int strips = across_columns ? cols_ : rows_;
  const int span = across_columns ? rows_ : cols_;
  const double strip_origin = across_columns ? min_x_ : min_y_;
  const double span_origin = across_columns ? min_y_ : min_x_;
  const size_t strip_step = across_columns ? 1 : static_cast<size_t>(cols_);
  const size_t span_step = across_columns ? static_cast<size_t>(cols_) : 1;
  // The line: span coordinate = slope * strip coordinate + intercept.
  const double slope = -other / along, intercept = -c / along;
  for (int s = 0; s < strips; ++s) {
    const double s0 = strip_origin + s * cell_;
    const double e0 = slope * s0 + intercept, e1 = e0 + slope * cell_;
    const double lo = (std::min(e0, e1) - half_width - span_origin) / cell_;
    const double hi = (std::max(e0, e1) + half_width - span_origin) / cell_;
    if (!(hi >= 0) || !(lo < span)) continue;
    const size_t first = static_cast<size_t>(std::max(0.0, lo));
    const size_t last = static_cast<size_t>(std::min(static_cast<double>(span - 1), hi));
    if (span_step == 1) {  // the cells lie side by side in a row: one range
      const size_t row = static_cast<size_t>(s) * strip_step;
      out->insert(out->end(), indices_.begin() + static_cast<long>(offsets_[row + first]),
                  indices_.begin() + static_cast<long>(offsets_[row + last + 1]));
      continue;
    }
    for (size_t k = first; k <= last; ++k) {
      const size_t cell = static_cast<size_t>(s) + k * span_step;
      out->insert(out->end(), indices_.begin() + static_cast<long>(offsets_[cell]),
                  indices_.begin() + static_cast<long>(offsets_[cell + 1]));
    }
  }
}

}  // namespace ademono
