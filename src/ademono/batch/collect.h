#pragma once
// One result for a batch: every run's row, scored through `ademono eval`'s code
// (EvaluateTrajectoryFiles on the run folder's groundtruth.tum and trajectory.tum), the mean,
// spread and worst case over seeds, and one comparison report of the runs side by side.
//   DIR/results.csv                   one row per run
//   DIR/summary.csv                   one row per dataset x variant, over its seeds
//   DIR/results.md                    both tables in Markdown
//   DIR/report.html                   report/report.h's comparison of the done runs
// frames/s is the last column of each table: it is the one figure that depends on the machine.

#include <optional>
#include <set>
#include <string>
#include <vector>

#include "ademono/batch/tasks.h"

namespace ademono::batch {

struct RunRow {
  std::string id, dataset, variant, seed;
  std::string status;  // done | failed | running | missing
  std::string log;
  size_t frames = 0, tracked = 0, keyframes = 0;
  std::optional<double> ate_se3, ate_sim3, sim3_scale, rpe;  // m; rpe over 30 frames (se3)
  double fps = 0;
};

struct GroupRow {
  std::string dataset, variant;
  size_t runs = 0, done = 0;
  size_t worst_tracked = 0, frames = 0;  // the seed that tracked fewest
  std::optional<double> se3_mean, se3_std, se3_max, sim3_mean, sim3_std, sim3_max, scale_mean,
      rpe_mean, rpe_max;
  double keyframes_mean = 0, fps_mean = 0;
};

struct Collection {
  std::vector<RunRow> runs;
  std::vector<GroupRow> groups;
  size_t Count(const std::string& status) const;
};

// Rows for every run of `batch`: "done" (complete outputs), "running" (`in_flight`: Slurm still
// holds it), "failed" (it left a log but no complete outputs) or "missing" (never started).
Collection CollectBatch(const Batch& batch, const std::set<std::string>& in_flight = {});
std::string ResultsCsv(const Collection& c);
std::string ResultsMarkdown(const Collection& c);
std::string SummaryCsv(const Collection& c);
std::string SummaryMarkdown(const Collection& c);
// Writes the tables and report.html (of the done runs) into the batch folder, atomically.
void WriteCollection(const Batch& batch, const Collection& c);

}  // namespace ademono::batch
