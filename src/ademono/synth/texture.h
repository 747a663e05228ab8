#pragma once
// Procedural surface textures for the synthetic scenes. Each surface gets its own texture
// generated from its own seed (no repeated tiles that could alias in feature matching): several
// octaves of value noise plus random blobs, lines, rectangles and text-like marks, and per style
// structure (windows on facades, lane markings on roads). Textures are grey, tinted by a colour,
// and kept as a mip pyramid so distant surfaces are sampled without aliasing.

#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

namespace ademono::synth {

enum class TextureStyle {
  kPlaster,   // office walls and ceiling: light, posters and marks
  kFloor,     // office floor: wood-like streaks
  kWood,      // furniture
  kCloth,     // clothes of persons and mannequins
  kSkin,      // heads and hands: smooth with a few features
  kRoad,      // asphalt with lane markings along the texture's long axis (u)
  kSidewalk,  // paving slabs
  kFacade,    // building fronts with windows
  kCarPaint,  // car bodies: smooth with panel lines and stickers
  kDark,      // tyres, window glass: dark, low contrast
};

struct TextureSpec {
  TextureStyle style = TextureStyle::kPlaster;
  double width_m = 1.0;   // extent along u
  double height_m = 1.0;  // extent along v
  double texel_m = 0.005;
  uint64_t seed = 0;
  cv::Vec3f tint{1.f, 1.f, 1.f};  // BGR multiplier of the grey texture
};

class Texture {
 public:
  // Deterministic for a spec. The texel size grows if the texture would exceed 4096 texels.
  static Texture Generate(const TextureSpec& spec);

  // BGR colour (0..255) at surface coordinates (u, v) in metres from the texture origin, for a
  // pixel footprint of `footprint_m` metres on the surface (chooses the mip level). Coordinates
  // outside the texture are clamped to its edge.
  cv::Vec3f Sample(double u_m, double v_m, double footprint_m) const;

  double texel_m() const { return texel_m_; }
  const cv::Mat& level(int i) const { return levels_[i]; }
  int num_levels() const { return static_cast<int>(levels_.size()); }

 private:
  std::vector<cv::Mat> levels_;  // CV_8UC1, level 0 full resolution
  double texel_m_ = 0.005;
  cv::Vec3f tint_{1.f, 1.f, 1.f};
};

}  // namespace ademono::synth
