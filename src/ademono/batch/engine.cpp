#include "ademono/batch/engine.h"

#include <sys/wait.h>
#include <csignal>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "ademono/batch/process.h"
#include "ademono/core/file_util.h"

namespace fs = std::filesystem;

namespace ademono::batch {

int DefaultJobs() {
  const long n = ::sysconf(_SC_NPROCESSORS_ONLN);
  return n > 0 ? static_cast<int>(n) : 1;
}

std::vector<TaskOutcome> RunLocal(const std::vector<const Task*>& tasks, int jobs,
                                  const std::function<void(const std::string&)>& report,
                                  const std::atomic<int>* stop) {
  jobs = std::max(1, jobs);
  enum class State { kWaiting, kRunning, kOk, kFailed };
  std::vector<State> state(tasks.size(), State::kWaiting);
  std::vector<TaskOutcome> outcomes(tasks.size());
  std::map<std::string, size_t> index;
  for (size_t i = 0; i < tasks.size(); ++i) {
    index[tasks[i]->id] = i;
    outcomes[i].id = tasks[i]->id;
  }
  std::map<pid_t, size_t> running;
  std::vector<std::chrono::steady_clock::time_point> started(tasks.size());
  size_t ended = 0;
  auto line = [&](const std::string& what) {
    std::ostringstream os;
    os << "[" << ++ended << "/" << tasks.size() << "] " << what;
    report(os.str());
  };

  bool stopping = false;
  for (;;) {
    if (!stopping && stop != nullptr && stop->load() != 0) {
      stopping = true;
      report("stopping: " + std::to_string(running.size()) + " running, nothing more starts");
      if (stop->load() == SIGTERM) {
        for (const auto& [pid, i] : running) ::kill(pid, SIGTERM);
      }
      for (size_t i = 0; i < tasks.size(); ++i) {
        if (state[i] == State::kWaiting) {
          state[i] = State::kFailed;
          outcomes[i].note = "not started (stopped)";
        }
      }
    }
    // Start what is ready, in order; a task whose cache failed ends without running.
    for (size_t i = 0; i < tasks.size() && static_cast<int>(running.size()) < jobs; ++i) {
      if (state[i] != State::kWaiting) continue;
      bool ready = true;
      std::string failed_need;
      for (const std::string& need : tasks[i]->needs) {
        const auto it = index.find(need);
        if (it == index.end()) continue;  // done before this call
        if (state[it->second] == State::kFailed) failed_need = need;
        if (state[it->second] != State::kOk) ready = false;
      }
      if (!failed_need.empty()) {
        state[i] = State::kFailed;
        outcomes[i].note = "not run: " + failed_need + " failed";
        line("skipped " + tasks[i]->id + " (" + outcomes[i].note + ")");
        continue;
      }
      if (!ready) continue;
      started[i] = std::chrono::steady_clock::now();
      try {
        running[SpawnLogged(tasks[i]->argv, tasks[i]->log)] = i;
        state[i] = State::kRunning;
      } catch (const std::exception& e) {
        state[i] = State::kFailed;
        outcomes[i].exit_code = 127;
        outcomes[i].note = e.what();
        line("FAILED " + tasks[i]->id + ": " + e.what());
      }
    }
    if (running.empty()) {
      // Nothing runs: either all ended, or what waits depends on a task that failed (handled
      // above on the next pass) — one more pass settles it.
      const bool waiting = std::any_of(state.begin(), state.end(),
                                       [](State s) { return s == State::kWaiting; });
      if (!waiting) break;
      continue;
    }
    int status = 0;
    const pid_t pid = ::waitpid(-1, &status, 0);
    if (pid < 0) {
      if (errno == EINTR) continue;
      throw std::runtime_error("waitpid failed");
    }
    const auto it = running.find(pid);
    if (it == running.end()) continue;  // not one of ours
    const size_t i = it->second;
    running.erase(it);
    TaskOutcome& o = outcomes[i];
    o.exit_code = ExitCode(status);
    o.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - started[i]).count();
    o.complete = IsComplete(*tasks[i]);
    std::ostringstream timing;
    timing.setf(std::ios::fixed);
    timing.precision(1);
    timing << o.seconds << " s";
    if (o.exit_code == 0 && o.complete) {
      state[i] = State::kOk;
      line("done " + tasks[i]->id + " (" + timing.str() + ")");
    } else {
      state[i] = State::kFailed;
      if (o.note.empty()) {
        o.note = o.exit_code != 0 ? "exit code " + std::to_string(o.exit_code)
                                  : "ended without complete outputs";
      }
      line("FAILED " + tasks[i]->id + " (" + o.note + ", " + timing.str() +
                  "), log: " + tasks[i]->log.string());
    }
  }
  return outcomes;
}

std::string SlurmScript(const std::string& job_name, const std::vector<const Task*>& tasks,
                        const SlurmSettings& settings, const fs::path& slurm_dir,
                        const std::string& kind, int number) {
  std::ostringstream s;
  s << "#!/bin/bash\n";
  s << "# ademono batch: " << tasks.size() << " " << kind
    << " tasks; array task i runs branch i below (its output goes to its log).\n";
  s << "#SBATCH --job-name=" << job_name << "\n";
  s << "#SBATCH --array=0-" << tasks.size() - 1;
  if (settings.max_parallel > 0) s << "%" << settings.max_parallel;
  s << "\n";
  s << "#SBATCH --output="
    << (slurm_dir / (std::to_string(number) + "-" + kind + "-%a.out")).string() << "\n";
  if (!settings.partition.empty()) s << "#SBATCH --partition=" << settings.partition << "\n";
  if (!settings.time.empty()) s << "#SBATCH --time=" << settings.time << "\n";
  if (!settings.mem.empty()) s << "#SBATCH --mem=" << settings.mem << "\n";
  if (settings.cpus_per_task > 0) s << "#SBATCH --cpus-per-task=" << settings.cpus_per_task << "\n";
  if (!settings.account.empty()) s << "#SBATCH --account=" << settings.account << "\n";
  if (!settings.qos.empty()) s << "#SBATCH --qos=" << settings.qos << "\n";
  s << "set -u\n";
  s << "case \"${SLURM_ARRAY_TASK_ID:?not an array task}\" in\n";
  for (size_t i = 0; i < tasks.size(); ++i) {
    const Task& t = *tasks[i];
    s << "  " << i << ")  # " << t.id << "\n";
    s << "    mkdir -p " << ShellQuote(t.log.parent_path().string()) << "\n";
    s << "    exec " << ShellCommand(t.argv) << " >" << ShellQuote(t.log.string()) << " 2>&1 ;;\n";
  }
  s << "esac\n";
  s << "echo \"ademono batch: no task ${SLURM_ARRAY_TASK_ID}\" >&2\n";
  s << "exit 2\n";
  return s.str();
}

namespace {

nlohmann::json SubmissionJson(const Submission& s) {
  return {{"job_id", s.job_id}, {"kind", s.kind}, {"script", s.script.string()},
          {"tasks", s.task_ids}};
}

std::string Submit(const std::vector<std::string>& args) {
  const CommandResult r = RunCommand(args);
  std::string out = r.output;
  while (!out.empty() && (out.back() == '\n' || out.back() == '\r')) out.pop_back();
  if (r.exit_code != 0) {
    std::replace(out.begin(), out.end(), '\n', ' ');
    throw std::runtime_error("sbatch failed (exit " + std::to_string(r.exit_code) + "): " + out);
  }
  // --parsable: "JOBID" or "JOBID;CLUSTER" (the last line; sbatch may warn before it).
  const size_t nl = out.rfind('\n');
  std::string id = nl == std::string::npos ? out : out.substr(nl + 1);
  id = id.substr(0, id.find(';'));
  if (id.empty() || id.find_first_not_of("0123456789") != std::string::npos) {
    throw std::runtime_error("sbatch printed no job id: " + out);
  }
  return id;
}

}  // namespace

std::vector<Submission> ReadSubmissions(const fs::path& dir) {
  const fs::path file = dir / "slurm" / "submissions.json";
  std::vector<Submission> out;
  if (!fs::exists(file)) return out;
  try {
    for (const auto& j : nlohmann::json::parse(ReadTextFile(file))) {
      Submission s;
      s.job_id = j.at("job_id").get<std::string>();
      s.kind = j.at("kind").get<std::string>();
      s.script = j.at("script").get<std::string>();
      s.task_ids = j.at("tasks").get<std::vector<std::string>>();
      out.push_back(std::move(s));
    }
  } catch (const std::exception& e) {
    throw std::runtime_error(file.string() + ": malformed: " + e.what());
  }
  return out;
}

std::vector<Submission> SubmitSlurm(const Batch& batch, const std::vector<const Task*>& caches,
                                    const std::vector<const Task*>& runs,
                                    const SlurmSettings& settings) {
  const fs::path slurm_dir = batch.dir / "slurm";
  fs::create_directories(slurm_dir);
  fs::create_directories(batch.dir / "logs");
  std::vector<Submission> all = ReadSubmissions(batch.dir);
  std::vector<Submission> made;
  const int number = static_cast<int>(all.size()) + 1;
  const std::string cwd = fs::current_path().string();
  auto submit = [&](const std::string& kind, const std::vector<const Task*>& tasks,
                    const std::string& after) {
    Submission s;
    s.kind = kind;
    s.script = slurm_dir / (std::to_string(number) + "-" + kind + ".sh");
    for (const Task* t : tasks) s.task_ids.push_back(t->id);
    WriteTextFileAtomic(s.script, SlurmScript("ademono-" + batch.plan_name + "-" + kind, tasks,
                                              settings, slurm_dir, kind, number));
    std::vector<std::string> args = {"sbatch", "--parsable", "--chdir=" + cwd};
    if (!after.empty()) {
      args.push_back("--dependency=afterok:" + after);
      args.push_back("--kill-on-invalid-dep=yes");
    }
    args.insert(args.end(), settings.sbatch_args.begin(), settings.sbatch_args.end());
    args.push_back(s.script.string());
    s.job_id = Submit(args);
    made.push_back(s);
    all.push_back(s);
    // Recorded at once, so that a later `batch` knows what Slurm holds even if this one dies.
    nlohmann::json j = nlohmann::json::array();
    for (const Submission& x : all) j.push_back(SubmissionJson(x));
    WriteTextFileAtomic(slurm_dir / "submissions.json", j.dump(1) + "\n");
    return s.job_id;
  };
  std::string cache_job;
  if (!caches.empty()) cache_job = submit("cache", caches, "");
  if (!runs.empty()) submit("runs", runs, cache_job);
  return made;
}

namespace {

// squeue's lines "INDEX STATE" of one array job; empty when Slurm no longer knows it.
std::vector<std::pair<std::string, std::string>> QueueOf(const std::string& job_id) {
  const CommandResult r = RunCommand({"squeue", "-h", "-r", "-j", job_id, "-o", "%K %T"});
  std::vector<std::pair<std::string, std::string>> out;
  if (r.exit_code != 0) return out;  // purged ids make squeue fail: nothing held
  std::istringstream in(r.output);
  std::string index, state;
  while (in >> index >> state) out.emplace_back(index, state);
  return out;
}

// Array indices of "3", "0-5", "0-5%2", "1,3".
std::vector<size_t> Indices(const std::string& text) {
  std::vector<size_t> out;
  std::stringstream ss(text.substr(0, text.find('%')));
  std::string part;
  while (std::getline(ss, part, ',')) {
    try {
      const size_t dash = part.find('-');
      const size_t a = std::stoul(part.substr(0, dash));
      const size_t b = dash == std::string::npos ? a : std::stoul(part.substr(dash + 1));
      for (size_t i = a; i <= b && i < a + 100000; ++i) out.push_back(i);
    } catch (const std::exception&) {
    }
  }
  return out;
}

}  // namespace

std::set<std::string> InFlight(const std::vector<Submission>& submissions) {
  std::set<std::string> held;
  for (const Submission& s : submissions) {
    for (const auto& [index, state] : QueueOf(s.job_id)) {
      for (size_t i : Indices(index)) {
        if (i < s.task_ids.size()) held.insert(s.task_ids[i]);
      }
    }
  }
  return held;
}

void WaitForSlurm(const std::vector<Submission>& submissions,
                  const std::function<void(const std::string&)>& report, double poll_seconds) {
  size_t last = static_cast<size_t>(-1);
  for (;;) {
    size_t pending = 0, running = 0;
    for (const Submission& s : submissions) {
      for (const auto& [index, state] : QueueOf(s.job_id)) {
        const size_t n = std::max<size_t>(1, Indices(index).size());
        (state == "RUNNING" || state == "COMPLETING" ? running : pending) += n;
      }
    }
    const size_t total = pending + running;
    if (total != last) {
      report("slurm: " + std::to_string(running) + " running, " + std::to_string(pending) +
             " pending");
      last = total;
    }
    if (total == 0) return;
    std::this_thread::sleep_for(std::chrono::duration<double>(poll_seconds));
  }
}

}  // namespace ademono::batch
