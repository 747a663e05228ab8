#pragma once
// Trajectory evaluation that reproduces the two reference tools:
// - evo (MichaelGrupp/evo): timestamp association, Umeyama alignment (se3 / sim3 / origin / none),
//   APE translation statistics, RPE translation (m) and rotation angle (deg) over a delta in
//   frames or metres, consecutive (non-overlapping) pairs, pairs chosen on the estimate's path.
// - kitti-odom-eval (Huangying-Zhan/kitti-odom-eval): t_rel (%) and r_rel (deg/100 m) over
//   sub-sequences of 100..800 m starting every 10 frames, with its alignments none / scale / 6dof
//   / 7dof, and its ATE (RMSE) and consecutive-frame RPE means.
//
// Poses are world_from_cam 4x4 matrices kept exactly as read from the files (not
// re-orthonormalised), because both tools work on the raw matrices and their results depend on
// it at the 1e-6 level: evo inverts poses as [R^T | -R^T t], kitti-odom-eval with a general
// matrix inverse and measures rotation by arccos((trace - 1) / 2).

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "ademono/io/trajectory.h"

namespace ademono {

// Timestamped raw poses. For KITTI files timestamps are the frame indices: the line indices
// 0, 1, 2, ... of a plain file, the indices written in an indexed one (sorted, may skip).
struct PoseSeries {
  std::vector<double> timestamps;
  std::vector<Eigen::Matrix4d> world_from_cam;
  // The format actually read: kKitti becomes kKittiIndexed when the file carries indices.
  TrajectoryFormat format = TrajectoryFormat::kTum;
  size_t size() const { return world_from_cam.size(); }
  bool HasFrameIndices() const {
    return format == TrajectoryFormat::kKitti || format == TrajectoryFormat::kKittiIndexed;
  }
};
PoseSeries ToPoseSeries(const Trajectory& trajectory);
// Reads a trajectory file without touching the rotation matrices (KITTI, plain or indexed, as
// kitti-odom-eval's loader: "kitti" takes either) or through the TUM / EuRoC quaternion readers.
// Same errors as io/trajectory.h.
PoseSeries ReadPoseSeries(const std::filesystem::path& path, TrajectoryFormat format);

// Population statistics (numpy: np.std with ddof = 0, np.median averaging the middle pair).
struct ErrorStats {
  double rmse = 0, mean = 0, median = 0, max = 0, min = 0, std = 0;
  size_t count = 0;
};
ErrorStats ComputeStats(const std::vector<double>& errors);
// The q-quantile (0 <= q <= 1), linear between order statistics (numpy's default method); 0 for
// an empty list. For the median of error lists use ComputeStats (numpy's median).
double Percentile(std::vector<double> values, double q);

// evo's sync.associate_trajectories: every stamp of the shorter trajectory is matched to the
// nearest stamp of the longer one (first index on ties) if |dt| <= max_diff. A pose of the longer
// trajectory can be matched more than once. Returns index pairs (gt index, est index) in the
// order of the shorter trajectory.
std::vector<std::pair<size_t, size_t>> AssociateLikeEvo(const std::vector<double>& gt_stamps,
                                                        const std::vector<double>& est_stamps,
                                                        double max_diff);

// Least-squares similarity dst ~ scale * rotation * src + translation (Umeyama 1991), as evo and
// kitti-odom-eval implement it. `with_scale` false gives scale 1 (the se3 / Horn solution).
// Throws std::invalid_argument for fewer than 3 points or a degenerate (collinear) point set.
struct Similarity {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  double scale = 1.0;
};
Similarity UmeyamaAlignment(const Eigen::Matrix3Xd& src, const Eigen::Matrix3Xd& dst,
                            bool with_scale);

// kNone on poses matched by frame index (an indexed KITTI file, kitti-odom-eval's format)
// measures both trajectories from the first estimated frame, as kitti-odom-eval does (a KITTI
// pose is relative to the first camera; an estimate that starts later, in its own frame, is
// otherwise off by that offset). Plain KITTI and timestamped files are compared as they are, as
// evo does (kitti-odom-eval agrees on files that start at the identity, as KITTI's do).
enum class Alignment { kNone, kSe3, kSim3, kOrigin };
enum class DeltaUnit { kFrames, kMeters };
enum class KittiAlignment { kNone, kScale, kSixDof, kSevenDof };
// "none|se3|sim3|origin", "frames|m", "none|scale|6dof|7dof"; std::invalid_argument otherwise.
Alignment ParseAlignment(const std::string& name);
DeltaUnit ParseDeltaUnit(const std::string& name);
KittiAlignment ParseKittiAlignment(const std::string& name);
std::string ToString(Alignment alignment);
std::string ToString(KittiAlignment alignment);
// The kitti-odom-eval variant matching an evo alignment (origin -> none: it always aligns the
// first frames).
KittiAlignment KittiAlignmentFor(Alignment alignment);

struct EvalOptions {
  Alignment alignment = Alignment::kSe3;
  // Match poses by timestamp (TUM, EuRoC) or pose i to pose i (KITTI: sizes must be equal).
  bool associate_by_timestamp = true;
  // Without timestamps: match by frame index as kitti-odom-eval does (for indexed KITTI files,
  // whose indices may skip): every estimate index must exist in the ground truth, ground-truth
  // poses without an estimate are left out. The timestamps of both series are the indices.
  bool associate_by_frame_index = false;
  double max_diff = 0.01;  // seconds, evo's default for TUM
  double rpe_delta = 1.0;
  DeltaUnit rpe_unit = DeltaUnit::kFrames;
  bool rpe_pairs_from_reference = false;  // evo --pairs_from_reference
  bool kitti_metrics = false;
  KittiAlignment kitti_alignment = KittiAlignment::kSixDof;
  // Throws std::invalid_argument describing the first bad option.
  void Check() const;
};

struct KittiOdometryResult {
  double t_rel_percent = 0;
  double r_rel_deg_per_100m = 0;
  double ate_m = 0;
  double rpe_m = 0;
  double rpe_deg = 0;
  size_t segments = 0;  // number of (start frame, length) sub-sequences averaged
};

struct EvalResult {
  size_t gt_poses = 0, est_poses = 0, matched_poses = 0;
  Alignment alignment = Alignment::kNone;
  Similarity gt_from_est;  // the alignment applied to the estimate
  ErrorStats ape;          // metres
  std::vector<double> ape_errors;
  ErrorStats rpe_trans;    // metres
  ErrorStats rpe_rot_deg;  // degrees
  double rpe_delta = 1.0;
  DeltaUnit rpe_unit = DeltaUnit::kFrames;
  std::optional<KittiOdometryResult> kitti;
  KittiAlignment kitti_alignment = KittiAlignment::kNone;
  PoseSeries gt_matched;   // associated ground truth
  PoseSeries est_aligned;  // associated estimate after alignment
};

// Throws InputError-free std::invalid_argument / std::runtime_error on unusable input (no
// matching timestamps, different KITTI lengths, too few poses to align); callers that know the
// file names (the CLI) add them.
EvalResult EvaluateTrajectories(const PoseSeries& gt, const PoseSeries& est,
                                const EvalOptions& options);
EvalResult EvaluateTrajectories(const Trajectory& gt, const Trajectory& est,
                                const EvalOptions& options);

// kitti-odom-eval on index-matched poses (gt[i] <-> est[i], equal sizes).
KittiOdometryResult EvaluateKittiOdometry(std::vector<Eigen::Matrix4d> gt,
                                          std::vector<Eigen::Matrix4d> est,
                                          KittiAlignment alignment);
// kitti-odom-eval on poses keyed by frame index, the estimate's indices possibly skipping.
// `gt_index` must be 0, 1, ..., N-1 (kitti-odom-eval indexes its path distances by position and
// looks poses up by key, which agree only then); `est_index` strictly increasing, each < N.
// As kitti-odom-eval: only the ground-truth poses with an estimate are moved to the first
// estimated frame; segments count only when both end frames were estimated; ATE over the
// estimated frames. RPE uses the consecutive index pairs (i, i + 1) that were both estimated
// (kitti-odom-eval itself stops with a KeyError when i + 1 is missing).
KittiOdometryResult EvaluateKittiOdometry(const std::vector<int64_t>& gt_index,
                                          std::vector<Eigen::Matrix4d> gt,
                                          const std::vector<int64_t>& est_index,
                                          std::vector<Eigen::Matrix4d> est,
                                          KittiAlignment alignment);

// A trajectory file as `ademono eval` reads it: `format_name` "auto" (detected from the first data
// line) or a TrajectoryFormat name. InputError naming the file when it cannot be read.
struct TrajectoryFile {
  std::string path;
  PoseSeries poses;
  bool detected = false;  // the format was detected, not given
};
TrajectoryFile LoadTrajectoryFile(const std::string& path, const std::string& format_name = "auto");
// `ademono eval` on two files: files without timestamps (KITTI) match pose i to pose i, or by
// the written frame index as soon as one file is indexed; the rest by timestamp (`options`'
// association flags are set from the files). InputError naming both files when they cannot be
// compared. `ademono batch` scores its runs through this too.
EvalResult EvaluateTrajectoryFiles(const TrajectoryFile& gt, const TrajectoryFile& est,
                                   EvalOptions options);

nlohmann::json ToJson(const ErrorStats& stats);
// Keys: ape, rpe_trans, rpe_rot_deg (rmse/mean/median/max/min/std), matched_poses, alignment,
// scale (sim3), rpe_delta, rpe_unit, kitti (t_rel_percent, r_rel_deg_per_100m, ate_m, rpe_m,
// rpe_deg, alignment) when computed.
nlohmann::json ToJson(const EvalResult& result);
// Human-readable multi-line summary.
std::string FormatReport(const EvalResult& result);

}  // namespace ademono
