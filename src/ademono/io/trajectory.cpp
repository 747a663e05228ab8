#include "ademono/io/trajectory.h"

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <optional>
#include <stdexcept>

#include "ademono/core/error.h"
#include "ademono/core/file_util.h"

namespace fs = std::filesystem;

namespace ademono {

namespace {

void RequireFieldCount(const fs::path& path, size_t line,
                       const std::vector<std::string_view>& fields, size_t expected,
                       bool at_least = false) {
  const bool ok = at_least ? fields.size() >= expected : fields.size() == expected;
  if (!ok) {
    ThrowInputError(path, line,
                    "expected " + std::string(at_least ? "at least " : "") +
                        std::to_string(expected) + " fields, found " +
                        std::to_string(fields.size()));
  }
}

// Quaternions in files are rarely exactly unit; a zero one is not a rotation at all.
Eigen::Quaterniond CheckedQuaternion(double w, double x, double y, double z, const fs::path& path,
                                     size_t line) {
  Eigen::Quaterniond q(w, x, y, z);
  if (q.norm() < 1e-6) ThrowInputError(path, line, "quaternion has zero norm");
  return q.normalized();
}

void RequireNonEmpty(const fs::path& path, const Trajectory& trajectory) {
  if (trajectory.empty()) ThrowInputError(path, "trajectory file has no poses");
}

std::string FormatPoseRow(const Rigid3d& world_from_cam) {
  const Eigen::Matrix4d m = world_from_cam.matrix();
  std::string row;
  char buf[64];
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) {
      std::snprintf(buf, sizeof(buf), "%.9e", m(r, c));
      if (!row.empty()) row += ' ';
      row += buf;
    }
  }
  return row;
}

}  // namespace

TrajectoryFormat ParseTrajectoryFormat(const std::string& name) {
  if (name == "tum" || name == "orbslam") return TrajectoryFormat::kTum;
  if (name == "kitti") return TrajectoryFormat::kKitti;
  if (name == "kitti-indexed") return TrajectoryFormat::kKittiIndexed;
  if (name == "euroc") return TrajectoryFormat::kEuroc;
  throw std::invalid_argument("unknown trajectory format '" + name +
                              "' (expected tum, orbslam, kitti, kitti-indexed or euroc)");
}

std::string ToString(TrajectoryFormat format) {
  switch (format) {
    case TrajectoryFormat::kTum:
      return "tum";
    case TrajectoryFormat::kKitti:
      return "kitti";
    case TrajectoryFormat::kKittiIndexed:
      return "kitti-indexed";
    case TrajectoryFormat::kEuroc:
      return "euroc";
  }
  return "?";
}

TrajectoryFormat DetectTrajectoryFormat(const fs::path& path) {
  RequireFile(path);
  std::ifstream in(path);
  if (!in) ThrowInputError(path, "cannot open for reading");
  std::string text;
  size_t number = 0;
  while (std::getline(in, text)) {
    ++number;
    const auto fields = SplitFields(text, false);
    if (fields.empty() || fields.front().front() == '#') continue;
    if (text.find(',') != std::string::npos) return TrajectoryFormat::kEuroc;
    switch (fields.size()) {
      case 8:
        return TrajectoryFormat::kTum;
      case 12:
        return TrajectoryFormat::kKitti;
      case 13:
        return TrajectoryFormat::kKittiIndexed;
      default:
        ThrowInputError(path, number,
                        "cannot tell the trajectory format from " + std::to_string(fields.size()) +
                            " fields (TUM has 8, KITTI 12, indexed KITTI 13, EuRoC is CSV)");
    }
  }
  ThrowInputError(path, "trajectory file has no poses");
}

KittiRows ReadKittiRows(const fs::path& path, bool accept_index, bool require_index) {
  KittiRows out;
  std::optional<bool> indexed;
  if (require_index) indexed = true;
  std::map<int64_t, size_t> line_of_index;
  std::vector<std::pair<int64_t, Eigen::Matrix<double, 3, 4>>> read;
  ForEachDataLine(path, false, [&](size_t line, const std::vector<std::string_view>& f) {
    if (!indexed) indexed = accept_index && f.size() == 13;
    if (*indexed && f.size() != 13) {
      ThrowInputError(
          path, line,
          "expected 13 fields (frame index and 12 pose values), found " + std::to_string(f.size()));
    }
    if (!*indexed) RequireFieldCount(path, line, f, 12);
    const size_t offset = *indexed ? 1 : 0;
    int64_t index = static_cast<int64_t>(read.size());
    if (*indexed) {
      const double v = ParseDouble(f[0], path, line, 0);
      if (v < 0 || v != std::floor(v) || v > 1e15) {
        ThrowInputError(path, line,
                        "frame index '" + std::string(f[0]) + "' is not a whole number >= 0");
      }
      index = static_cast<int64_t>(v);
      const auto [it, inserted] = line_of_index.emplace(index, line);
      if (!inserted) {
        ThrowInputError(path, line,
                        "frame index " + std::to_string(index) + " already on line " +
                            std::to_string(it->second));
      }
    }
    Eigen::Matrix<double, 3, 4> m;
    for (size_t i = 0; i < 12; ++i) {
      m(static_cast<Eigen::Index>(i / 4), static_cast<Eigen::Index>(i % 4)) =
          ParseDouble(f[i + offset], path, line, i + offset);
    }
    if (std::abs(m.leftCols<3>().determinant()) < 1e-6) {
      ThrowInputError(path, line, "rotation part is singular");
    }
    read.emplace_back(index, m);
  });
  if (read.empty()) ThrowInputError(path, "trajectory file has no poses");
  // kitti-odom-eval keys poses by index and walks them sorted.
  std::stable_sort(read.begin(), read.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  out.indexed = indexed.value_or(false);
  for (auto& [index, m] : read) {
    out.index.push_back(index);
    out.rows.push_back(m);
  }
  return out;
}

Trajectory ReadTumTrajectory(const fs::path& path) {
  Trajectory trajectory;
  ForEachDataLine(path, false, [&](size_t line, const std::vector<std::string_view>& f) {
    RequireFieldCount(path, line, f, 8);
    double v[8];
    for (size_t i = 0; i < 8; ++i) v[i] = ParseDouble(f[i], path, line, i);
    StampedPose pose;
    pose.timestamp = v[0];
    pose.world_from_cam =
        MakeRigid3d(CheckedQuaternion(v[7], v[4], v[5], v[6], path, line), {v[1], v[2], v[3]});
    trajectory.push_back(pose);
  });
  RequireNonEmpty(path, trajectory);
  return trajectory;
}

Trajectory ReadKittiTrajectory(const fs::path& path) {
  Trajectory trajectory;
  ForEachDataLine(path, false, [&](size_t line, const std::vector<std::string_view>& f) {
    RequireFieldCount(path, line, f, 12);
    Eigen::Matrix<double, 3, 4> m;
    for (size_t i = 0; i < 12; ++i) m(i / 4, i % 4) = ParseDouble(f[i], path, line, i);
    if (std::abs(m.leftCols<3>().determinant()) < 1e-6) {
      ThrowInputError(path, line, "rotation part is singular");
    }
    StampedPose pose;
    pose.timestamp = static_cast<double>(trajectory.size());
    pose.world_from_cam = MakeRigid3d(m);
    trajectory.push_back(pose);
  });
  RequireNonEmpty(path, trajectory);
  return trajectory;
}

Trajectory ReadKittiIndexedTrajectory(const fs::path& path) {
  const KittiRows rows = ReadKittiRows(path, true, /*require_index=*/true);
  Trajectory trajectory(rows.rows.size());
  for (size_t i = 0; i < rows.rows.size(); ++i) {
    trajectory[i].timestamp = static_cast<double>(rows.index[i]);
    trajectory[i].world_from_cam = MakeRigid3d(rows.rows[i]);
  }
  return trajectory;
}

Trajectory ReadEurocTrajectory(const fs::path& path) {
  Trajectory trajectory;
  ForEachDataLine(path, true, [&](size_t line, const std::vector<std::string_view>& f) {
    RequireFieldCount(path, line, f, 8, /*at_least=*/true);
    double v[8];
    for (size_t i = 0; i < 8; ++i) v[i] = ParseDouble(f[i], path, line, i);
    StampedPose pose;
    pose.timestamp = v[0] * 1e-9;
    pose.world_from_cam =
        MakeRigid3d(CheckedQuaternion(v[4], v[5], v[6], v[7], path, line), {v[1], v[2], v[3]});
    trajectory.push_back(pose);
  });
  RequireNonEmpty(path, trajectory);
  return trajectory;
}

Trajectory ReadTrajectory(const fs::path& path, TrajectoryFormat format) {
  switch (format) {
    case TrajectoryFormat::kTum:
      return ReadTumTrajectory(path);
    case TrajectoryFormat::kKitti:
      return ReadKittiTrajectory(path);
    case TrajectoryFormat::kEuroc:
      return ReadEurocTrajectory(path);
    case TrajectoryFormat::kKittiIndexed:
      return ReadKittiIndexedTrajectory(path);
  }
  throw std::invalid_argument("unknown trajectory format");
}

const char kTumHeader[] = "# timestamp tx ty tz qx qy qz qw (world_from_cam)\n";

std::string FormatTumLine(const StampedPose& pose) {
  const Eigen::Quaterniond q(pose.world_from_cam.linear());
  const Eigen::Vector3d t = pose.world_from_cam.translation();
  char buf[256];
  std::snprintf(buf, sizeof(buf), "%.9f %.9f %.9f %.9f %.9f %.9f %.9f %.9f\n", pose.timestamp,
                t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w());
  return buf;
}

void WriteTumTrajectory(const fs::path& path, const Trajectory& trajectory) {
  WriteFileAtomic(path, [&](std::ostream& out) {
    out << kTumHeader;
    for (const auto& pose : trajectory) out << FormatTumLine(pose);
  });
}

void WriteKittiTrajectory(const fs::path& path, const Trajectory& trajectory) {
  WriteFileAtomic(path, [&](std::ostream& out) {
    for (const auto& pose : trajectory) out << FormatPoseRow(pose.world_from_cam) << '\n';
  });
}

void WriteKittiIndexedTrajectory(const fs::path& path, const Trajectory& trajectory) {
  WriteFileAtomic(path, [&](std::ostream& out) {
    for (const auto& pose : trajectory) {
      out << std::llround(pose.timestamp) << ' ' << FormatPoseRow(pose.world_from_cam) << '\n';
    }
  });
}

void WriteEurocTrajectory(const fs::path& path, const Trajectory& trajectory) {
  WriteFileAtomic(path, [&](std::ostream& out) {
    out << "#timestamp [ns],p_x [m],p_y [m],p_z [m],q_w [],q_x [],q_y [],q_z []\n";
    char buf[256];
    for (const auto& pose : trajectory) {
      const Eigen::Quaterniond q(pose.world_from_cam.linear());
      const Eigen::Vector3d t = pose.world_from_cam.translation();
      const auto ns = static_cast<int64_t>(std::llround(pose.timestamp * 1e9));
      std::snprintf(buf, sizeof(buf), "%" PRId64 ",%.9f,%.9f,%.9f,%.9f,%.9f,%.9f,%.9f\n", ns, t.x(),
                    t.y(), t.z(), q.w(), q.x(), q.y(), q.z());
      out << buf;
    }
  });
}

void WriteTrajectory(const fs::path& path, const Trajectory& trajectory, TrajectoryFormat format) {
  switch (format) {
    case TrajectoryFormat::kTum:
      return WriteTumTrajectory(path, trajectory);
    case TrajectoryFormat::kKitti:
      return WriteKittiTrajectory(path, trajectory);
    case TrajectoryFormat::kEuroc:
      return WriteEurocTrajectory(path, trajectory);
    case TrajectoryFormat::kKittiIndexed:
      return WriteKittiIndexedTrajectory(path, trajectory);
  }
}

}  // namespace ademono
