// `ademono batch`: a plan of datasets x variants x seeds run as `ademono infer` / `ademono run`
// command lines by a local process pool or as Slurm job arrays, then one table and one comparison
// report (`--collect DIR` for a Slurm job that outlived the shell). The work is in
// src/ademono/batch.
#include <atomic>
#include <csignal>
#include <iostream>
#include <set>
#include <string>
#include <vector>

#include "ademono/batch/collect.h"
#include "ademono/batch/engine.h"
#include "ademono/batch/plan.h"
#include "ademono/batch/process.h"
#include "ademono/batch/tasks.h"
#include "ademono/core/error.h"
#include "command.h"
#include "stop_signals.h"

namespace fs = std::filesystem;

namespace ademono::cli {
namespace {

struct BatchArgs {
  std::string plan, out, engine = "local", root, collect;
  int jobs = 0;
  std::string partition, time, mem;
  int cpus_per_task = 0;
  bool no_wait = false, dry_run = false;
};

void Say(const std::string& line) { std::cerr << "ademono batch: " << line << std::endl; }

// SIGINT / SIGTERM while the local engine runs: nothing more starts, the running tasks end
// (runs write partial outputs, which the next batch redoes), then the table of what is done.
std::atomic<int> g_stop{0};
extern "C" void OnBatchStopSignal(int signo) { g_stop.store(signo); }

// Writes the tables and the report; lists what is not done. 0 when every run is done.
int Collect(const batch::Batch& b, const std::set<std::string>& in_flight) {
  const batch::Collection c = batch::CollectBatch(b, in_flight);
  batch::WriteCollection(b, c);
  std::cout << batch::SummaryMarkdown(c);
  for (const batch::RunRow& r : c.runs) {
    if (r.status == "done") continue;
    std::cout << r.status << ": " << r.id << (r.status == "missing" ? "" : ", log: " + r.log)
              << "\n";
  }
  // A cache that failed is why its runs are missing (Slurm cancels runs whose caches failed).
  for (const batch::Task& t : b.caches) {
    if (!batch::IsComplete(t) && in_flight.count(t.id) == 0 && fs::exists(t.log))
      std::cout << "failed: " << t.id << ", log: " << t.log.string() << "\n";
  }
  std::cout << c.Count("done") << "/" << c.runs.size() << " runs done; tables in "
            << (b.dir / "results.md").string() << ", " << (b.dir / "results.csv").string() << ", "
            << (b.dir / "summary.csv").string()
            << (c.Count("done") > 0 ? ", report " + (b.dir / "report.html").string() : "") << "\n";
  return c.Count("done") == c.runs.size() ? 0 : 1;
}

std::set<std::string> HeldBySlurm(const fs::path& dir) {
  const std::vector<batch::Submission> submissions = batch::ReadSubmissions(dir);
  if (submissions.empty() || !batch::FindOnPath("squeue")) return {};
  return batch::InFlight(submissions);
}

int RunBatch(const BatchArgs& args) {
  if (!args.collect.empty()) {
    if (!args.plan.empty()) throw InputError("--collect DIR takes no plan");
    const batch::Batch b = batch::ReadBatch(args.collect);
    return Collect(b, HeldBySlurm(b.dir));
  }
  if (args.plan.empty()) throw InputError("give a plan: ademono batch PLAN.yaml --out DIR");
  if (args.out.empty()) throw InputError("--out DIR is required");
  // Everything is checked before anything is written or submitted.
  const batch::Plan plan = batch::LoadPlan(args.plan, args.root);
  const bool slurm = args.engine == "slurm";
  if (!slurm && args.engine != "local") {
    ThrowInputError(args.plan,
                    "engine '" + args.engine + "' is not there (expected local or slurm)");
  }
  if (slurm) {
    for (const char* program : {"sbatch", "squeue"}) {
      if (!batch::FindOnPath(program)) {
        ThrowInputError(args.plan, std::string("engine slurm is not there: ") + program +
                                       " not found on PATH (scripts/slurm_local.sh starts a "
                                       "Slurm on this machine)");
      }
    }
  }
  batch::Batch b = batch::ExpandPlan(plan, args.out, batch::SelfBinary());
  if (fs::exists(b.dir / "batch.json")) batch::CheckCompatible(batch::ReadBatch(b.dir), b);
  const std::set<std::string> held = HeldBySlurm(b.dir);
  if (!slurm && !held.empty()) {
    ThrowInputError(b.dir, std::to_string(held.size()) +
                               " of its tasks are still held by Slurm (squeue): wait for them or "
                               "scancel them first");
  }

  // What is left: runs neither complete nor held, and the caches they read.
  std::vector<const batch::Task*> runs, caches;
  std::set<std::string> needed;
  size_t done = 0;
  for (const batch::Task& t : b.runs) {
    if (batch::IsComplete(t)) {
      ++done;
    } else if (held.count(t.id) == 0) {
      runs.push_back(&t);
      needed.insert(t.needs.begin(), t.needs.end());
    }
  }
  for (const batch::Task& t : b.caches) {
    if (needed.count(t.id) != 0 && !batch::IsComplete(t) && held.count(t.id) == 0)
      caches.push_back(&t);
  }
  Say("plan " + plan.name + ": " + std::to_string(b.runs.size()) + " runs (" +
      std::to_string(plan.datasets.size()) + " datasets x " + std::to_string(plan.variants.size()) +
      " variants x " + std::to_string(plan.seeds.size()) + " seeds): " + std::to_string(done) +
      " done, " + std::to_string(held.size()) + " held by Slurm, " + std::to_string(runs.size()) +
      " to run, " + std::to_string(caches.size()) + " caches to compute");
  if (args.dry_run) {
    for (const auto* list : {&caches, &runs}) {
      for (const batch::Task* t : *list) std::cout << batch::ShellCommand(t->argv) << "\n";
    }
    return 0;
  }
  batch::WriteBatch(b);

  if (!slurm) {
    std::vector<const batch::Task*> tasks = caches;
    tasks.insert(tasks.end(), runs.begin(), runs.end());
    const int jobs = args.jobs > 0 ? args.jobs : plan.jobs > 0 ? plan.jobs : batch::DefaultJobs();
    if (!tasks.empty()) {
      Say("local engine, " + std::to_string(jobs) + " at a time");
      // No SA_RESTART: waitpid returns to look at the flag.
      const StopSignals signals(OnBatchStopSignal, 0);
      batch::RunLocal(tasks, jobs, Say, &g_stop);
    }
    const int collected = Collect(b, {});
    return g_stop.load() != 0 ? 128 + g_stop.load() : collected;
  }

  batch::SlurmSettings settings = plan.slurm;
  if (!args.partition.empty()) settings.partition = args.partition;
  if (!args.time.empty()) settings.time = args.time;
  if (!args.mem.empty()) settings.mem = args.mem;
  if (args.cpus_per_task > 0) settings.cpus_per_task = args.cpus_per_task;
  std::vector<batch::Submission> submissions;
  if (!caches.empty() || !runs.empty()) {
    try {
      submissions = batch::SubmitSlurm(b, caches, runs, settings);
    } catch (const std::runtime_error& e) {
      ThrowInputError(args.plan, e.what());
    }
  }
  for (const batch::Submission& s : submissions) {
    Say("submitted " + s.kind + " array " + s.job_id + " (" + std::to_string(s.task_ids.size()) +
        " tasks, " + s.script.string() + ")");
  }
  if (args.no_wait) {
    Say("not waiting; when Slurm is done: ademono batch --collect " + b.dir.string());
    return 0;
  }
  // Wait for what this call submitted and for what earlier ones still hold.
  batch::WaitForSlurm(batch::ReadSubmissions(b.dir), Say);
  return Collect(b, {});
}

const bool kRegistered = RegisterCommand(
    "batch",
    "Run a plan of datasets x variants x seeds locally or on Slurm, then one table and report",
    [](CLI::App& app) -> Runner {
      auto args = std::make_shared<BatchArgs>();
      app.add_option("plan", args->plan, "the plan (YAML, docs/batch.md)");
      app.add_option("--out", args->out, "the batch folder (runs, caches, logs, tables)");
      app.add_option("--engine", args->engine, "local (a process pool) or slurm (job arrays)")
          ->capture_default_str();
      app.add_option("--root", args->root, "the datasets' root (overrides the plan's root:)");
      app.add_option("--jobs", args->jobs, "local engine: runs at once (default: the CPU count)");
      app.add_option("--partition", args->partition, "slurm: partition (overrides the plan's)");
      app.add_option("--time", args->time, "slurm: time limit per task, e.g. 02:00:00");
      app.add_option("--mem", args->mem, "slurm: memory per task, e.g. 4G");
      app.add_option("--cpus-per-task", args->cpus_per_task, "slurm: CPUs per task");
      app.add_flag("--no-wait", args->no_wait,
                   "slurm: submit and return (collect later with --collect DIR)");
      app.add_flag("--dry-run", args->dry_run, "print the commands left to run, run nothing");
      app.add_option("--collect", args->collect,
                     "write the tables and report of batch folder DIR (no plan)");
      return [args] { return RunBatch(*args); };
    });

}  // namespace
}  // namespace ademono::cli
