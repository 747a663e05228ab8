#pragma once
// Photo sprites: a cut-out of a real photograph (colour plus an alpha mask) on a planar quad,
// carried by an actor. The renderer treats a Box with `sprite >= 0` as the quad through the box
// centre spanning its x (u, metres from the -x edge) and z (v, metres down from the +z edge)
// axes; a ray hits it only where the alpha mask is opaque, so masks, boxes and depth stay exact.

#include <opencv2/core.hpp>
#include <vector>

namespace ademono::synth {

class Sprite {
 public:
  // `bgr` CV_8UC3 and `alpha` CV_8UC1 (>= 128 opaque) of the same size; the quad is `height_m`
  // tall and as wide as the image's aspect ratio gives. Throws std::invalid_argument otherwise.
  static Sprite FromCutout(const cv::Mat& bgr, const cv::Mat& alpha, double height_m);

  // Opaque at quad coordinates (u, v) in metres? Nearest texel of the full-resolution mask, so
  // the silhouette does not depend on the distance.
  bool Opaque(double u_m, double v_m) const;
  // BGR colour (0..255) at (u, v) for a pixel footprint of `footprint_m` metres (mip level as in
  // Texture::Sample, bilinear within the level).
  cv::Vec3f Sample(double u_m, double v_m, double footprint_m) const;

  double width_m() const { return width_m_; }
  double height_m() const { return height_m_; }
  const cv::Mat& alpha() const { return alpha_; }
  const cv::Mat& level(int i) const { return levels_[i]; }

 private:
  std::vector<cv::Mat> levels_;  // CV_8UC3, level 0 full resolution
  cv::Mat alpha_;                // CV_8UC1, level 0
  double texel_m_ = 0.01;
  double width_m_ = 0.0, height_m_ = 0.0;
};

}  // namespace ademono::synth
