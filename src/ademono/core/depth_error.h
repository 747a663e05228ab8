#pragma once
// Error model of a depth source: the standard deviation of a depth reading z (metres) is
//   sigma(z) = z * (relative + per_metre * z)
// i.e. a relative error that grows linearly with depth. A learned network's depth is a prior with
// such an error model, not a measurement; a model of all zeros means "no model": the depth is
// weighted as ORB-SLAM2's virtual stereo measurement (the pixel sigma of the keypoint's level).

namespace ademono {

struct DepthErrorModel {
  double relative = 0.0;   // sigma / z at z -> 0
  double per_metre = 0.0;  // 1/m: growth of sigma / z with depth

  bool Enabled() const { return relative > 0.0 || per_metre > 0.0; }
  double RelativeSigma(double z) const { return relative + per_metre * z; }
  double Sigma(double z) const { return z * RelativeSigma(z); }
  bool operator==(const DepthErrorModel&) const = default;
};

}  // namespace ademono
