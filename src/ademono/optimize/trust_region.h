#pragma once
// Ceres' Levenberg-Marquardt rules with its Solver::Options defaults, for the built-in solvers
// that replay Ceres' iteration without its per-problem machinery (the pose optimiser's 6x6 LM,
// the bundle adjustment's Schur LM): the same constants, the same radius updates.
#include <algorithm>
#include <cmath>

namespace ademono::internal {

inline constexpr double kLmMinDiagonal = 1e-6;  // the LM diagonal's clamp, in scaled units
inline constexpr double kLmMaxDiagonal = 1e32;
inline constexpr double kLmMinRelativeDecrease = 1e-3;  // a step's quality to be taken
inline constexpr double kLmFunctionTolerance = 1e-6;
inline constexpr double kLmParameterTolerance = 1e-8;
inline constexpr double kLmGradientTolerance = 1e-10;

// Huber as Ceres' HuberLoss(a) on s = |r|^2: rho = s (s <= a^2) else 2 a sqrt(s) - a^2. Returns
// rho and sets rho' (Ceres' corrector scales J and r by sqrt(rho') since rho'' <= 0 here).
inline double HuberRho(double s, double a2, double* rho1) {
  if (s <= a2) {
    *rho1 = 1.0;
    return s;
  }
  const double root = std::sqrt(s);
  const double a = std::sqrt(a2);
  *rho1 = a / root;
  return 2.0 * a * root - a2;
}

// The trust region's radius: 1e4 at the start; a taken step of quality q divides it by
// max(1/3, 1 - (2q - 1)^3) (at most 1e16), a refused one by a factor that doubles each time.
class LmTrustRegion {
 public:
  double Radius() const { return radius_; }
  void Accepted(double quality) {
    const double t = 2.0 * quality - 1.0;
    radius_ = std::min(1e16, radius_ / std::max(1.0 / 3.0, 1.0 - t * t * t));
    decrease_factor_ = 2.0;
  }
  void Rejected() {
    radius_ /= decrease_factor_;
    decrease_factor_ *= 2.0;
  }
  bool Collapsed() const { return radius_ < 1e-32; }  // Ceres' min_trust_region_radius

 private:
  double radius_ = 1e4;
  double decrease_factor_ = 2.0;
};

}  // namespace ademono::internal
