#pragma once
// A plan expanded into tasks: `ademono infer` caches (one per dataset and network) and
// `ademono run` invocations (one per dataset x variant x seed), each with its output folder and
// its log. The same command lines run under every engine, so their outputs are the same.
//
// Layout of the batch folder DIR:
//   DIR/batch.json                   the expanded plan (what --collect and a restart read)
//   DIR/cache/<dataset>/<network>/   `ademono infer` outputs, shared by every variant and seed
//   DIR/runs/<dataset>__<variant>__s<seed>/   one `ademono run` folder each
//   DIR/logs/<task id>.log           stdout and stderr of each task
//   DIR/slurm/                       the job scripts and the submissions (engine slurm)
//   DIR/results.{csv,md}, DIR/summary.{csv,md}, DIR/report.html   (collect.h)

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "ademono/batch/plan.h"

namespace ademono::batch {

struct Task {
  enum class Kind { kCache, kRun };
  Kind kind = Kind::kRun;
  std::string id;                 // unique in the batch; names the log
  std::vector<std::string> argv;  // argv[0]: the ademono binary
  std::filesystem::path out;      // the run folder or the cache folder
  std::filesystem::path log;
  std::vector<std::string> needs;  // ids of the cache tasks this run reads
  // Runs: what the row of the table says.
  std::string dataset, variant, seed;
  // Caches: the file or folder `infer` leaves when done (depth/ or detections.jsonl).
  std::filesystem::path product;
};

struct Batch {
  std::string plan_name;
  std::filesystem::path plan_file, dir;
  std::vector<Task> caches;  // in plan order
  std::vector<Task> runs;    // datasets x variants x seeds, in plan order
  const Task* Find(const std::string& id) const;
  nlohmann::json ToJson() const;
  static Batch FromJson(const nlohmann::json& j);
};

// Expands `plan` into tasks writing below `dir` (made absolute), run by `ademono_binary`.
Batch ExpandPlan(const Plan& plan, const std::filesystem::path& dir,
                 const std::filesystem::path& ademono_binary);

// DIR/batch.json: read (InputError naming it when missing or malformed) and written atomically.
Batch ReadBatch(const std::filesystem::path& dir);
void WriteBatch(const Batch& batch);
// A new expansion over the same folder must not change the command of a run already done there:
// InputError naming the folder and the first such run.
void CheckCompatible(const Batch& before, const Batch& now);

// Done means the outputs are there and whole: a run's summary.json (written last, atomically, by
// `run`) without "partial": true, a cache's product (moved into place last by `infer`).
bool IsComplete(const Task& task);

// One shell word (single-quoted unless it is plain), for job scripts and logs.
std::string ShellQuote(const std::string& word);
std::string ShellCommand(const std::vector<std::string>& argv);

// The ademono binary of this process (/proc/self/exe).
std::filesystem::path SelfBinary();

}  // namespace ademono::batch
