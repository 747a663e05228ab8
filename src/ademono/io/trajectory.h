#pragma once
// Trajectory files. Every pose is `world_from_cam` (camera-to-world), as TUM, KITTI and EuRoC
// ground truth store them.
// - TUM:   "timestamp tx ty tz qx qy qz qw" per line, '#' comments.
// - KITTI: 12 numbers per line, row-major 3x4 [R|t] of world_from_cam; no timestamps (the
//          reader numbers poses 0, 1, 2, ... unless times are given).
// - EuRoC: CSV "timestamp_ns, px, py, pz, qw, qx, qy, qz[, ...]" (state_groundtruth_estimate0).
// Readers throw InputError "file:line: problem" for malformed lines (field count, non-numeric,
// NaN) and for an empty file. Writers write atomically (temp file + rename).

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

enum class TrajectoryFormat { kTum, kKitti, kEuroc };
// "tum" | "kitti" | "euroc"; throws std::invalid_argument otherwise.
TrajectoryFormat ParseTrajectoryFormat(const std::string& name);

Trajectory ReadTumTrajectory(const std::filesystem::path& path);
Trajectory ReadKittiTrajectory(const std::filesystem::path& path);
Trajectory ReadEurocTrajectory(const std::filesystem::path& path);
Trajectory ReadTrajectory(const std::filesystem::path& path, TrajectoryFormat format);

void WriteTumTrajectory(const std::filesystem::path& path, const Trajectory& trajectory);
void WriteKittiTrajectory(const std::filesystem::path& path, const Trajectory& trajectory);
void WriteEurocTrajectory(const std::filesystem::path& path, const Trajectory& trajectory);
void WriteTrajectory(const std::filesystem::path& path, const Trajectory& trajectory,
                     TrajectoryFormat format);

}  // namespace ademono
