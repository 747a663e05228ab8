#pragma once
// The one writer of a run folder, used by `ademono run` and by every `ademono ablate` variant:
//   trajectory.tum, trajectory.kitti  one pose per tracked frame (world = first camera)
//   keyframes.tum                     keyframe poses at the end of the run
//   map.ply                           ASCII, x y z red green blue
//   groundtruth.tum                   the dataset's poses associated with trajectory.tum
//                                     (only with ground truth; unaligned)
//   summary.json                      RunSummaryJson (schema "ademono.run/1", docs/slam.md)
//   config.resolved.yaml              the options as run
// Kill-safe: all files are written and fsynced in DIR/.staging.<pid>/, then renamed into DIR one
// by one, summary.json last; a SIGKILL at any moment leaves each file complete or absent.

#include <filesystem>
#include <vector>

#include "ademono/runner/run.h"
#include "ademono/slam/system.h"

namespace ademono {

void WriteRunOutputs(const RunReport& report, const std::filesystem::path& out_dir);

// A staging folder a killed run left behind (DIR/.staging.<pid>): not an output; removed by
// RemoveStaleStaging, ignored when deciding whether a folder already holds outputs.
bool IsStagingEntry(const std::filesystem::path& entry);
void RemoveStaleStaging(const std::filesystem::path& out_dir);

void WritePly(const std::filesystem::path& path, const std::vector<System::ColoredPoint>& cloud);

}  // namespace ademono
