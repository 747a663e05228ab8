#include "ademono/io/trajectory.h"

#include <cinttypes>
#include <cmath>
#include <cstdio>
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
  if (name == "tum") return TrajectoryFormat::kTum;
  if (name == "kitti") return TrajectoryFormat::kKitti;
  if (name == "euroc") return TrajectoryFormat::kEuroc;
  throw std::invalid_argument("unknown trajectory format '" + name +
                              "' (expected tum, kitti or euroc)");
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
  }
  throw std::invalid_argument("unknown trajectory format");
}

void WriteTumTrajectory(const fs::path& path, const Trajectory& trajectory) {
  WriteFileAtomic(path, [&](std::ostream& out) {
    out << "# timestamp tx ty tz qx qy qz qw (world_from_cam)\n";
    char buf[256];
    for (const auto& pose : trajectory) {
      const Eigen::Quaterniond q(pose.world_from_cam.linear());
      const Eigen::Vector3d t = pose.world_from_cam.translation();
      std::snprintf(buf, sizeof(buf), "%.9f %.9f %.9f %.9f %.9f %.9f %.9f %.9f\n", pose.timestamp,
                    t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w());
      out << buf;
    }
  });
}

void WriteKittiTrajectory(const fs::path& path, const Trajectory& trajectory) {
  WriteFileAtomic(path, [&](std::ostream& out) {
    for (const auto& pose : trajectory) out << FormatPoseRow(pose.world_from_cam) << '\n';
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
  }
}

}  // namespace ademono
