#include "ademono/initializer/two_view.h"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <Eigen/SVD>
#include <algorithm>
#include <array>
#include <cmath>
#include <future>
#include <optional>
#include <random>
#include <stdexcept>

#include "ademono/core/options_table.h"
#include "ademono/optimize/triangulation.h"

namespace ademono {

const OptionsTable<TwoViewOptions>& TwoViewOptions::Table() {
  using T = TwoViewOptions;
  static const auto table =
      OptionsTable<T>("initializer")
          .Add("ransac_iterations", &T::ransac_iterations, Range::AtLeast(1))
          .Add("sigma_px", &T::sigma_px, Range::Above(0))
          .Add("homography_ratio", &T::homography_ratio, Range::Closed(0, 1))
          .Add("min_parallax_deg", &T::min_parallax_deg, Range::AtLeast(0))
          .Add("min_triangulated", &T::min_triangulated, Range::AtLeast(8))
          .Add("min_triangulated_ratio", &T::min_triangulated_ratio, Range::Closed(0, 1))
          .Add("max_direction_sigma_deg", &T::max_direction_sigma_deg, Range::Above(0))
          .Add("seed", &T::seed)
          .Add("parallel", &T::parallel);
  return table;
}

void TwoViewOptions::Check() const { Table().CheckRanges(*this); }

const char* TwoViewModelName(TwoViewModel model) {
  switch (model) {
    case TwoViewModel::kNone:
      return "none";
    case TwoViewModel::kHomography:
      return "homography";
    case TwoViewModel::kFundamental:
      return "fundamental";
  }
  throw std::logic_error("TwoViewModelName: unknown model");
}

namespace {

constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;
// chi2 at 95 %: 1 dof (a point's distance to an epipolar line), 2 dof (a transfer error).
constexpr double kChi2OneDof = 3.841;
constexpr double kChi2TwoDof = 5.991;
// Rays closer than this cosine are parallel: no depth from them (ORB-SLAM's 0.99998, 0.36 deg).
constexpr double kParallelCos = 0.99998;

// Hartley normalisation: centroid at the origin, mean absolute deviation 1 per axis.
Eigen::Matrix3d Normalize(const std::vector<Eigen::Vector2d>& points,
                          std::vector<Eigen::Vector2d>* normalized) {
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const auto& p : points) mean += p;
  mean /= static_cast<double>(points.size());
  Eigen::Vector2d deviation = Eigen::Vector2d::Zero();
  for (const auto& p : points) deviation += (p - mean).cwiseAbs();
  deviation /= static_cast<double>(points.size());
  const double sx = deviation.x() > 0 ? 1.0 / deviation.x() : 1.0;
  const double sy = deviation.y() > 0 ? 1.0 / deviation.y() : 1.0;
  normalized->resize(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    (*normalized)[i] = Eigen::Vector2d((points[i].x() - mean.x()) * sx,
                                       (points[i].y() - mean.y()) * sy);
  }
  Eigen::Matrix3d T = Eigen::Matrix3d::Identity();
  T(0, 0) = sx;
  T(1, 1) = sy;
  T(0, 2) = -mean.x() * sx;
  T(1, 2) = -mean.y() * sy;
  return T;
}

// The unit vector x minimising |A x| for the DLT rows accumulated in `ata` = A^T A: its
// eigenvector of the smallest eigenvalue (as OpenCV's 8-point and homography kernels). A fixed
// 9x9 eigen-solve instead of an SVD of the 2n x 9 (or n x 9) A: several times cheaper in the
// RANSAC loop, and the normalised coordinates keep A^T A well conditioned.
Eigen::Matrix<double, 9, 1> NullVector(const Eigen::Matrix<double, 9, 9>& ata) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 9, 9>> eigen(ata);
  return eigen.eigenvectors().col(0);
}

Eigen::Matrix3d HomographyFromNormalized(const std::vector<Eigen::Vector2d>& p1,
                                         const std::vector<Eigen::Vector2d>& p2) {
  Eigen::Matrix<double, 9, 9> ata = Eigen::Matrix<double, 9, 9>::Zero();
  for (size_t i = 0; i < p1.size(); ++i) {
    const double u1 = p1[i].x(), v1 = p1[i].y(), u2 = p2[i].x(), v2 = p2[i].y();
    Eigen::Matrix<double, 9, 1> a, b;
    a << 0, 0, 0, -u1, -v1, -1, v2 * u1, v2 * v1, v2;
    b << u1, v1, 1, 0, 0, 0, -u2 * u1, -u2 * v1, -u2;
    ata.noalias() += a * a.transpose() + b * b.transpose();
  }
  const Eigen::Matrix<double, 9, 1> h = NullVector(ata);
  Eigen::Matrix3d H;
  H << h(0), h(1), h(2), h(3), h(4), h(5), h(6), h(7), h(8);
  return H;
}

Eigen::Matrix3d FundamentalFromNormalized(const std::vector<Eigen::Vector2d>& p1,
                                          const std::vector<Eigen::Vector2d>& p2) {
  Eigen::Matrix<double, 9, 9> ata = Eigen::Matrix<double, 9, 9>::Zero();
  for (size_t i = 0; i < p1.size(); ++i) {
    const double u1 = p1[i].x(), v1 = p1[i].y(), u2 = p2[i].x(), v2 = p2[i].y();
    Eigen::Matrix<double, 9, 1> a;
    a << u2 * u1, u2 * v1, u2, v2 * u1, v2 * v1, v2, u1, v1, 1;
    ata.noalias() += a * a.transpose();
  }
  const Eigen::Matrix<double, 9, 1> f = NullVector(ata);
  Eigen::Matrix3d F;
  F << f(0), f(1), f(2), f(3), f(4), f(5), f(6), f(7), f(8);
  // Rank 2: a fundamental matrix has a null space (the epipole).
  Eigen::JacobiSVD<Eigen::Matrix3d> svd_f(F, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Vector3d w = svd_f.singularValues();
  w(2) = 0;
  return svd_f.matrixU() * w.asDiagonal() * svd_f.matrixV().transpose();
}

Eigen::Vector2d Transfer(const Eigen::Matrix3d& H, const Eigen::Vector2d& p) {
  const Eigen::Vector3d x = H * p.homogeneous();
  return x.hnormalized();
}

// A match adds at most this to a score (both of its terms at chi2 = 0).
constexpr double kMaxMatchScore = 2 * kChi2TwoDof;

// Whether a hypothesis whose first `scored` of `n` matches sum to `score` can no longer beat
// `to_beat` (RANSAC keeps a model only when it scores strictly more): even if every remaining
// match added kMaxMatchScore. The margin covers the sums' rounding, so a hypothesis is dropped
// only when it provably loses: the chosen model is the same as with every match scored.
bool CannotBeat(double score, size_t scored, size_t n, double to_beat) {
  const double bound = score + kMaxMatchScore * static_cast<double>(n - scored);
  return bound < to_beat - 1e-9 * std::abs(to_beat);
}

// Every this many matches the bound above is checked.
constexpr size_t kBoundStride = 16;

// ORB-SLAM's score: the sum over matches of (threshold - chi2) in both directions, for the
// matches within the threshold in both; `inliers` marks those. Returns -1 (and partial inliers)
// as soon as the score cannot exceed `to_beat`.
double ScoreHomography(const Eigen::Matrix3d& H21, const std::vector<Eigen::Vector2d>& p1,
                       const std::vector<Eigen::Vector2d>& p2, double inv_sigma2,
                       std::vector<uint8_t>* inliers, double to_beat) {
  const Eigen::Matrix3d H12 = H21.inverse();
  double score = 0;
  inliers->assign(p1.size(), 0);
  for (size_t i = 0; i < p1.size(); ++i) {
    if (i % kBoundStride == 0 && CannotBeat(score, i, p1.size(), to_beat)) return -1;
    const double chi1 = (p1[i] - Transfer(H12, p2[i])).squaredNorm() * inv_sigma2;
    const double chi2 = (p2[i] - Transfer(H21, p1[i])).squaredNorm() * inv_sigma2;
    if (!(chi1 <= kChi2TwoDof) || !(chi2 <= kChi2TwoDof)) continue;
    score += (kChi2TwoDof - chi1) + (kChi2TwoDof - chi2);
    (*inliers)[i] = 1;
  }
  return score;
}

// A match is an inlier when it lies within the 1-dof threshold of both epipolar lines; it scores
// against the 2-dof threshold, as the homography does, so that the two scores compare.
double ScoreFundamental(const Eigen::Matrix3d& F21, const std::vector<Eigen::Vector2d>& p1,
                        const std::vector<Eigen::Vector2d>& p2, double inv_sigma2,
                        std::vector<uint8_t>* inliers, double to_beat) {
  double score = 0;
  inliers->assign(p1.size(), 0);
  for (size_t i = 0; i < p1.size(); ++i) {
    if (i % kBoundStride == 0 && CannotBeat(score, i, p1.size(), to_beat)) return -1;
    const Eigen::Vector3d x1 = p1[i].homogeneous(), x2 = p2[i].homogeneous();
    const Eigen::Vector3d l2 = F21 * x1;             // in image 2
    const Eigen::Vector3d l1 = F21.transpose() * x2;  // in image 1
    const double n2 = l2.head<2>().squaredNorm(), n1 = l1.head<2>().squaredNorm();
    if (!(n1 > 0) || !(n2 > 0)) continue;
    const double chi2 = std::pow(l2.dot(x2), 2) / n2 * inv_sigma2;
    const double chi1 = std::pow(l1.dot(x1), 2) / n1 * inv_sigma2;
    if (!(chi1 <= kChi2OneDof) || !(chi2 <= kChi2OneDof)) continue;
    score += (kChi2TwoDof - chi1) + (kChi2TwoDof - chi2);
    (*inliers)[i] = 1;
  }
  return score;
}

struct Hypothesis {
  Eigen::Matrix3d R;
  Eigen::Vector3d t;
};

struct Check {
  int good = 0;
  double parallax_deg = 0;
  std::vector<uint8_t> triangulated;
  std::vector<Eigen::Vector3d> points;
};

// ORB-SLAM's CheckRT: triangulates every inlier under (R, t) and counts those in front of both
// cameras that reproject within `max_error2` px^2; the ones with parallax are triangulated.
Check CheckMotion(const Hypothesis& h, const Eigen::Matrix3d& K,
                  const std::vector<Eigen::Vector2d>& p1, const std::vector<Eigen::Vector2d>& p2,
                  const std::vector<uint8_t>& inliers, double max_error2) {
  Check check;
  check.triangulated.assign(p1.size(), 0);
  check.points.assign(p1.size(), Eigen::Vector3d::Zero());
  const Eigen::Matrix3d K_inv = K.inverse();
  Rigid3d cam2_from_cam1 = Rigid3d::Identity();
  cam2_from_cam1.linear() = h.R;
  cam2_from_cam1.translation() = h.t;
  const Eigen::Vector3d center2 = -h.R.transpose() * h.t;
  std::vector<double> parallax_cos;
  auto reprojection2 = [&](const Eigen::Vector3d& x_cam, const Eigen::Vector2d& pixel) {
    return ((K * x_cam).hnormalized() - pixel).squaredNorm();
  };
  for (size_t i = 0; i < p1.size(); ++i) {
    if (!inliers[i]) continue;
    const Eigen::Vector2d n1 = (K_inv * p1[i].homogeneous()).hnormalized();
    const Eigen::Vector2d n2 = (K_inv * p2[i].homogeneous()).hnormalized();
    const std::optional<Eigen::Vector3d> x =
        TriangulatePoint(Rigid3d::Identity(), cam2_from_cam1, n1, n2);
    if (!x) continue;
    const Eigen::Vector3d ray1 = *x, ray2 = *x - center2;
    const double cos_parallax = ray1.dot(ray2) / (ray1.norm() * ray2.norm());
    const Eigen::Vector3d x2 = cam2_from_cam1 * *x;
    // Behind a camera is only meaningful with parallax (else the depth is unconstrained).
    if ((x->z() <= 0 || x2.z() <= 0) && cos_parallax < kParallelCos) continue;
    if (x->z() <= 0 || x2.z() <= 0) continue;
    if (reprojection2(*x, p1[i]) > max_error2 || reprojection2(x2, p2[i]) > max_error2) continue;
    parallax_cos.push_back(cos_parallax);
    ++check.good;
    if (cos_parallax < kParallelCos) {
      check.triangulated[i] = 1;
      check.points[i] = *x;
    }
  }
  if (!parallax_cos.empty()) {
    // The 50th-largest parallax (ORB-SLAM): a few dozen points must have it, not just one.
    std::sort(parallax_cos.begin(), parallax_cos.end());
    const size_t idx = std::min<size_t>(50, parallax_cos.size() - 1);
    check.parallax_deg = std::acos(std::clamp(parallax_cos[idx], -1.0, 1.0)) * kRadToDeg;
  }
  return check;
}

// The eight motions of a homography (Faugeras' SVD decomposition, as ORB-SLAM's ReconstructH).
std::vector<Hypothesis> DecomposeHomography(const Eigen::Matrix3d& H21, const Eigen::Matrix3d& K) {
  const Eigen::Matrix3d A = K.inverse() * H21 * K;
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(A, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Matrix3d U = svd.matrixU(), V = svd.matrixV();
  const Eigen::Matrix3d Vt = V.transpose();
  const double s = U.determinant() * Vt.determinant();
  const Eigen::Vector3d w = svd.singularValues();
  const double d1 = w(0), d2 = w(1), d3 = w(2);
  std::vector<Hypothesis> out;
  // Equal singular values: the motion is not recoverable from H (pure rotation or a degenerate
  // case).
  if (d1 / d2 < 1.00001 || d2 / d3 < 1.00001) return out;
  const double aux1 = std::sqrt((d1 * d1 - d2 * d2) / (d1 * d1 - d3 * d3));
  const double aux3 = std::sqrt((d2 * d2 - d3 * d3) / (d1 * d1 - d3 * d3));
  const std::array<double, 4> x1{aux1, aux1, -aux1, -aux1};
  const std::array<double, 4> x3{aux3, -aux3, aux3, -aux3};
  // d' = d2 > 0.
  const double aux_stheta =
      std::sqrt((d1 * d1 - d2 * d2) * (d2 * d2 - d3 * d3)) / ((d1 + d3) * d2);
  const double ctheta = (d2 * d2 + d1 * d3) / ((d1 + d3) * d2);
  const std::array<double, 4> stheta{aux_stheta, -aux_stheta, -aux_stheta, aux_stheta};
  for (int i = 0; i < 4; ++i) {
    Eigen::Matrix3d Rp;
    Rp << ctheta, 0, -stheta[i], 0, 1, 0, stheta[i], 0, ctheta;
    const Eigen::Vector3d tp(x1[i] * (d1 - d3), 0, -x3[i] * (d1 - d3));
    out.push_back({s * U * Rp * Vt, (U * tp).normalized()});
  }
  // d' = -d2 < 0.
  const double aux_sphi = std::sqrt((d1 * d1 - d2 * d2) * (d2 * d2 - d3 * d3)) / ((d1 - d3) * d2);
  const double cphi = (d1 * d3 - d2 * d2) / ((d1 - d3) * d2);
  const std::array<double, 4> sphi{aux_sphi, -aux_sphi, -aux_sphi, aux_sphi};
  for (int i = 0; i < 4; ++i) {
    Eigen::Matrix3d Rp;
    Rp << cphi, 0, sphi[i], 0, -1, 0, sphi[i], 0, -cphi;
    const Eigen::Vector3d tp(x1[i] * (d1 + d3), 0, x3[i] * (d1 + d3));
    out.push_back({s * U * Rp * Vt, (U * tp).normalized()});
  }
  return out;
}

// The four motions of an essential matrix.
std::vector<Hypothesis> DecomposeEssential(const Eigen::Matrix3d& E) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(E, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Matrix3d U = svd.matrixU(), V = svd.matrixV();
  Eigen::Matrix3d W;
  W << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  Eigen::Matrix3d R1 = U * W * V.transpose();
  Eigen::Matrix3d R2 = U * W.transpose() * V.transpose();
  if (R1.determinant() < 0) R1 = -R1;
  if (R2.determinant() < 0) R2 = -R2;
  const Eigen::Vector3d t = U.col(2).normalized();
  return {{R1, t}, {R2, t}, {R1, -t}, {R2, -t}};
}

}  // namespace

Eigen::Matrix3d HomographyDlt(const std::vector<Eigen::Vector2d>& pixels1,
                              const std::vector<Eigen::Vector2d>& pixels2) {
  if (pixels1.size() != pixels2.size() || pixels1.size() < 4)
    throw std::invalid_argument("HomographyDlt: needs >= 4 matches");
  std::vector<Eigen::Vector2d> n1, n2;
  const Eigen::Matrix3d T1 = Normalize(pixels1, &n1), T2 = Normalize(pixels2, &n2);
  return T2.inverse() * HomographyFromNormalized(n1, n2) * T1;
}

Eigen::Matrix3d FundamentalEightPoint(const std::vector<Eigen::Vector2d>& pixels1,
                                      const std::vector<Eigen::Vector2d>& pixels2) {
  if (pixels1.size() != pixels2.size() || pixels1.size() < 8)
    throw std::invalid_argument("FundamentalEightPoint: needs >= 8 matches");
  std::vector<Eigen::Vector2d> n1, n2;
  const Eigen::Matrix3d T1 = Normalize(pixels1, &n1), T2 = Normalize(pixels2, &n2);
  return T2.transpose() * FundamentalFromNormalized(n1, n2) * T1;
}

TwoViewResult InitializeTwoView(const Eigen::Matrix3d& K,
                                const std::vector<Eigen::Vector2d>& pixels1,
                                const std::vector<Eigen::Vector2d>& pixels2,
                                const TwoViewOptions& options) {
  options.Check();
  if (pixels1.size() != pixels2.size())
    throw std::invalid_argument("InitializeTwoView: match lists differ in length");
  TwoViewResult result;
  const size_t n = pixels1.size();
  if (n < 8) {
    result.failure = "fewer than 8 matches";
    return result;
  }
  std::vector<Eigen::Vector2d> n1, n2;
  const Eigen::Matrix3d T1 = Normalize(pixels1, &n1), T2 = Normalize(pixels2, &n2);
  const Eigen::Matrix3d T2_inv = T2.inverse();
  const double inv_sigma2 = 1.0 / (options.sigma_px * options.sigma_px);

  // The same minimal sets for both models, so that their scores compare: drawn first, then each
  // model's RANSAC runs on its own thread (as ORB-SLAM's), in iteration order, so the result does
  // not depend on the threads.
  std::mt19937_64 rng(options.seed);
  std::vector<std::array<size_t, 8>> sets(static_cast<size_t>(options.ransac_iterations));
  std::vector<size_t> all(n);
  for (auto& set : sets) {
    for (size_t i = 0; i < n; ++i) all[i] = i;
    // A partial Fisher-Yates shuffle: 8 distinct matches.
    for (size_t j = 0; j < 8; ++j) {
      std::uniform_int_distribution<size_t> pick(j, n - 1);
      std::swap(all[j], all[pick(rng)]);
      set[j] = all[j];
    }
  }
  // Runs one model's RANSAC; `fit` gives the model in pixels (none for a degenerate set),
  // `score` its score and inliers.
  auto ransac = [&](auto fit, auto score, Eigen::Matrix3d* model, std::vector<uint8_t>* inliers) {
    std::vector<Eigen::Vector2d> s1(8), s2(8);
    std::vector<uint8_t> current;
    double best = -1;
    for (const auto& set : sets) {
      for (size_t j = 0; j < 8; ++j) {
        s1[j] = n1[set[j]];
        s2[j] = n2[set[j]];
      }
      const std::optional<Eigen::Matrix3d> m = fit(s1, s2);
      if (!m) continue;
      const double s = score(*m, &current, best);
      if (s > best) {
        best = s;
        *model = *m;
        *inliers = current;
      }
    }
    return best;
  };
  std::vector<uint8_t> inliers_h, inliers_f;
  double best_h = -1, best_f = -1;
  auto homography = [&] {
    best_h = ransac(
        [&](const auto& s1, const auto& s2) -> std::optional<Eigen::Matrix3d> {
          const Eigen::Matrix3d H = T2_inv * HomographyFromNormalized(s1, s2) * T1;
          if (!H.allFinite() || !(std::abs(H.determinant()) > 1e-15)) return std::nullopt;
          return H;
        },
        [&](const Eigen::Matrix3d& H, std::vector<uint8_t>* current, double to_beat) {
          return ScoreHomography(H, pixels1, pixels2, inv_sigma2, current, to_beat);
        },
        &result.H21, &inliers_h);
  };
  auto fundamental = [&] {
    best_f = ransac(
        [&](const auto& s1, const auto& s2) -> std::optional<Eigen::Matrix3d> {
          const Eigen::Matrix3d F = T2.transpose() * FundamentalFromNormalized(s1, s2) * T1;
          if (!F.allFinite()) return std::nullopt;
          return F;
        },
        [&](const Eigen::Matrix3d& F, std::vector<uint8_t>* current, double to_beat) {
          return ScoreFundamental(F, pixels1, pixels2, inv_sigma2, current, to_beat);
        },
        &result.F21, &inliers_f);
  };
  if (options.parallel) {
    // std::async: an exception on the other thread reaches this one at get().
    std::future<void> homography_done = std::async(std::launch::async, homography);
    fundamental();
    homography_done.get();
  } else {
    homography();
    fundamental();
  }
  result.score_homography = std::max(0.0, best_h);
  result.score_fundamental = std::max(0.0, best_f);
  const double total = result.score_homography + result.score_fundamental;
  if (!(total > 0)) {
    result.failure = "no model explains the matches";
    return result;
  }
  result.homography_ratio = result.score_homography / total;
  const bool use_h = result.homography_ratio > options.homography_ratio;
  result.model = use_h ? TwoViewModel::kHomography : TwoViewModel::kFundamental;
  const std::vector<uint8_t>& inliers = use_h ? inliers_h : inliers_f;
  const int num_inliers = static_cast<int>(std::count(inliers.begin(), inliers.end(), 1));
  const std::vector<Hypothesis> hypotheses =
      use_h ? DecomposeHomography(result.H21, K)
            : DecomposeEssential(K.transpose() * result.F21 * K);
  if (hypotheses.empty()) {
    result.failure = "the homography has no motion (pure rotation?)";
    return result;
  }
  const double max_error2 = 4.0 * options.sigma_px * options.sigma_px;
  std::vector<Check> checks;
  int best = -1;
  for (size_t k = 0; k < hypotheses.size(); ++k) {
    checks.push_back(CheckMotion(hypotheses[k], K, pixels1, pixels2, inliers, max_error2));
    if (best < 0 || checks[k].good > checks[static_cast<size_t>(best)].good)
      best = static_cast<int>(k);
  }
  const Check& winner = checks[static_cast<size_t>(best)];
  const int min_good = std::max(options.min_triangulated,
                                static_cast<int>(options.min_triangulated_ratio * num_inliers));
  // Another hypothesis nearly as good: the motion is ambiguous (ORB-SLAM: 0.75 for H's eight,
  // 0.7 for F's four).
  const double ambiguity = use_h ? 0.75 : 0.7;
  int similar = 0;
  for (const Check& c : checks) similar += c.good > ambiguity * winner.good ? 1 : 0;
  if (winner.good < min_good) {
    result.failure = "too few matches triangulated (" + std::to_string(winner.good) + " of " +
                     std::to_string(num_inliers) + " inliers)";
    return result;
  }
  if (similar > 1) {
    result.failure = "ambiguous motion";
    return result;
  }
  if (winner.parallax_deg < options.min_parallax_deg) {
    result.failure = "too little parallax";
    result.parallax_deg = winner.parallax_deg;
    return result;
  }
  result.valid = true;
  result.cam2_from_cam1.linear() = hypotheses[static_cast<size_t>(best)].R;
  result.cam2_from_cam1.translation() = hypotheses[static_cast<size_t>(best)].t;
  result.triangulated = winner.triangulated;
  result.points_cam1 = winner.points;
  result.num_triangulated =
      static_cast<int>(std::count(winner.triangulated.begin(), winner.triangulated.end(), 1));
  result.parallax_deg = winner.parallax_deg;
  return result;
}

double TranslationDirectionSigmaDeg(const Eigen::Matrix3d& K, const Rigid3d& cam2_from_cam1,
                                    const std::vector<Eigen::Vector3d>& points_cam1,
                                    const std::vector<Eigen::Vector2d>& pixels1,
                                    const std::vector<Eigen::Vector2d>& pixels2,
                                    double sigma_px) {
  (void)pixels1;
  (void)pixels2;  // the information depends on the geometry only (Gauss-Newton at the solution)
  const Eigen::Matrix3d R = cam2_from_cam1.linear();
  const Eigen::Vector3d t = cam2_from_cam1.translation();
  if (!(t.norm() > 0)) return 180.0;
  // At unit baseline, so that a step of the direction's parameters is an angle.
  const Eigen::Vector3d dir = t.normalized();
  const double unit = 1.0 / t.norm();
  // Two unit vectors orthogonal to the translation: its direction's degrees of freedom.
  Eigen::Vector3d b1 = dir.unitOrthogonal();
  const Eigen::Vector3d b2 = dir.cross(b1);
  Eigen::Matrix<double, 3, 2> B;
  B << b1, b2;
  auto projection_jacobian = [&](const Eigen::Vector3d& p) {
    Eigen::Matrix<double, 2, 3> J;
    const double z = p.z(), z2 = z * z;
    J << K(0, 0) / z, 0, -K(0, 0) * p.x() / z2, 0, K(1, 1) / z, -K(1, 1) * p.y() / z2;
    return J;
  };
  // Pose parameters: rotation (left perturbation, 3) and the translation's direction (2).
  Eigen::Matrix<double, 5, 5> schur = Eigen::Matrix<double, 5, 5>::Zero();
  const double w = 1.0 / (sigma_px * sigma_px);
  int used = 0;
  for (const Eigen::Vector3d& point : points_cam1) {
    const Eigen::Vector3d x = point * unit;
    const Eigen::Vector3d p2 = R * x + dir;
    if (!(x.z() > 0) || !(p2.z() > 0)) continue;
    const Eigen::Matrix<double, 2, 3> P1 = projection_jacobian(x), P2 = projection_jacobian(p2);
    Eigen::Matrix<double, 2, 5> Jc;
    Jc.leftCols<3>() = -P2 * Skew(R * x);
    Jc.rightCols<2>() = P2 * B;
    const Eigen::Matrix<double, 2, 3> Jx2 = P2 * R;
    const Eigen::Matrix3d Hxx = w * (P1.transpose() * P1 + Jx2.transpose() * Jx2);
    const Eigen::Matrix<double, 5, 3> Hcx = w * Jc.transpose() * Jx2;
    schur += w * Jc.transpose() * Jc - Hcx * Hxx.ldlt().solve(Hcx.transpose());
    ++used;
  }
  if (used < 5) return 180.0;
  const Eigen::Matrix<double, 5, 5> covariance = schur.inverse();
  if (!covariance.allFinite()) return 180.0;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(covariance.bottomRightCorner<2, 2>());
  const double variance = eig.eigenvalues().maxCoeff();
  if (!(variance > 0)) return 180.0;
  return std::min(180.0, std::sqrt(variance) * kRadToDeg);
}

}  // namespace ademono
