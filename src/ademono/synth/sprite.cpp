#include "ademono/synth/sprite.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace ademono::synth {

Sprite Sprite::FromCutout(const cv::Mat& bgr, const cv::Mat& alpha, double height_m) {
  if (bgr.empty() || bgr.type() != CV_8UC3 || alpha.type() != CV_8UC1 ||
      alpha.size() != bgr.size())
    throw std::invalid_argument("sprite needs a BGR image and an alpha mask of the same size");
  if (!(height_m > 0.0)) throw std::invalid_argument("sprite height must be positive");
  Sprite sprite;
  sprite.alpha_ = alpha.clone();
  sprite.levels_.push_back(bgr.clone());
  // Down to a few texels: distant sprites are averaged, not aliased.
  while (std::min(sprite.levels_.back().cols, sprite.levels_.back().rows) > 4) {
    cv::Mat next;
    cv::pyrDown(sprite.levels_.back(), next);
    sprite.levels_.push_back(next);
  }
  sprite.height_m_ = height_m;
  sprite.texel_m_ = height_m / bgr.rows;
  sprite.width_m_ = sprite.texel_m_ * bgr.cols;
  return sprite;
}

bool Sprite::Opaque(double u_m, double v_m) const {
  const int x = static_cast<int>(std::floor(u_m / texel_m_));
  const int y = static_cast<int>(std::floor(v_m / texel_m_));
  if (x < 0 || y < 0 || x >= alpha_.cols || y >= alpha_.rows) return false;
  return alpha_.at<uint8_t>(y, x) >= 128;
}

cv::Vec3f Sprite::Sample(double u_m, double v_m, double footprint_m) const {
  int level = 0;
  const double ratio = footprint_m / texel_m_;
  if (ratio > 1.41421356)
    level = std::clamp(std::ilogb(ratio * 0.70710678), 0, static_cast<int>(levels_.size()) - 1);
  const cv::Mat& image = levels_[level];
  // pyrDown halves sizes rounding up: the level's texel is the full image over its size.
  const double sx = image.cols / width_m_, sy = image.rows / height_m_;
  const double x = std::clamp(u_m * sx - 0.5, 0.0, image.cols - 1.000001);
  const double y = std::clamp(v_m * sy - 0.5, 0.0, image.rows - 1.000001);
  const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
  const int x1 = std::min(x0 + 1, image.cols - 1), y1 = std::min(y0 + 1, image.rows - 1);
  const float fx = static_cast<float>(x - x0), fy = static_cast<float>(y - y0);
  const cv::Vec3b* row0 = image.ptr<cv::Vec3b>(y0);
  const cv::Vec3b* row1 = image.ptr<cv::Vec3b>(y1);
  cv::Vec3f out;
  for (int c = 0; c < 3; ++c) {
    const float top = row0[x0][c] + fx * (row0[x1][c] - row0[x0][c]);
    const float bottom = row1[x0][c] + fx * (row1[x1][c] - row1[x0][c]);
    out[c] = top + fy * (bottom - top);
  }
  return out;
}

}  // namespace ademono::synth
