#include "ademono/runner/run_writer.h"

#include <unistd.h>

#include <cstdio>
#include <string>

#include "ademono/core/error.h"
#include "ademono/core/file_util.h"
#include "ademono/io/trajectory.h"

namespace fs = std::filesystem;

namespace ademono {
namespace {

constexpr const char* kStagingPrefix = ".staging.";

// Every file a run folder may hold, in commit order: summary.json last (the commit mark),
// report.html is written from the committed files afterwards (cmd_run).
constexpr const char* kOutputs[] = {"trajectory.tum", "trajectory.kitti", "keyframes.tum",
                                    "map.ply",        "groundtruth.tum",  "config.resolved.yaml",
                                    "summary.json"};

void RenameOrThrow(const fs::path& from, const fs::path& to) {
  std::error_code ec;
  fs::rename(from, to, ec);
  if (ec) ThrowInputError(to, "cannot move into place: " + ec.message());
}

}  // namespace

void WritePly(const fs::path& path, const std::vector<System::ColoredPoint>& cloud) {
  WriteFileAtomic(path, [&](std::ostream& os) {
    os << "ply\nformat ascii 1.0\nelement vertex " << cloud.size()
       << "\nproperty float x\nproperty float y\nproperty float z\n"
          "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n";
    char line[128];
    for (const auto& p : cloud) {
      std::snprintf(line, sizeof(line), "%.6f %.6f %.6f %d %d %d\n", p.position.x(), p.position.y(),
                    p.position.z(), p.bgr[2], p.bgr[1], p.bgr[0]);
      os << line;
    }
  });
}

bool IsStagingEntry(const fs::path& entry) {
  return entry.filename().string().rfind(kStagingPrefix, 0) == 0;
}

void RemoveStaleStaging(const fs::path& out_dir) {
  std::error_code ec;
  if (!fs::is_directory(out_dir, ec)) return;
  for (const auto& entry : fs::directory_iterator(out_dir, ec)) {
    if (IsStagingEntry(entry.path())) fs::remove_all(entry.path(), ec);
  }
}

void WriteRunOutputs(const RunReport& report, const fs::path& out_dir) {
  // Everything is written and fsynced in a staging folder first, then renamed into place one
  // file at a time (rename is atomic), summary.json last: a kill at any moment leaves every
  // output either complete (this run's or the previous run's) or absent, and a folder whose
  // summary.json is this run's holds this run's complete set.
  const fs::path staging = out_dir / (kStagingPrefix + std::to_string(::getpid()));
  std::error_code ec;
  fs::remove_all(staging, ec);
  fs::create_directories(staging, ec);
  if (ec) ThrowInputError(staging, "cannot create directory: " + ec.message());
  WriteTumTrajectory(staging / "trajectory.tum", report.trajectory);
  WriteKittiTrajectory(staging / "trajectory.kitti", report.trajectory);
  WriteTumTrajectory(staging / "keyframes.tum", report.keyframe_trajectory);
  WritePly(staging / "map.ply", report.map_cloud);
  if (!report.ground_truth.empty())
    WriteTumTrajectory(staging / "groundtruth.tum", report.ground_truth);
  // The options as run (defaults and command-line switches resolved): `--config` of this file
  // repeats the run exactly.
  WriteResolvedConfig(staging / "config.resolved.yaml", report.options, report.detector_options);
  WriteTextFileAtomic(staging / "summary.json", RunSummaryJson(report).dump(2) + "\n");
  for (const char* name : kOutputs) {
    if (fs::exists(staging / name)) SyncFile(staging / name);
  }

  // Commit. The previous run's summary.json and report.html go first, so they never describe a
  // mix of two runs' files.
  fs::remove(out_dir / "summary.json", ec);
  fs::remove(out_dir / "report.html", ec);
  for (const char* name : kOutputs) {
    if (fs::exists(staging / name)) {
      RenameOrThrow(staging / name, out_dir / name);
    } else {
      fs::remove(out_dir / name, ec);  // a previous run's file this run does not have
    }
  }
  SyncDirectory(out_dir);
  fs::remove_all(staging, ec);
}

}  // namespace ademono
