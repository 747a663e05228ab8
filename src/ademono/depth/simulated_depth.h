#pragma once
// A SIMULATION of a monocular depth network, not a network: it degrades ground-truth depth (the
// dataset's own depth in FrameData, or a cache folder given as gt=DIR) with the error patterns
// learned metric depth shows, so the SLAM pipeline can be tested against known truth:
//   z_out = scale * (z_edge + sigma(z) * n),   sigma(z) = a * z + b * z^2
// - scale: global scale bias (a network's metric scale is never exact);
// - n: unit-variance noise; a fraction `pixel` (default 10 %) of the variance is per-pixel noise,
//   the rest a smooth low-frequency field (networks output smooth maps whose errors are
//   correlated over tens of pixels);
// - z_edge: ground truth with depth edges smeared: within `edge_blur` pixels of a depth
//   discontinuity (local max/min > 1.1) the depth is the local mean of valid depths;
// - jitter: a network's scale also wanders from frame to frame with the scene's content. With
//   jitter > 0 the scale of frame k is scale * exp(jitter * J(k)), J a smooth zero-mean,
//   unit-variance signal (a sum of 8 cosines with periods around `jitter_frames` frames and
//   phases from the seed), the same for every pixel of the frame;
// - shift: networks also compress or stretch the depth range, a shift in inverse depth:
//   1 / z_out = 1 / z_scaled + shift_k (m^-1), shift_k = shift + shift_jitter * J'(k), J' a second
//   smooth signal like J. With the scale this is a per-frame affine map in inverse depth;
// - a fraction `invalid` of the pixels, in blobs (the top of another smooth field, ~12 px
//   correlation), and every pixel without ground truth is 0.
// Deterministic per frame: the noise is drawn from (seed, frame index) only.
//
// Spec: simulated[:scale=1.05,a=0.01,b=0.001,pixel=0.1,edge_blur=3,invalid=0.02,jitter=0,
//                 jitter_frames=60,shift=0,shift_jitter=0,seed=S,gt=DIR]
// (every key optional; seed defaults to the run's seed).

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "ademono/depth/depth_factory.h"
#include "ademono/perception/depth_provider.h"

namespace ademono {

struct SimulatedDepthOptions {
  double scale = 1.05;
  double a = 0.01;     // relative noise (sigma grows linearly with depth)
  double b = 0.001;    // 1/m: quadratic growth, dominating far away
  double pixel = 0.1;  // share of the noise variance that is per-pixel (the rest is smooth)
  int edge_blur = 3;   // pixels; 0 keeps edges sharp
  double invalid = 0.02;
  double jitter = 0.0;          // log-scale standard deviation of the per-frame scale
  double jitter_frames = 60.0;  // typical period of the scale's wandering, in frames
  double shift = 0.0;           // m^-1: inverse-depth shift (1 / z_out = 1 / z_scaled + shift_k)
  double shift_jitter = 0.0;    // m^-1: standard deviation of its per-frame wandering
  uint64_t seed = 0;
  std::optional<std::filesystem::path> gt_dir;  // ground truth from a depth cache folder

  // Throws std::invalid_argument naming the first bad field.
  void Check() const;
  // Parses "k=v,k=v" (empty: defaults). InputError for unknown keys or bad values.
  static SimulatedDepthOptions Parse(const std::string& argument, uint64_t default_seed);
};

class SimulatedDepthProvider : public DepthProvider {
 public:
  // `ground_truth`: where true depth comes from; null uses FrameData::depth.
  SimulatedDepthProvider(const SimulatedDepthOptions& options,
                         std::unique_ptr<DepthProvider> ground_truth);
  std::string Name() const override { return "simulated"; }
  // InputError naming the frame when it has no ground-truth depth or it has the wrong size.
  cv::Mat Depth(const FrameData& frame, const Camera& camera) override;
  bool ReadsSequenceDepth() const override { return ground_truth_ == nullptr; }
  // The degradation alone, for a given ground truth (CV_32FC1 metres) and frame index.
  cv::Mat Degrade(const cv::Mat& depth_m, size_t frame_index) const;
  // The scale bias of frame `frame_index` (scale, times the jitter when it is on).
  double FrameScale(size_t frame_index) const;
  // The inverse-depth shift of frame `frame_index` (m^-1). With FrameScale s and shift c the
  // frame's depths (before noise) map back to the truth as 1 / z = s / z_out - s c: an affine map
  // in inverse depth with a = s, b = -s c.
  double FrameShift(size_t frame_index) const;

 private:
  SimulatedDepthOptions options_;
  std::unique_ptr<DepthProvider> ground_truth_;
};

// The `simulated` branch of MakeDepthProvider: `argument` is what follows "simulated:".
std::unique_ptr<DepthProvider> MakeSimulatedDepthProvider(const std::string& argument,
                                                          const DepthFactoryContext& context);

}  // namespace ademono
