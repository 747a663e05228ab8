#include "ademono/eval/trajectory_eval.h"

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <numeric>
#include <stdexcept>

#include "ademono/core/error.h"
#include "ademono/core/file_util.h"

namespace fs = std::filesystem;

namespace ademono {

namespace {

constexpr double kRadToDeg = 180.0 / M_PI;

// evo's lie.se3_inverse: assumes a rotation, inverts with the transpose.
Eigen::Matrix4d Se3InverseByTranspose(const Eigen::Matrix4d& m) {
  Eigen::Matrix4d inv = Eigen::Matrix4d::Identity();
  const Eigen::Matrix3d rt = m.topLeftCorner<3, 3>().transpose();
  inv.topLeftCorner<3, 3>() = rt;
  inv.topRightCorner<3, 1>() = -rt * m.topRightCorner<3, 1>();
  return inv;
}

// evo's lie.relative_se3(a, b) = a^-1 * b.
Eigen::Matrix4d RelativeSe3(const Eigen::Matrix4d& a, const Eigen::Matrix4d& b) {
  return Se3InverseByTranspose(a) * b;
}

// Rotation angle through the quaternion, accurate for small angles (evo uses scipy's rotvec).
double RotationAngleOf(const Eigen::Matrix3d& r) {
  Eigen::Quaterniond q(r);
  q.normalize();
  return 2.0 * std::atan2(q.vec().norm(), std::abs(q.w()));
}

Eigen::Matrix3Xd Positions(const std::vector<Eigen::Matrix4d>& poses) {
  Eigen::Matrix3Xd p(3, poses.size());
  for (size_t i = 0; i < poses.size(); ++i)
    p.col(static_cast<Eigen::Index>(i)) = poses[i].topRightCorner<3, 1>();
  return p;
}

// evo filters.filter_pairs_by_index / filter_pairs_by_path with all_pairs = False.
std::vector<std::pair<size_t, size_t>> RpePairs(const std::vector<Eigen::Matrix4d>& poses,
                                                double delta, DeltaUnit unit) {
  std::vector<size_t> ids;
  if (unit == DeltaUnit::kFrames) {
    const auto step = static_cast<size_t>(delta);
    for (size_t i = 0; i < poses.size(); i += step) ids.push_back(i);
  } else {
    double path = 0.0;
    for (size_t i = 0; i < poses.size(); ++i) {
      const size_t prev = i == 0 ? 0 : i - 1;
      path += (poses[i].topRightCorner<3, 1>() - poses[prev].topRightCorner<3, 1>()).norm();
      if (path >= delta) {
        ids.push_back(i);
        path = 0.0;
      }
    }
  }
  std::vector<std::pair<size_t, size_t>> pairs;
  for (size_t k = 1; k < ids.size(); ++k) pairs.emplace_back(ids[k - 1], ids[k]);
  return pairs;
}

// kitti-odom-eval's rotation_error: arccos of the clamped trace on the raw matrix.
double KittiRotationError(const Eigen::Matrix4d& e) {
  const double d = 0.5 * (e(0, 0) + e(1, 1) + e(2, 2) - 1.0);
  return std::acos(std::max(std::min(d, 1.0), -1.0));
}

double KittiTranslationError(const Eigen::Matrix4d& e) { return e.topRightCorner<3, 1>().norm(); }

}  // namespace

PoseSeries ToPoseSeries(const Trajectory& trajectory) {
  PoseSeries series;
  for (const auto& pose : trajectory) {
    series.timestamps.push_back(pose.timestamp);
    series.world_from_cam.push_back(pose.world_from_cam.matrix());
  }
  return series;
}

PoseSeries ReadPoseSeries(const fs::path& path, TrajectoryFormat format) {
  if (format != TrajectoryFormat::kKitti && format != TrajectoryFormat::kKittiIndexed) {
    PoseSeries series = ToPoseSeries(ReadTrajectory(path, format));
    series.format = format;
    return series;
  }
  const KittiRows rows =
      ReadKittiRows(path, /*accept_index=*/true, format == TrajectoryFormat::kKittiIndexed);
  PoseSeries series;
  series.format = rows.indexed ? TrajectoryFormat::kKittiIndexed : TrajectoryFormat::kKitti;
  for (size_t i = 0; i < rows.rows.size(); ++i) {
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    m.topRows<3>() = rows.rows[i];
    series.timestamps.push_back(static_cast<double>(rows.index[i]));
    series.world_from_cam.push_back(m);
  }
  return series;
}

ErrorStats ComputeStats(const std::vector<double>& errors) {
  ErrorStats s;
  s.count = errors.size();
  if (errors.empty()) return s;
  const double n = static_cast<double>(errors.size());
  double sum = 0, sum_sq = 0;
  for (double e : errors) {
    sum += e;
    sum_sq += e * e;
  }
  s.mean = sum / n;
  s.rmse = std::sqrt(sum_sq / n);
  double var = 0;
  for (double e : errors) var += (e - s.mean) * (e - s.mean);
  s.std = std::sqrt(var / n);
  const auto [lo, hi] = std::minmax_element(errors.begin(), errors.end());
  s.min = *lo;
  s.max = *hi;
  std::vector<double> sorted = errors;
  std::sort(sorted.begin(), sorted.end());
  const size_t mid = sorted.size() / 2;
  s.median = sorted.size() % 2 == 1 ? sorted[mid] : 0.5 * (sorted[mid - 1] + sorted[mid]);
  return s;
}

double Percentile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const double pos = q * static_cast<double>(values.size() - 1);
  const size_t lo = static_cast<size_t>(std::floor(pos));
  const size_t hi = std::min(values.size() - 1, lo + 1);
  return values[lo] + (pos - static_cast<double>(lo)) * (values[hi] - values[lo]);
}

std::vector<std::pair<size_t, size_t>> AssociateLikeEvo(const std::vector<double>& gt_stamps,
                                                        const std::vector<double>& est_stamps,
                                                        double max_diff) {
  const bool est_longer = est_stamps.size() > gt_stamps.size();
  const std::vector<double>& shorter = est_longer ? gt_stamps : est_stamps;
  const std::vector<double>& longer = est_longer ? est_stamps : gt_stamps;
  const bool sorted = std::is_sorted(longer.begin(), longer.end());
  std::vector<std::pair<size_t, size_t>> pairs;
  for (size_t i = 0; i < shorter.size(); ++i) {
    const double t = shorter[i];
    size_t best = 0;
    double best_diff = std::numeric_limits<double>::infinity();
    auto consider = [&](size_t j) {
      const double diff = std::abs(longer[j] - t);
      // np.argmin: the first index wins on ties.
      if (diff < best_diff || (diff == best_diff && j < best)) {
        best_diff = diff;
        best = j;
      }
    };
    if (sorted) {
      const size_t upper =
          static_cast<size_t>(std::lower_bound(longer.begin(), longer.end(), t) - longer.begin());
      // Equal stamps may repeat; scan back over ties so the first of them wins.
      size_t lo = upper == 0 ? 0 : upper - 1;
      while (lo > 0 && longer[lo - 1] == longer[lo]) --lo;
      for (size_t j = lo; j < std::min(longer.size(), upper + 1); ++j) consider(j);
    } else {
      for (size_t j = 0; j < longer.size(); ++j) consider(j);
    }
    if (!longer.empty() && best_diff <= max_diff) {
      pairs.emplace_back(est_longer ? i : best, est_longer ? best : i);
    }
  }
  return pairs;
}

Similarity UmeyamaAlignment(const Eigen::Matrix3Xd& src, const Eigen::Matrix3Xd& dst,
                            bool with_scale) {
  if (src.cols() != dst.cols()) throw std::invalid_argument("Umeyama: point counts differ");
  if (src.cols() < 3) throw std::invalid_argument("need at least 3 matched poses to align");
  const double n = static_cast<double>(src.cols());
  const Eigen::Vector3d mean_src = src.rowwise().mean();
  const Eigen::Vector3d mean_dst = dst.rowwise().mean();
  const Eigen::Matrix3Xd src_c = src.colwise() - mean_src;
  const Eigen::Matrix3Xd dst_c = dst.colwise() - mean_dst;
  const double sigma_src = src_c.squaredNorm() / n;
  const Eigen::Matrix3d cov = dst_c * src_c.transpose() / n;
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(cov, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Vector3d d = svd.singularValues();
  const int rank = static_cast<int>((d.array() > std::numeric_limits<double>::epsilon()).count());
  if (rank < 2) {
    throw std::invalid_argument("degenerate point set (all positions on a line), cannot align");
  }
  Eigen::Matrix3d s = Eigen::Matrix3d::Identity();
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0.0) s(2, 2) = -1;
  Similarity out;
  out.rotation = svd.matrixU() * s * svd.matrixV().transpose();
  out.scale = with_scale ? (d.asDiagonal() * s).trace() / sigma_src : 1.0;
  out.translation = mean_dst - out.scale * out.rotation * mean_src;
  return out;
}

Alignment ParseAlignment(const std::string& name) {
  if (name == "none") return Alignment::kNone;
  if (name == "se3") return Alignment::kSe3;
  if (name == "sim3") return Alignment::kSim3;
  if (name == "origin") return Alignment::kOrigin;
  throw std::invalid_argument("unknown alignment '" + name +
                              "' (expected none, se3, sim3, origin)");
}

DeltaUnit ParseDeltaUnit(const std::string& name) {
  if (name == "frames" || name == "f") return DeltaUnit::kFrames;
  if (name == "m" || name == "meters" || name == "metres") return DeltaUnit::kMeters;
  throw std::invalid_argument("unknown RPE delta unit '" + name + "' (expected frames or m)");
}

KittiAlignment ParseKittiAlignment(const std::string& name) {
  if (name == "none") return KittiAlignment::kNone;
  if (name == "scale") return KittiAlignment::kScale;
  if (name == "6dof") return KittiAlignment::kSixDof;
  if (name == "7dof") return KittiAlignment::kSevenDof;
  throw std::invalid_argument("unknown KITTI alignment '" + name +
                              "' (expected none, scale, 6dof, 7dof)");
}

std::string ToString(Alignment alignment) {
  switch (alignment) {
    case Alignment::kNone:
      return "none";
    case Alignment::kSe3:
      return "se3";
    case Alignment::kSim3:
      return "sim3";
    case Alignment::kOrigin:
      return "origin";
  }
  return "?";
}

std::string ToString(KittiAlignment alignment) {
  switch (alignment) {
    case KittiAlignment::kNone:
      return "none";
    case KittiAlignment::kScale:
      return "scale";
    case KittiAlignment::kSixDof:
      return "6dof";
    case KittiAlignment::kSevenDof:
      return "7dof";
  }
  return "?";
}

KittiAlignment KittiAlignmentFor(Alignment alignment) {
  switch (alignment) {
    case Alignment::kSe3:
      return KittiAlignment::kSixDof;
    case Alignment::kSim3:
      return KittiAlignment::kSevenDof;
    default:
      return KittiAlignment::kNone;
  }
}

void EvalOptions::Check() const {
  if (!(max_diff >= 0) || !std::isfinite(max_diff)) {
    throw std::invalid_argument("max_diff must be a finite number >= 0");
  }
  if (!(rpe_delta > 0) || !std::isfinite(rpe_delta)) {
    throw std::invalid_argument("RPE delta must be > 0");
  }
  if (rpe_unit == DeltaUnit::kFrames && rpe_delta != std::floor(rpe_delta)) {
    throw std::invalid_argument("RPE delta in frames must be a whole number");
  }
}

KittiOdometryResult EvaluateKittiOdometry(std::vector<Eigen::Matrix4d> gt,
                                          std::vector<Eigen::Matrix4d> est,
                                          KittiAlignment alignment) {
  if (gt.size() != est.size()) throw std::invalid_argument("KITTI evaluation needs equal sizes");
  std::vector<int64_t> index(gt.size());
  std::iota(index.begin(), index.end(), int64_t{0});
  return EvaluateKittiOdometry(index, std::move(gt), index, std::move(est), alignment);
}

KittiOdometryResult EvaluateKittiOdometry(const std::vector<int64_t>& gt_index,
                                          std::vector<Eigen::Matrix4d> gt,
                                          const std::vector<int64_t>& est_index,
                                          std::vector<Eigen::Matrix4d> est,
                                          KittiAlignment alignment) {
  if (gt.empty() || est.empty()) throw std::invalid_argument("KITTI evaluation needs poses");
  if (gt_index.size() != gt.size() || est_index.size() != est.size()) {
    throw std::invalid_argument("KITTI evaluation: one index per pose");
  }
  const size_t n = gt.size(), m = est.size();
  for (size_t i = 0; i < n; ++i) {
    if (gt_index[i] != static_cast<int64_t>(i)) {
      throw std::invalid_argument(
          "KITTI metrics need ground-truth frame indices 0, 1, 2, ... without gaps");
    }
  }
  // Position in `est` of each ground-truth frame, or m when that frame was not estimated.
  std::vector<size_t> est_at(n, m);
  for (size_t j = 0; j < m; ++j) {
    if (est_index[j] < 0 || est_index[j] >= static_cast<int64_t>(n)) {
      throw std::invalid_argument("estimate frame index " + std::to_string(est_index[j]) +
                                  " has no ground-truth pose");
    }
    if (j > 0 && est_index[j] <= est_index[j - 1]) {
      throw std::invalid_argument("estimate frame indices must increase");
    }
    est_at[static_cast<size_t>(est_index[j])] = j;
  }
  auto gt_of = [&](size_t j) -> Eigen::Matrix4d& { return gt[static_cast<size_t>(est_index[j])]; };
  // Both trajectories start at the identity; kitti-odom-eval moves only the ground-truth poses
  // that have an estimate.
  const Eigen::Matrix4d est0_inv = est[0].inverse();
  const Eigen::Matrix4d gt0_inv = gt_of(0).inverse();
  for (size_t j = 0; j < m; ++j) {
    est[j] = est0_inv * est[j];
    gt_of(j) = gt0_inv * gt_of(j);
  }
  if (alignment == KittiAlignment::kScale) {
    double xy = 0, xx = 0;
    for (size_t j = 0; j < m; ++j) {
      const Eigen::Vector3d x = est[j].topRightCorner<3, 1>();
      xy += x.dot(gt_of(j).topRightCorner<3, 1>());
      xx += x.squaredNorm();
    }
    const double scale = xy / xx;
    for (auto& pose : est) pose.topRightCorner<3, 1>() *= scale;
  } else if (alignment != KittiAlignment::kNone) {
    Eigen::Matrix3Xd gt_xyz(3, static_cast<Eigen::Index>(m));
    for (size_t j = 0; j < m; ++j)
      gt_xyz.col(static_cast<Eigen::Index>(j)) = gt_of(j).topRightCorner<3, 1>();
    const Similarity sim =
        UmeyamaAlignment(Positions(est), gt_xyz, alignment == KittiAlignment::kSevenDof);
    Eigen::Matrix4d align = Eigen::Matrix4d::Identity();
    align.topLeftCorner<3, 3>() = sim.rotation;
    align.topRightCorner<3, 1>() = sim.translation;
    for (auto& pose : est) {
      pose.topRightCorner<3, 1>() *= sim.scale;
      pose = align * pose;
    }
  }

  // Sub-sequence errors (calc_sequence_errors), path length along the whole ground truth.
  std::vector<double> dist(n, 0.0);
  for (size_t i = 1; i < n; ++i) {
    dist[i] =
        dist[i - 1] + (gt[i - 1].topRightCorner<3, 1>() - gt[i].topRightCorner<3, 1>()).norm();
  }
  static constexpr double kLengths[] = {100, 200, 300, 400, 500, 600, 700, 800};
  constexpr size_t kStep = 10;
  double t_sum = 0, r_sum = 0;
  size_t segments = 0;
  for (size_t first = 0; first < n; first += kStep) {
    for (double length : kLengths) {
      size_t last = n;
      for (size_t i = first; i < n; ++i) {
        if (dist[i] > dist[first] + length) {
          last = i;
          break;
        }
      }
      if (last == n || est_at[first] == m || est_at[last] == m) continue;
      const Eigen::Matrix4d delta_gt = gt[first].inverse() * gt[last];
      const Eigen::Matrix4d delta_est = est[est_at[first]].inverse() * est[est_at[last]];
      const Eigen::Matrix4d error = delta_est.inverse() * delta_gt;
      r_sum += KittiRotationError(error) / length;
      t_sum += KittiTranslationError(error) / length;
      ++segments;
    }
  }
  KittiOdometryResult result;
  result.segments = segments;
  if (segments > 0) {
    result.t_rel_percent = t_sum / static_cast<double>(segments) * 100.0;
    result.r_rel_deg_per_100m = r_sum / static_cast<double>(segments) * kRadToDeg * 100.0;
  }
  // compute_ATE and compute_RPE, over the estimated frames.
  double ate_sq = 0;
  for (size_t j = 0; j < m; ++j) {
    ate_sq += (gt_of(j).topRightCorner<3, 1>() - est[j].topRightCorner<3, 1>()).squaredNorm();
  }
  result.ate_m = std::sqrt(ate_sq / static_cast<double>(m));
  double rpe_t = 0, rpe_r = 0;
  size_t rpe_pairs = 0;
  for (size_t j = 0; j + 1 < m; ++j) {
    if (est_index[j + 1] != est_index[j] + 1) continue;
    const Eigen::Matrix4d gt_rel = gt_of(j).inverse() * gt_of(j + 1);
    const Eigen::Matrix4d est_rel = est[j].inverse() * est[j + 1];
    const Eigen::Matrix4d error = gt_rel.inverse() * est_rel;
    rpe_t += KittiTranslationError(error);
    rpe_r += KittiRotationError(error);
    ++rpe_pairs;
  }
  if (rpe_pairs > 0) {
    result.rpe_m = rpe_t / static_cast<double>(rpe_pairs);
    result.rpe_deg = rpe_r / static_cast<double>(rpe_pairs) * kRadToDeg;
  }
  return result;
}

namespace {

// Without alignment, poses matched by frame index (an indexed KITTI file, kitti-odom-eval's
// format) are measured from the first estimated frame, as kitti-odom-eval measures them. Plain
// KITTI and timestamped files keep evo's raw comparison (evo reads those formats).
bool AnchorsAtFirstFrame(const EvalOptions& options) {
  return options.alignment == Alignment::kNone && options.associate_by_frame_index &&
         !options.associate_by_timestamp;
}

}  // namespace

EvalResult EvaluateTrajectories(const PoseSeries& gt, const PoseSeries& est,
                                const EvalOptions& options) {
  options.Check();
  if (gt.size() == 0 || est.size() == 0) throw std::invalid_argument("empty trajectory");
  EvalResult r;
  r.gt_poses = gt.size();
  r.est_poses = est.size();
  r.alignment = options.alignment;
  r.rpe_delta = options.rpe_delta;
  r.rpe_unit = options.rpe_unit;

  std::vector<std::pair<size_t, size_t>> pairs;
  if (options.associate_by_timestamp) {
    pairs = AssociateLikeEvo(gt.timestamps, est.timestamps, options.max_diff);
    if (pairs.empty()) {
      char buf[64];
      std::snprintf(buf, sizeof(buf), "%g", options.max_diff);
      throw std::invalid_argument(std::string("no matching timestamps within ") + buf + " s");
    }
  } else if (options.associate_by_frame_index) {
    // kitti-odom-eval: poses keyed by frame index, the estimate's keys looked up in the ground
    // truth.
    std::map<double, size_t> gt_at;
    for (size_t i = 0; i < gt.size(); ++i) gt_at.emplace(gt.timestamps[i], i);
    for (size_t j = 0; j < est.size(); ++j) {
      const auto it = gt_at.find(est.timestamps[j]);
      if (it == gt_at.end()) {
        char buf[64];
        std::snprintf(buf, sizeof(buf), "%.0f", est.timestamps[j]);
        throw std::invalid_argument(std::string("estimate frame index ") + buf +
                                    " has no ground-truth pose");
      }
      pairs.emplace_back(it->second, j);
    }
  } else {
    if (gt.size() != est.size()) {
      throw std::invalid_argument("trajectories have different lengths");
    }
    for (size_t i = 0; i < gt.size(); ++i) pairs.emplace_back(i, i);
  }
  r.matched_poses = pairs.size();
  for (const auto& [i, j] : pairs) {
    r.gt_matched.timestamps.push_back(gt.timestamps[i]);
    r.gt_matched.world_from_cam.push_back(gt.world_from_cam[i]);
    r.est_aligned.timestamps.push_back(est.timestamps[j]);
    r.est_aligned.world_from_cam.push_back(est.world_from_cam[j]);
  }
  std::vector<Eigen::Matrix4d>& est_poses = r.est_aligned.world_from_cam;
  const std::vector<Eigen::Matrix4d>& gt_poses = r.gt_matched.world_from_cam;
  const std::vector<Eigen::Matrix4d> est_unaligned = est_poses;

  // Alignment (evo: PosePath3D.align / align_origin).
  if (options.alignment == Alignment::kSe3 || options.alignment == Alignment::kSim3) {
    r.gt_from_est = UmeyamaAlignment(Positions(est_poses), Positions(gt_poses),
                                     options.alignment == Alignment::kSim3);
  } else if (options.alignment == Alignment::kOrigin || AnchorsAtFirstFrame(options)) {
    // Origin; and indexed KITTI files without alignment: kitti-odom-eval (whose format they are)
    // expresses both trajectories relative to the first estimated frame before it measures
    // anything, since a KITTI pose is relative to the first camera and an estimate may start
    // later, in its own frame. The APE is that of evo's origin alignment (a rigid motion of both
    // changes no distance).
    const Eigen::Matrix4d t = gt_poses.front() * Se3InverseByTranspose(est_poses.front());
    r.gt_from_est.rotation = t.topLeftCorner<3, 3>();
    r.gt_from_est.translation = t.topRightCorner<3, 1>();
  }
  if (options.alignment != Alignment::kNone || AnchorsAtFirstFrame(options)) {
    Eigen::Matrix4d t = Eigen::Matrix4d::Identity();
    t.topLeftCorner<3, 3>() = r.gt_from_est.rotation;
    t.topRightCorner<3, 1>() = r.gt_from_est.translation;
    for (auto& pose : est_poses) {
      pose.topRightCorner<3, 1>() *= r.gt_from_est.scale;
      pose = t * pose;
    }
  }

  // APE, translation part.
  r.ape_errors.reserve(pairs.size());
  for (size_t k = 0; k < pairs.size(); ++k) {
    r.ape_errors.push_back(
        (est_poses[k].topRightCorner<3, 1>() - gt_poses[k].topRightCorner<3, 1>()).norm());
  }
  r.ape = ComputeStats(r.ape_errors);

  // RPE on the aligned estimate (evo_rpe with the same alignment).
  const auto rpe_pairs = RpePairs(options.rpe_pairs_from_reference ? gt_poses : est_poses,
                                  options.rpe_delta, options.rpe_unit);
  std::vector<double> rpe_t, rpe_r;
  for (const auto& [i, j] : rpe_pairs) {
    const Eigen::Matrix4d e =
        RelativeSe3(RelativeSe3(gt_poses[i], gt_poses[j]), RelativeSe3(est_poses[i], est_poses[j]));
    rpe_t.push_back(e.topRightCorner<3, 1>().norm());
    rpe_r.push_back(RotationAngleOf(e.topLeftCorner<3, 3>()) * kRadToDeg);
  }
  r.rpe_trans = ComputeStats(rpe_t);
  r.rpe_rot_deg = ComputeStats(rpe_r);

  if (options.kitti_metrics) {
    r.kitti_alignment = options.kitti_alignment;
    if (options.associate_by_frame_index && !options.associate_by_timestamp) {
      std::vector<int64_t> gt_index, est_index;
      for (double t : gt.timestamps) gt_index.push_back(std::llround(t));
      for (double t : est.timestamps) est_index.push_back(std::llround(t));
      r.kitti = EvaluateKittiOdometry(gt_index, gt.world_from_cam, est_index, est.world_from_cam,
                                      options.kitti_alignment);
    } else {
      r.kitti = EvaluateKittiOdometry(gt_poses, est_unaligned, options.kitti_alignment);
    }
  }
  return r;
}

EvalResult EvaluateTrajectories(const Trajectory& gt, const Trajectory& est,
                                const EvalOptions& options) {
  return EvaluateTrajectories(ToPoseSeries(gt), ToPoseSeries(est), options);
}

nlohmann::json ToJson(const ErrorStats& s) {
  return {{"rmse", s.rmse}, {"mean", s.mean}, {"median", s.median}, {"max", s.max},
          {"min", s.min},   {"std", s.std},   {"count", s.count}};
}

nlohmann::json ToJson(const EvalResult& r) {
  nlohmann::json j;
  j["ape"] = ToJson(r.ape);
  j["rpe_trans"] = ToJson(r.rpe_trans);
  j["rpe_rot_deg"] = ToJson(r.rpe_rot_deg);
  j["rpe_delta"] = r.rpe_delta;
  j["rpe_unit"] = r.rpe_unit == DeltaUnit::kFrames ? "frames" : "m";
  j["matched_poses"] = r.matched_poses;
  j["gt_poses"] = r.gt_poses;
  j["est_poses"] = r.est_poses;
  j["alignment"] = ToString(r.alignment);
  if (r.alignment == Alignment::kSim3) j["scale"] = r.gt_from_est.scale;
  if (r.kitti) {
    j["kitti"] = {{"t_rel_percent", r.kitti->t_rel_percent},
                  {"r_rel_deg_per_100m", r.kitti->r_rel_deg_per_100m},
                  {"ate_m", r.kitti->ate_m},
                  {"rpe_m", r.kitti->rpe_m},
                  {"rpe_deg", r.kitti->rpe_deg},
                  {"segments", r.kitti->segments},
                  {"alignment", ToString(r.kitti_alignment)}};
  }
  return j;
}

std::string FormatReport(const EvalResult& r) {
  std::string out;
  char buf[256];
  std::snprintf(buf, sizeof(buf), "matched poses: %zu (ground truth %zu, estimate %zu)\n",
                r.matched_poses, r.gt_poses, r.est_poses);
  out += buf;
  out += "alignment: " + ToString(r.alignment);
  if (r.alignment == Alignment::kSim3) {
    std::snprintf(buf, sizeof(buf), " (scale %.6f)", r.gt_from_est.scale);
    out += buf;
  }
  out += "\n";
  auto row = [&](const char* name, const ErrorStats& s, const char* unit) {
    std::snprintf(
        buf, sizeof(buf),
        "%-22s rmse %.6f  mean %.6f  median %.6f  std %.6f  min %.6f  max %.6f %s (n=%zu)\n", name,
        s.rmse, s.mean, s.median, s.std, s.min, s.max, unit, s.count);
    out += buf;
  };
  row("APE translation", r.ape, "m");
  std::snprintf(buf, sizeof(buf), "RPE (delta %g %s)", r.rpe_delta,
                r.rpe_unit == DeltaUnit::kFrames ? "frames" : "m");
  out += std::string(buf) + "\n";
  if (r.rpe_trans.count == 0) {
    out += "  no pose pairs this far apart\n";
  } else {
    row("  translation", r.rpe_trans, "m");
    row("  rotation", r.rpe_rot_deg, "deg");
  }
  if (r.kitti) {
    std::snprintf(buf, sizeof(buf),
                  "KITTI (%s): t_rel %.3f %%  r_rel %.3f deg/100m  ATE %.3f m  RPE %.3f m %.3f deg"
                  "  (%zu segments)\n",
                  ToString(r.kitti_alignment).c_str(), r.kitti->t_rel_percent,
                  r.kitti->r_rel_deg_per_100m, r.kitti->ate_m, r.kitti->rpe_m, r.kitti->rpe_deg,
                  r.kitti->segments);
    out += buf;
  }
  return out;
}

TrajectoryFile LoadTrajectoryFile(const std::string& path, const std::string& format_name) {
  TrajectoryFile file;
  file.path = path;
  file.detected = format_name == "auto";
  const TrajectoryFormat format =
      file.detected ? DetectTrajectoryFormat(path) : ParseTrajectoryFormat(format_name);
  file.poses = ReadPoseSeries(path, format);
  return file;
}

EvalResult EvaluateTrajectoryFiles(const TrajectoryFile& gt, const TrajectoryFile& est,
                                   EvalOptions options) {
  const bool gt_indexed = gt.poses.format == TrajectoryFormat::kKittiIndexed;
  const bool est_indexed = est.poses.format == TrajectoryFormat::kKittiIndexed;
  options.associate_by_timestamp = !gt.poses.HasFrameIndices() && !est.poses.HasFrameIndices();
  options.associate_by_frame_index = gt_indexed || est_indexed;
  if (options.associate_by_frame_index &&
      !(gt.poses.HasFrameIndices() && est.poses.HasFrameIndices())) {
    throw InputError(
        "an indexed KITTI file matches poses by frame index and cannot be compared "
        "with a timestamped file: " +
        gt.path + " (" + ToString(gt.poses.format) + ") and " + est.path + " (" +
        ToString(est.poses.format) + ")");
  }
  try {
    return EvaluateTrajectories(gt.poses, est.poses, options);
  } catch (const std::invalid_argument& e) {
    // The evaluation does not know the files; name both here.
    throw InputError(std::string(e.what()) + " between " + gt.path + " (" +
                     std::to_string(gt.poses.size()) + " poses) and " + est.path + " (" +
                     std::to_string(est.poses.size()) + " poses)");
  }
}

}  // namespace ademono
