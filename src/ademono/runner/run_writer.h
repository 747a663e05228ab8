#pragma once
// The one writer of a run folder, used by `ademono run` and by every `ademono ablate` variant:
//   trajectory.tum, trajectory.kitti  one pose per tracked frame (world = first camera)
//   keyframes.tum                     keyframe poses at the end of the run
//   map.ply                           ASCII, x y z red green blue
//   groundtruth.tum                   the dataset's poses associated with trajectory.tum
//                                     (only with ground truth; unaligned)
//   summary.json                      RunSummaryJson (schema "ademono.run/1", docs/slam.md)
// Each file is written atomically (temp file + rename); summary.json last.

#include <filesystem>
#include <vector>

#include "ademono/runner/run.h"
#include "ademono/slam/system.h"

namespace ademono {

void WriteRunOutputs(const RunReport& report, const std::filesystem::path& out_dir);

void WritePly(const std::filesystem::path& path, const std::vector<System::ColoredPoint>& cloud);

}  // namespace ademono
