#pragma once
// The two engines. Both run exactly the command lines of tasks.h, so their outputs are the same:
// - local: a pool of child processes of the same binary, `jobs` at a time; a run starts once
//   the caches it reads are done;
// - slurm: one job array for the caches and one for the runs (`sbatch --array`), the second
//   waiting for the first (`--dependency=afterok`); each array task is an ordinary
//   `ademono infer` / `ademono run` command line in the job script.

#include <atomic>
#include <filesystem>
#include <functional>
#include <set>
#include <string>
#include <vector>

#include "ademono/batch/plan.h"
#include "ademono/batch/tasks.h"

namespace ademono::batch {

struct TaskOutcome {
  std::string id;
  int exit_code = 0;
  bool complete = false;  // IsComplete after it ended
  std::string note;       // why it did not run or failed
  double seconds = 0;
};

// Runs `tasks` (caches and runs; a run waits for the caches it needs among them and is skipped
// when one of them fails) with at most `jobs` at once. `report` gets one line per ended task.
// Once `*stop` holds a signal number, nothing more starts; SIGTERM is passed on to the running
// tasks (SIGINT from a terminal reached them already), which `run` answers by writing its
// partial outputs; the call returns when they have ended.
std::vector<TaskOutcome> RunLocal(const std::vector<const Task*>& tasks, int jobs,
                                  const std::function<void(const std::string&)>& report,
                                  const std::atomic<int>* stop = nullptr);
// The machine's CPU count (the local pool's default size).
int DefaultJobs();

struct Submission {
  std::string job_id;
  std::string kind;  // "cache" or "runs"
  std::filesystem::path script;
  std::vector<std::string> task_ids;  // array index -> task id
};

// The job script of one array: `#SBATCH` lines from `settings`, then a case over
// $SLURM_ARRAY_TASK_ID whose branch i execs task i's command with its output in its log.
std::string SlurmScript(const std::string& job_name, const std::vector<const Task*>& tasks,
                        const SlurmSettings& settings, const std::filesystem::path& slurm_dir,
                        const std::string& kind, int number);
// Writes the scripts and submits the cache array (if any) and the run array (if any), the runs
// after the caches. Records the submissions in DIR/slurm/submissions.json. std::runtime_error
// with sbatch's message when it refuses.
std::vector<Submission> SubmitSlurm(const Batch& batch, const std::vector<const Task*>& caches,
                                    const std::vector<const Task*>& runs,
                                    const SlurmSettings& settings);
// Every submission recorded in DIR/slurm/submissions.json.
std::vector<Submission> ReadSubmissions(const std::filesystem::path& dir);
// Ids of the tasks of `submissions` that Slurm still holds (pending or running).
std::set<std::string> InFlight(const std::vector<Submission>& submissions);
// Polls squeue until no task of `submissions` is pending or running; `report` gets a line
// whenever the count changes.
void WaitForSlurm(const std::vector<Submission>& submissions,
                  const std::function<void(const std::string&)>& report, double poll_seconds = 2);

}  // namespace ademono::batch
