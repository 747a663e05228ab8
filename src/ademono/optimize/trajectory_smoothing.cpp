#include "ademono/optimize/trajectory_smoothing.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace ademono {
namespace {

// A = I + lambda D2'D2 (symmetric pentadiagonal) as its LDL' factors: L unit lower with two
// sub-diagonals l1 (i, i-1) and l2 (i, i-2).
struct BandedLdl {
  std::vector<double> d, l1, l2;
};

BandedLdl Factor(size_t n, double lambda) {
  // The band of D2'D2: each row r of D2 is (1, -2, 1) at columns r, r+1, r+2.
  std::vector<double> a0(n, 1.0), a1(n, 0.0), a2(n, 0.0);
  for (size_t r = 0; r + 2 < n; ++r) {
    const double c[3] = {1.0, -2.0, 1.0};
    for (int j = 0; j < 3; ++j) {
      a0[r + j] += lambda * c[j] * c[j];
      if (j < 2) a1[r + j] += lambda * c[j] * c[j + 1];
    }
    a2[r] += lambda * c[0] * c[2];
  }
  BandedLdl f{std::vector<double>(n), std::vector<double>(n, 0.0), std::vector<double>(n, 0.0)};
  for (size_t i = 0; i < n; ++i) {
    if (i >= 2) f.l2[i] = a2[i - 2] / f.d[i - 2];
    if (i >= 1) {
      const double coupled = i >= 2 ? f.l2[i] * f.l1[i - 1] * f.d[i - 2] : 0.0;
      f.l1[i] = (a1[i - 1] - coupled) / f.d[i - 1];
    }
    f.d[i] = a0[i] - (i >= 1 ? f.l1[i] * f.l1[i] * f.d[i - 1] : 0.0) -
             (i >= 2 ? f.l2[i] * f.l2[i] * f.d[i - 2] : 0.0);
  }
  return f;
}

std::vector<double> Solve(const BandedLdl& f, const std::vector<double>& y) {
  const size_t n = y.size();
  std::vector<double> x(n);
  for (size_t i = 0; i < n; ++i) {
    x[i] = y[i] - (i >= 1 ? f.l1[i] * x[i - 1] : 0.0) - (i >= 2 ? f.l2[i] * x[i - 2] : 0.0);
  }
  for (size_t i = 0; i < n; ++i) x[i] /= f.d[i];
  for (size_t k = n; k-- > 0;) {
    if (k + 1 < n) x[k] -= f.l1[k + 1] * x[k + 1];
    if (k + 2 < n) x[k] -= f.l2[k + 2] * x[k + 2];
  }
  return x;
}

// trace(A^-1) from the factors: the band of Z = A^-1 by the backward recursion
// Z(i,j) = delta_ij / d_i - sum_{k>i} L(k,i) Z(k,j), which within the band only needs the band.
double InverseTrace(const BandedLdl& f) {
  const size_t n = f.d.size();
  std::vector<double> z0(n, 0.0), z1(n, 0.0), z2(n, 0.0);  // Z(i,i), Z(i,i+1), Z(i,i+2)
  double trace = 0.0;
  for (size_t i = n; i-- > 0;) {
    const double a = i + 1 < n ? f.l1[i + 1] : 0.0;  // L(i+1, i)
    const double b = i + 2 < n ? f.l2[i + 2] : 0.0;  // L(i+2, i)
    if (i + 2 < n) z2[i] = -(a * z1[i + 1] + b * z0[i + 2]);
    if (i + 1 < n) z1[i] = -(a * z0[i + 1] + b * z1[i + 1]);  // b = 0 when i + 2 == n
    z0[i] = 1.0 / f.d[i] - a * z1[i] - b * z2[i];
    trace += z0[i];
  }
  return trace;
}

}  // namespace

const std::vector<double>& SmoothingLambdas() {
  static const std::vector<double> lambdas = [] {
    std::vector<double> l;
    for (int k = -4; k <= 12; ++k) l.push_back(std::pow(10.0, k / 4.0));
    return l;
  }();
  return lambdas;
}

std::vector<double> SmoothSeries(const std::vector<double>& y, double lambda, double* hat_trace) {
  const BandedLdl f = Factor(y.size(), lambda);
  if (hat_trace != nullptr) *hat_trace = InverseTrace(f);
  return Solve(f, y);
}

SmoothedSeries SmoothSeriesGcv(const std::vector<double>& y) {
  SmoothedSeries best;
  best.values = y;
  const size_t n = y.size();
  if (n < kMinSmoothedSamples) return best;
  best.gcv = std::numeric_limits<double>::infinity();
  for (double lambda : SmoothingLambdas()) {
    double trace = 0.0;
    std::vector<double> x = SmoothSeries(y, lambda, &trace);
    double rss = 0.0;
    for (size_t i = 0; i < n; ++i) rss += (y[i] - x[i]) * (y[i] - x[i]);
    const double dof = static_cast<double>(n) - trace;
    const double gcv = static_cast<double>(n) * rss / (dof * dof);
    if (gcv < best.gcv) best = {std::move(x), lambda, gcv};
  }
  return best;
}

std::vector<Rigid3d> SmoothPoses(const std::vector<double>& timestamps,
                                 const std::vector<Rigid3d>& world_from_cam,
                                 PoseSmoothingReport* report) {
  std::vector<Rigid3d> out = world_from_cam;
  PoseSmoothingReport r;
  const size_t n = std::min(timestamps.size(), world_from_cam.size());
  if (n < kMinSmoothedSamples) {
    if (report != nullptr) *report = r;
    return out;
  }
  std::vector<double> steps;
  for (size_t i = 1; i < n; ++i) steps.push_back(timestamps[i] - timestamps[i - 1]);
  std::vector<double> sorted = steps;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const double max_step = 1.5 * sorted[sorted.size() / 2];
  double sum_sq = 0.0;
  size_t begin = 0;
  for (size_t i = 1; i <= n; ++i) {
    if (i < n && steps[i - 1] <= max_step) continue;
    const size_t end = i;  // the segment [begin, end)
    const size_t m = end - begin;
    if (m >= kMinSmoothedSamples) {
      ++r.segments;
      // Rotation as an integrated body-frame angle: u_k = u_{k-1} + log(R_{k-1}' R_k). A
      // correction delta_k = u'_k - u_k is applied as R_k exp(delta_k); to first order the
      // smoothed increments are then u'_k - u'_{k-1}.
      std::vector<std::vector<double>> series(6, std::vector<double>(m));
      Eigen::Vector3d u = Eigen::Vector3d::Zero();
      for (size_t k = 0; k < m; ++k) {
        const Rigid3d& pose = world_from_cam[begin + k];
        if (k > 0) {
          const Rigid3d& previous = world_from_cam[begin + k - 1];
          u += LogSO3(previous.linear().transpose() * pose.linear());
        }
        for (int c = 0; c < 3; ++c) {
          series[c][k] = pose.translation()[c];
          series[3 + c][k] = u[c];
        }
      }
      std::vector<std::vector<double>> smoothed(6);
      for (int c = 0; c < 6; ++c) smoothed[c] = SmoothSeriesGcv(series[c]).values;
      for (size_t k = 0; k < m; ++k) {
        Rigid3d& pose = out[begin + k];
        const Eigen::Vector3d centre(smoothed[0][k], smoothed[1][k], smoothed[2][k]);
        const Eigen::Vector3d delta(smoothed[3][k] - series[3][k], smoothed[4][k] - series[4][k],
                                    smoothed[5][k] - series[5][k]);
        const double shift = (centre - pose.translation()).norm();
        r.max_shift_m = std::max(r.max_shift_m, shift);
        sum_sq += shift * shift;
        pose.linear() = pose.linear() * ExpSO3(delta);
        pose.translation() = centre;
      }
    }
    begin = end;
  }
  r.rms_shift_m = std::sqrt(sum_sq / static_cast<double>(n));
  if (report != nullptr) *report = r;
  return out;
}

}  // namespace ademono
