#include "ademono/synth/texture.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <string>

#include "ademono/synth/random.h"

namespace ademono::synth {

namespace {

constexpr int kMaxTextureSide = 4096;

// How a style looks; shape densities are per 100 x 100 texels and sizes in texels, because
// texel sizes are chosen per surface to match the distance it is seen from.
struct StyleParams {
  float base = 150.f;  // mean grey
  float noise_amplitude = 30.f;
  float fine_noise = 8.f;  // per-texel grain
  float blobs = 2.f;
  float lines = 1.f;
  float text = 1.f;
  float rectangles = 0.1f;
  float contrast = 90.f;  // grey spread of marks around the base
  float streak = 0.f;     // anisotropic streaks along u (wood, floor)
};

StyleParams ParamsFor(TextureStyle style) {
  StyleParams p;
  switch (style) {
    case TextureStyle::kPlaster:
      p = {175.f, 25.f, 6.f, 2.0f, 0.8f, 1.2f, 0.08f, 110.f, 0.f};
      break;
    case TextureStyle::kFloor:
      p = {120.f, 30.f, 8.f, 1.5f, 1.0f, 0.3f, 0.05f, 80.f, 40.f};
      break;
    case TextureStyle::kWood:
      p = {110.f, 30.f, 8.f, 1.5f, 1.0f, 0.8f, 0.05f, 80.f, 35.f};
      break;
    case TextureStyle::kCloth:
      p = {120.f, 35.f, 10.f, 3.0f, 2.0f, 0.8f, 0.10f, 100.f, 0.f};
      break;
    case TextureStyle::kSkin:
      p = {165.f, 15.f, 4.f, 1.5f, 0.3f, 0.f, 0.f, 60.f, 0.f};
      break;
    case TextureStyle::kRoad:
      p = {85.f, 18.f, 14.f, 2.5f, 0.6f, 0.f, 0.02f, 50.f, 0.f};
      break;
    case TextureStyle::kSidewalk:
      p = {140.f, 20.f, 10.f, 2.0f, 0.5f, 0.1f, 0.f, 60.f, 0.f};
      break;
    case TextureStyle::kFacade:
      p = {150.f, 30.f, 6.f, 1.5f, 0.6f, 0.6f, 0.05f, 90.f, 0.f};
      break;
    case TextureStyle::kCarPaint:
      p = {140.f, 12.f, 3.f, 1.0f, 0.8f, 0.5f, 0.05f, 90.f, 0.f};
      break;
    case TextureStyle::kDark:
      p = {45.f, 10.f, 5.f, 1.0f, 0.3f, 0.f, 0.f, 30.f, 0.f};
      break;
  }
  return p;
}

// Sum of value-noise octaves from 256 down to 4 texels, amplitudes falling slowly so every
// scale has structure.
void AddOctaveNoise(cv::Mat& image, float amplitude, float streak, cv::RNG& rng) {
  const cv::Size size = image.size();
  float octave_amplitude = amplitude;
  for (int cell = 256; cell >= 4; cell /= 2) {
    const int cols = std::max(2, size.width / cell + 2);
    // Streaks: coarser along u than along v.
    const int rows = std::max(2, size.height / std::max(1, streak > 0 ? cell / 4 : cell) + 2);
    cv::Mat coarse(rows, cols, CV_32F);
    rng.fill(coarse, cv::RNG::UNIFORM, -1.f, 1.f);
    cv::Mat up;
    cv::resize(coarse, up, size, 0, 0, cv::INTER_CUBIC);
    image += up * octave_amplitude;
    octave_amplitude *= 0.7f;
  }
  if (streak > 0) {
    cv::Mat lines(size.height, 1, CV_32F);
    rng.fill(lines, cv::RNG::UNIFORM, -streak, streak);
    cv::Mat wide;
    cv::repeat(lines, 1, size.width, wide);
    image += wide;
  }
}

std::string RandomMark(Rng& rng) {
  static const char kChars[] = "ABCDEFGHKLMNPRSTUVWXYZ0123456789#%&@+";
  std::string s;
  const int n = rng.UniformInt(2, 6);
  for (int i = 0; i < n; ++i) s.push_back(kChars[rng.UniformInt(0, sizeof(kChars) - 2)]);
  return s;
}

double Grey(const StyleParams& p, Rng& rng) {
  return std::clamp(p.base + rng.Uniform(-1.0, 1.0) * p.contrast, 0.0, 255.0);
}

void DrawMarks(cv::Mat& image, const StyleParams& p, Rng& rng) {
  const double area = image.rows * static_cast<double>(image.cols) / 1e4;
  const int w = image.cols, h = image.rows;
  auto count = [&](float density) {
    return static_cast<int>(std::floor(density * area + rng.Uniform()));
  };
  const int rectangles = count(p.rectangles);
  for (int i = 0; i < rectangles; ++i) {
    const int rw = rng.UniformInt(20, 120), rh = rng.UniformInt(20, 120);
    const cv::Point tl(rng.UniformInt(-rw / 2, w), rng.UniformInt(-rh / 2, h));
    cv::rectangle(image, cv::Rect(tl, cv::Size(rw, rh)), cv::Scalar(Grey(p, rng)), cv::FILLED);
    cv::rectangle(image, cv::Rect(tl, cv::Size(rw, rh)), cv::Scalar(Grey(p, rng)),
                  rng.UniformInt(1, 3));
  }
  const int blobs = count(p.blobs);
  for (int i = 0; i < blobs; ++i) {
    const cv::Point c(rng.UniformInt(0, w - 1), rng.UniformInt(0, h - 1));
    const cv::Size axes(rng.UniformInt(2, 14), rng.UniformInt(2, 14));
    cv::ellipse(image, c, axes, rng.Uniform(0, 180), 0, 360, cv::Scalar(Grey(p, rng)), cv::FILLED,
                cv::LINE_AA);
  }
  const int lines = count(p.lines);
  for (int i = 0; i < lines; ++i) {
    const cv::Point a(rng.UniformInt(0, w - 1), rng.UniformInt(0, h - 1));
    const double angle = rng.Uniform(0, 2 * CV_PI), length = rng.Uniform(8, 60);
    const cv::Point b(a.x + static_cast<int>(length * std::cos(angle)),
                      a.y + static_cast<int>(length * std::sin(angle)));
    cv::line(image, a, b, cv::Scalar(Grey(p, rng)), rng.UniformInt(1, 3), cv::LINE_AA);
  }
  const int texts = count(p.text);
  for (int i = 0; i < texts; ++i) {
    const cv::Point at(rng.UniformInt(-20, w - 1), rng.UniformInt(0, h + 10));
    const int font = rng.UniformInt(0, 1) ? cv::FONT_HERSHEY_SIMPLEX : cv::FONT_HERSHEY_DUPLEX;
    cv::putText(image, RandomMark(rng), at, font, rng.Uniform(0.3, 0.9), cv::Scalar(Grey(p, rng)),
                rng.UniformInt(1, 2), cv::LINE_AA);
  }
}

// Windows in floors and bays, each with its own brightness and frame, some with blinds.
void DrawWindows(cv::Mat& image, double texel_m, Rng& rng) {
  const double floor_h = rng.Uniform(2.8, 3.6) / texel_m;
  const double bay_w = rng.Uniform(2.0, 3.5) / texel_m;
  const double win_w = bay_w * rng.Uniform(0.45, 0.7), win_h = floor_h * rng.Uniform(0.45, 0.6);
  const int frame = std::max(1, static_cast<int>(0.08 / texel_m));
  for (double y = floor_h * 0.3; y + win_h < image.rows; y += floor_h) {
    for (double x = bay_w * 0.25; x + win_w < image.cols; x += bay_w) {
      const cv::Rect r(static_cast<int>(x), static_cast<int>(y), static_cast<int>(win_w),
                       static_cast<int>(win_h));
      cv::rectangle(image, r, cv::Scalar(rng.Uniform(20, 120)), cv::FILLED);
      if (rng.Uniform() < 0.4) {  // half-drawn blind
        cv::Rect blind = r;
        blind.height = static_cast<int>(r.height * rng.Uniform(0.2, 0.9));
        cv::rectangle(image, blind, cv::Scalar(rng.Uniform(150, 230)), cv::FILLED);
      }
      cv::rectangle(image, r, cv::Scalar(rng.Uniform(180, 250)), frame);
    }
  }
}

// Lane markings: dashed centre line, solid edge lines, along u; v spans the road width.
void DrawLaneMarkings(cv::Mat& image, double texel_m, Rng& rng) {
  const int width = std::max(1, static_cast<int>(0.15 / texel_m));
  const double dash = 3.0 / texel_m, gap = 6.0 / texel_m;
  const int centre = image.rows / 2;
  for (double x = -rng.Uniform(0, dash + gap); x < image.cols; x += dash + gap) {
    cv::rectangle(image,
                  cv::Rect(static_cast<int>(x), centre - width / 2, static_cast<int>(dash), width),
                  cv::Scalar(rng.Uniform(200, 235)), cv::FILLED);
  }
  const int edge = static_cast<int>(0.5 / texel_m);
  for (int v : {edge, image.rows - 1 - edge}) {
    cv::rectangle(image, cv::Rect(0, v - width / 2, image.cols, width),
                  cv::Scalar(rng.Uniform(190, 230)), cv::FILLED);
  }
}

// Paving: joints every ~0.6 m.
void DrawSlabs(cv::Mat& image, double texel_m, Rng& rng) {
  const double slab = rng.Uniform(0.5, 0.8) / texel_m;
  for (double x = rng.Uniform(0, slab); x < image.cols; x += slab)
    cv::line(image, cv::Point(static_cast<int>(x), 0), cv::Point(static_cast<int>(x), image.rows),
             cv::Scalar(rng.Uniform(70, 100)), 1);
  for (double y = rng.Uniform(0, slab); y < image.rows; y += slab)
    cv::line(image, cv::Point(0, static_cast<int>(y)), cv::Point(image.cols, static_cast<int>(y)),
             cv::Scalar(rng.Uniform(70, 100)), 1);
}

}  // namespace

Texture Texture::Generate(const TextureSpec& spec) {
  Texture texture;
  texture.tint_ = spec.tint;
  double texel = spec.texel_m;
  const double longest = std::max(spec.width_m, spec.height_m);
  if (longest / texel > kMaxTextureSide) texel = longest / kMaxTextureSide;
  texture.texel_m_ = texel;
  const int cols = std::max(8, static_cast<int>(std::ceil(spec.width_m / texel)) + 1);
  const int rows = std::max(8, static_cast<int>(std::ceil(spec.height_m / texel)) + 1);

  const StyleParams params = ParamsFor(spec.style);
  cv::RNG cv_rng(Mix64(spec.seed) | 1);  // cv::RNG::fill is deterministic for a state
  Rng rng(SubSeed(spec.seed, 1));
  cv::Mat grey(rows, cols, CV_32F, cv::Scalar(params.base));
  AddOctaveNoise(grey, params.noise_amplitude, params.streak, cv_rng);
  cv::Mat fine(rows, cols, CV_32F);
  cv_rng.fill(fine, cv::RNG::NORMAL, 0.f, params.fine_noise);
  grey += fine;

  cv::Mat image;
  grey.convertTo(image, CV_8U);  // saturates to 0..255
  if (spec.style == TextureStyle::kFacade) DrawWindows(image, texel, rng);
  if (spec.style == TextureStyle::kSidewalk) DrawSlabs(image, texel, rng);
  DrawMarks(image, params, rng);
  if (spec.style == TextureStyle::kRoad) DrawLaneMarkings(image, texel, rng);

  texture.levels_.push_back(image);
  while (texture.levels_.back().rows >= 8 && texture.levels_.back().cols >= 8) {
    cv::Mat down;
    cv::pyrDown(texture.levels_.back(), down);
    texture.levels_.push_back(down);
  }
  return texture;
}

cv::Vec3f Texture::Sample(double u_m, double v_m, double footprint_m) const {
  // Level whose texel is about the pixel footprint (rounded so texels are at most ~1.4 px).
  int level = 0;
  const double ratio = footprint_m / texel_m_;
  // Just above sqrt(2) texels ilogb(ratio / sqrt(2)) can round to -1: clamp both ends.
  if (ratio > 1.41421356)
    level = std::clamp(std::ilogb(ratio * 0.70710678), 0, num_levels() - 1);
  const cv::Mat& image = levels_[level];
  const double scale = 1.0 / std::ldexp(texel_m_, level);
  // Texel centres at (i + 0.5) texels; pyrDown halves sizes rounding up, so this stays aligned.
  const double x = std::clamp(u_m * scale - 0.5, 0.0, image.cols - 1.000001);
  const double y = std::clamp(v_m * scale - 0.5, 0.0, image.rows - 1.000001);
  const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
  const float fx = static_cast<float>(x - x0), fy = static_cast<float>(y - y0);
  const uint8_t* row0 = image.ptr<uint8_t>(y0);
  const uint8_t* row1 = image.ptr<uint8_t>(std::min(y0 + 1, image.rows - 1));
  const int x1 = std::min(x0 + 1, image.cols - 1);
  const float top = row0[x0] + fx * (row0[x1] - row0[x0]);
  const float bottom = row1[x0] + fx * (row1[x1] - row1[x0]);
  const float grey = top + fy * (bottom - top);
  return cv::Vec3f(grey * tint_[0], grey * tint_[1], grey * tint_[2]);
}

}  // namespace ademono::synth
