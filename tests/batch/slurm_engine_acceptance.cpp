// `ademono batch --engine slurm` on a real one-node Slurm (scripts/slurm_local.sh, started and
// stopped here; CTest's slurm_local_stop cleans up even if this binary dies). A plan of 2
// synthetic sequences x 2 variants x 2 seeds with a shared cache array:
// - the run array waits for the cache array (afterok);
// - a run task cancelled mid-run (scancel) is listed as failed, and a second `batch` runs it, and
//   only it, again;
// - every run's trajectory is byte-identical to the same plan run by the local engine, and the
//   collected tables are the same (bar frames/s, the one machine-dependent column).
// Needs root (the daemons) and ../shared's YOLOX-nano (the cached network).
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

namespace fs = std::filesystem;

namespace {

using ::testing::HasSubstr;

const fs::path kModel = fs::path(ADEMONO_SHARED_DIR) / "models" / "yolox_nano.onnx";
const fs::path kScript = fs::path(ADEMONO_SOURCE_DIR) / "scripts" / "slurm_local.sh";

struct Result {
  int code = -1;
  std::string out;
};
// A shell command's exit code and what it printed (stdout and stderr).
Result Shell(const std::string& command) {
  Result r;
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  char buffer[4096];
  while (fgets(buffer, sizeof(buffer), pipe) != nullptr) r.out += buffer;
  const int status = pclose(pipe);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}
Result Ademono(const std::string& args) {
  return Shell(std::string(ADEMONO_CLI) + " --log-level warn " + args);
}
std::string ReadFile(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}
// A table without its last column (frames/s: wall time).
std::string WithoutLastColumn(const std::string& csv) {
  std::istringstream in(csv);
  std::string line, out;
  while (std::getline(in, line)) out += line.substr(0, line.rfind(',')) + "\n";
  return out;
}
// Polls `done` every 0.2 s for up to `seconds`.
template <typename F>
bool WaitFor(double seconds, F done) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < end) {
    if (done()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
  return done();
}

class SlurmBatchTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (::geteuid() != 0) {
      skip_ = "needs root to start the Slurm and munge daemons";
      return;
    }
    if (!fs::exists(kModel)) {
      skip_ = "no shared data";
      return;
    }
    const Result start = Shell("bash " + kScript.string() + " start");
    started_ = true;
    ASSERT_EQ(start.code, 0) << start.out;
    dir_ = fs::temp_directory_path() / ("ademono_batch_slurm_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "data");
    const char* seeds[] = {"3", "5"};
    for (int i = 0; i < 2; ++i) {
      const std::string name = i == 0 ? "a" : "b";
      const Result r =
          Ademono(std::string("synth --scene office --motion xyz --frames 50 --seed ") + seeds[i] +
                  " --out " + (dir_ / "data" / name).string());
      ASSERT_EQ(r.code, 0) << r.out;
    }
  }
  static void TearDownTestSuite() {
    if (started_) {
      const Result stop = Shell("bash " + kScript.string() + " stop");
      EXPECT_EQ(stop.code, 0) << stop.out;
    }
    std::error_code ec;
    if (!dir_.empty()) fs::remove_all(dir_, ec);
  }
  void SetUp() override {
    if (!skip_.empty()) GTEST_SKIP() << skip_;
  }
  static std::string skip_;
  static bool started_;
  static fs::path dir_;
};
std::string SlurmBatchTest::skip_;
bool SlurmBatchTest::started_ = false;
fs::path SlurmBatchTest::dir_;

TEST_F(SlurmBatchTest, SameOutputsAsLocalAndOnlyTheCancelledTaskRunsAgain) {
  const std::string network = "depth: simulated, detector: model:" + kModel.string();
  const fs::path plan = dir_ / "plan.yaml";
  std::ofstream(plan) << "root: " << (dir_ / "data").string() << "\n"
                      << "datasets: {a: tum:a, b: tum:b}\n"
                      << "variants:\n"
                      << "  full: {" << network << "}\n"
                      << "  no_distant: {ablation: no_distant, " << network << "}\n"
                      << "seeds: [1, 2]\n"
                      << "slurm: {time: '00:10:00', cpus_per_task: 1}\n";
  const fs::path local = dir_ / "local", slurm = dir_ / "slurm";

  // The Slurm engine, not waiting: a cache array of 2 tasks and a run array of 8 after it.
  const Result submitted =
      Ademono("batch " + plan.string() + " --out " + slurm.string() + " --engine slurm --no-wait");
  ASSERT_EQ(submitted.code, 0) << submitted.out;
  const nlohmann::json subs = nlohmann::json::parse(ReadFile(slurm / "slurm" / "submissions.json"));
  ASSERT_EQ(subs.size(), 2u);
  EXPECT_EQ(subs[0]["kind"], "cache");
  EXPECT_EQ(subs[0]["tasks"].size(), 2u);
  EXPECT_EQ(subs[1]["kind"], "runs");
  ASSERT_EQ(subs[1]["tasks"].size(), 8u);
  const std::string cache_job = subs[0]["job_id"], runs_job = subs[1]["job_id"];
  const Result dependency = Shell("scontrol show job " + runs_job);
  EXPECT_THAT(dependency.out, HasSubstr("Dependency=afterok:" + cache_job)) << dependency.out;

  // Cancel one run task once it is running (its log shows `run` started).
  std::string victim;
  std::string victim_index;
  ASSERT_TRUE(WaitFor(150, [&] {
    const Result r = Shell("squeue -h -r -j " + runs_job + " -t RUNNING -o %K");
    std::istringstream in(r.out);
    std::string index;
    if (!(in >> index)) return false;
    const std::string id = subs[1]["tasks"][std::stoul(index)];
    if (ReadFile(slurm / "logs" / (id + ".log")).find("config:") == std::string::npos) return false;
    victim = id;
    victim_index = index;
    return true;
  })) << Shell("squeue").out;
  const Result cancel = Shell("scancel " + runs_job + "_" + victim_index);
  ASSERT_EQ(cancel.code, 0) << cancel.out;

  // Meanwhile the same plan on the local engine.
  const Result local_run = Ademono("batch " + plan.string() + " --out " + local.string());
  ASSERT_EQ(local_run.code, 0) << local_run.out;

  ASSERT_TRUE(WaitFor(300, [] { return Shell("squeue -h").out.empty(); })) << Shell("squeue").out;
  const Result collected = Ademono("batch --collect " + slurm.string());
  EXPECT_EQ(collected.code, 1) << collected.out;
  EXPECT_THAT(collected.out, HasSubstr("failed: " + victim + ", log: "));
  EXPECT_THAT(collected.out, HasSubstr("7/8 runs done"));

  // Again: the cancelled task alone, in a third submission.
  const Result again =
      Ademono("batch " + plan.string() + " --out " + slurm.string() + " --engine slurm");
  ASSERT_EQ(again.code, 0) << again.out;
  EXPECT_THAT(again.out, HasSubstr("7 done, 0 held by Slurm, 1 to run, 0 caches to compute"));
  const nlohmann::json all = nlohmann::json::parse(ReadFile(slurm / "slurm" / "submissions.json"));
  ASSERT_EQ(all.size(), 3u);
  EXPECT_EQ(all[2]["kind"], "runs");
  EXPECT_EQ(all[2]["tasks"], nlohmann::json::array({victim}));

  // The same outputs as the local engine.
  for (const auto& id : subs[1]["tasks"]) {
    const std::string a = ReadFile(local / "runs" / id.get<std::string>() / "trajectory.tum");
    const std::string b = ReadFile(slurm / "runs" / id.get<std::string>() / "trajectory.tum");
    EXPECT_GT(a.size(), 100u) << id;
    EXPECT_EQ(a, b) << id;
  }
  for (const char* table : {"results.csv", "summary.csv"}) {
    const std::string a = ReadFile(local / table), b = ReadFile(slurm / table);
    EXPECT_GT(a.size(), 100u) << table;
    EXPECT_EQ(WithoutLastColumn(a), WithoutLastColumn(b)) << table;
  }
}

}  // namespace
