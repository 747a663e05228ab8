#include "ademono/runner/run_writer.h"

#include <cstdio>

#include "ademono/core/file_util.h"
#include "ademono/io/trajectory.h"

namespace fs = std::filesystem;

namespace ademono {

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

void WriteRunOutputs(const RunReport& report, const fs::path& out_dir) {
  fs::create_directories(out_dir);
  WriteTumTrajectory(out_dir / "trajectory.tum", report.trajectory);
  WriteKittiTrajectory(out_dir / "trajectory.kitti", report.trajectory);
  WriteTumTrajectory(out_dir / "keyframes.tum", report.keyframe_trajectory);
  WritePly(out_dir / "map.ply", report.map_cloud);
  if (!report.ground_truth.empty())
    WriteTumTrajectory(out_dir / "groundtruth.tum", report.ground_truth);
  // The options as run (defaults and command-line switches resolved): `--config` of this file
  // repeats the run exactly.
  WriteResolvedConfig(out_dir / "config.resolved.yaml", report.options, report.detector_options);
  WriteTextFileAtomic(out_dir / "summary.json", RunSummaryJson(report).dump(2) + "\n");
}

}  // namespace ademono
