#pragma once
// Trajectory files. Every pose is `world_from_cam` (camera-to-world), as TUM, KITTI and EuRoC
// ground truth store them.
// - TUM:   "timestamp tx ty tz qx qy qz qw" per line, '#' comments.
// - KITTI: 12 numbers per line, row-major 3x4 [R|t] of world_from_cam; no timestamps (the
//          reader numbers poses 0, 1, 2, ... unless times are given).
// - indexed KITTI (kitti-odom-eval): a frame index, then the 12 numbers. Indices may skip; the
//          reader sorts by index and uses the index as the pose's "timestamp".
// - ORB-SLAM's KeyFrameTrajectory.txt and CameraTrajectory.txt (TUM variant) are TUM files.
// - EuRoC: CSV "timestamp_ns, px, py, pz, qw, qx, qy, qz[, ...]" (state_groundtruth_estimate0).
// Readers throw InputError "file:line: problem" for malformed lines (field count, non-numeric,
// NaN) and for an empty file. Writers write atomically (temp file + rename).

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "ademono/core/geometry.h"

namespace ademono {

struct StampedPose {
  double timestamp = 0.0;  // seconds
  Rigid3d world_from_cam = Rigid3d::Identity();
};
using Trajectory = std::vector<StampedPose>;

enum class TrajectoryFormat { kTum, kKitti, kEuroc, kKittiIndexed };
// "tum" | "orbslam" (= tum) | "kitti" | "kitti-indexed" | "euroc"; std::invalid_argument
// otherwise.
TrajectoryFormat ParseTrajectoryFormat(const std::string& name);
std::string ToString(TrajectoryFormat format);

// Guesses the format from the first data line (comments and blank lines skipped): commas ->
// EuRoC CSV, 8 fields -> TUM, 12 -> KITTI, 13 -> indexed KITTI. InputError "file:line: ..." when
// none fits, "file: trajectory file has no poses" when there is no data line.
TrajectoryFormat DetectTrajectoryFormat(const std::filesystem::path& path);

// KITTI rows as written, without re-orthonormalising: `index[i]` is the frame index (the line
// number from 0 for plain files), `rows[i]` the 3x4 [R|t]. With `accept_index` the first data
// line decides between plain (12 fields) and indexed (13 fields); every line must then match.
// Indexed rows are sorted by index; an index that is negative, not whole or repeated is an
// InputError naming the line.
struct KittiRows {
  bool indexed = false;
  std::vector<int64_t> index;
  std::vector<Eigen::Matrix<double, 3, 4>> rows;
};
KittiRows ReadKittiRows(const std::filesystem::path& path, bool accept_index,
                        bool require_index = false);

Trajectory ReadTumTrajectory(const std::filesystem::path& path);
Trajectory ReadKittiTrajectory(const std::filesystem::path& path);
Trajectory ReadEurocTrajectory(const std::filesystem::path& path);
// Timestamps are the frame indices.
Trajectory ReadKittiIndexedTrajectory(const std::filesystem::path& path);
Trajectory ReadTrajectory(const std::filesystem::path& path, TrajectoryFormat format);

// The TUM file's header line and one pose line ("timestamp tx ty tz qx qy qz qw\n"), for writers
// that stream a trajectory line by line (run --live-trajectory).
extern const char kTumHeader[];
std::string FormatTumLine(const StampedPose& pose);
void WriteTumTrajectory(const std::filesystem::path& path, const Trajectory& trajectory);
void WriteKittiTrajectory(const std::filesystem::path& path, const Trajectory& trajectory);
void WriteEurocTrajectory(const std::filesystem::path& path, const Trajectory& trajectory);
// Frame index = the timestamp rounded to a whole number.
void WriteKittiIndexedTrajectory(const std::filesystem::path& path, const Trajectory& trajectory);
void WriteTrajectory(const std::filesystem::path& path, const Trajectory& trajectory,
                     TrajectoryFormat format);

}  // namespace ademono
