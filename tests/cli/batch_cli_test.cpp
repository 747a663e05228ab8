// `ademono batch` with the local engine on two short synthetic offices: every run of the plan done
// once, the inference cache computed once per dataset and shared, the table scored as
// `ademono eval` scores, a second batch runs only what is missing; bad plans are one line, exit 2
// and nothing written.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cli_test_util.h"

extern char** environ;

namespace fs = std::filesystem;

namespace {

using ::testing::HasSubstr;
using ademono::cli_test::CliRun;
using ademono::cli_test::ReadFile;

const fs::path kModel = fs::path(ADEMONO_SHARED_DIR) / "models" / "yolox_nano.onnx";

class BatchCliTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("ademono_batch_cli_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "data");
    for (const char* name : {"a", "b"}) {
      const CliRun r =
          Run(std::string("synth --scene office --motion xyz --frames 30 --seed ") +
              (name[0] == 'a' ? "3" : "5") + " --out " + (dir_ / "data" / name).string());
      ASSERT_EQ(r.exit_code, 0) << r.err;
    }
  }
  static void TearDownTestSuite() {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  static CliRun Run(const std::string& args) {
    return ademono::cli_test::RunAdemono("--log-level warn " + args, dir_);
  }
  static fs::path Plan(const std::string& name, const std::string& body) {
    const fs::path file = dir_ / name;
    std::ofstream(file) << "root: " << (dir_ / "data").string() << "\n" << body;
    return file;
  }
  static fs::path dir_;
};
fs::path BatchCliTest::dir_;

TEST_F(BatchCliTest, LocalEngineRunsThePlanOnceAndAgainOnlyWhatIsMissing) {
  if (!fs::exists(kModel)) GTEST_SKIP() << "no shared data";
  const fs::path plan =
      Plan("plan.yaml",
           "datasets: {a: tum:a, b: tum:b}\n"
           "variants:\n"
           "  full: {depth: simulated, detector: model:" +
               kModel.string() +
               "}\n"
               "  no_distant: {ablation: no_distant, depth: simulated, detector: model:" +
               kModel.string() +
               "}\n"
               "seeds: [1]\n");
  const fs::path out = dir_ / "out";
  const CliRun first = Run("batch " + plan.string() + " --out " + out.string() + " --jobs 2");
  ASSERT_EQ(first.exit_code, 0) << first.out << first.err;
  EXPECT_THAT(first.err, HasSubstr("4 runs (2 datasets x 2 variants x 1 seeds): 0 done"));
  EXPECT_THAT(first.err, HasSubstr("4 to run, 2 caches to compute"));
  for (const char* id : {"a__full__s1", "a__no_distant__s1", "b__full__s1", "b__no_distant__s1"}) {
    EXPECT_TRUE(fs::exists(out / "runs" / id / "summary.json")) << id;
    EXPECT_TRUE(fs::exists(out / "logs" / (std::string(id) + ".log"))) << id;
  }
  // One cache per dataset (one network), read by both variants.
  for (const char* d : {"a", "b"}) {
    size_t caches = 0;
    for (const auto& e : fs::directory_iterator(out / "cache" / d)) {
      EXPECT_TRUE(fs::exists(e.path() / "detections.jsonl"));
      ++caches;
    }
    EXPECT_EQ(caches, 1u) << d;
  }
  const std::string config = ReadFile(out / "runs" / "a__no_distant__s1" / "config.resolved.yaml");
  EXPECT_THAT(config, HasSubstr("enable_distant_filter: false"));
  const nlohmann::json summary =
      nlohmann::json::parse(ReadFile(out / "runs" / "a__full__s1" / "summary.json"));
  EXPECT_THAT(summary["detector"].get<std::string>(), HasSubstr("cache:"));

  // The table: one row per run, scored as `ademono eval` scores the run folder.
  const std::string csv = ReadFile(out / "results.csv");
  std::istringstream lines(csv);
  std::string header, row;
  std::getline(lines, header);
  EXPECT_EQ(header,
            "dataset,variant,seed,status,frames,tracked,keyframes,ate_se3_m,ate_sim3_m,sim3_scale,"
            "rpe_30f_m,fps");
  std::getline(lines, row);
  EXPECT_EQ(row.rfind("a,full,1,done,30,", 0), 0u) << row;
  const fs::path run = out / "runs" / "a__full__s1";
  const CliRun eval = Run("eval --gt " + (run / "groundtruth.tum").string() + " --est " +
                          (run / "trajectory.tum").string() + " --align sim3 --json " +
                          (dir_ / "eval.json").string());
  ASSERT_EQ(eval.exit_code, 0) << eval.err;
  const nlohmann::json e = nlohmann::json::parse(ReadFile(dir_ / "eval.json"));
  char ate[64];
  std::snprintf(ate, sizeof(ate), ",%.6f,%.6f,", e["ape"]["rmse"].get<double>(),
                e["scale"].get<double>());
  EXPECT_THAT(row, HasSubstr(ate));
  EXPECT_THAT(ReadFile(out / "summary.csv"), HasSubstr("\na,full,1,1,"));
  EXPECT_THAT(ReadFile(out / "results.md"), HasSubstr("| a | no_distant | 1/1 |"));
  EXPECT_TRUE(fs::exists(out / "report.html"));

  // Again: nothing to do, nothing rewritten.
  const std::string before = ReadFile(run / "trajectory.tum");
  const auto written = fs::last_write_time(run / "summary.json");
  const CliRun second = Run("batch " + plan.string() + " --out " + out.string());
  ASSERT_EQ(second.exit_code, 0) << second.err;
  EXPECT_THAT(second.err, HasSubstr("4 done, 0 held by Slurm, 0 to run, 0 caches to compute"));
  EXPECT_EQ(fs::last_write_time(run / "summary.json"), written);

  // A run whose outputs are gone (a killed run leaves no summary.json) runs again, alone, and
  // gives the same trajectory; its cache is not recomputed.
  fs::remove(run / "summary.json");
  const CliRun third = Run("batch " + plan.string() + " --out " + out.string());
  ASSERT_EQ(third.exit_code, 0) << third.err;
  EXPECT_THAT(third.err, HasSubstr("3 done, 0 held by Slurm, 1 to run, 0 caches to compute"));
  EXPECT_EQ(ReadFile(run / "trajectory.tum"), before);

  // A plan that changes a run already done there is refused.
  const fs::path changed = Plan("changed.yaml",
                                "datasets: {a: tum:a, b: tum:b}\n"
                                "variants:\n"
                                "  full: {depth: simulated}\n"
                                "seeds: [1]\n");
  const CliRun refused = Run("batch " + changed.string() + " --out " + out.string());
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_THAT(refused.err, HasSubstr("'a__full__s1' was done with another command"));

  // --collect gives the same table.
  const std::string table = ReadFile(out / "results.csv");
  fs::remove(out / "results.csv");
  const CliRun collect = Run("batch --collect " + out.string());
  ASSERT_EQ(collect.exit_code, 0) << collect.err;
  EXPECT_EQ(ReadFile(out / "results.csv"), table);
}

// SIGTERM to `batch` mid-run: nothing more starts, the running runs get SIGTERM and end
// (incomplete), `batch` writes the table of what is done and exits 143; the next `batch` runs
// the rest, and the runs are the same as when nothing was stopped.
TEST_F(BatchCliTest, StoppedBySigtermAndResumed) {
  const fs::path plan = Plan("stop.yaml",
                             "datasets: {a: {dataset: tum:a, frames: '0:20'}}\n"
                             "variants: {full: {depth: simulated}}\n"
                             "seeds: [1, 2, 3, 4]\n");
  const fs::path out = dir_ / "stop";
  const std::string out_arg = out.string();
  const std::string plan_arg = plan.string();
  const std::string err_file = (dir_ / "stop.err").string();
  std::vector<std::string> args = {ADEMONO_CLI, "--log-level", "warn", "batch", plan_arg,
                                   "--out",     out_arg,       "--jobs", "2"};
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, err_file.c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  pid_t pid = 0;
  ASSERT_EQ(posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ), 0);
  posix_spawn_file_actions_destroy(&actions);
  // Once a run has started (its log exists), stop the batch.
  for (int i = 0; i < 600 && !fs::exists(out / "logs" / "a__full__s1.log"); ++i) ::usleep(50000);
  ::usleep(300000);
  ::kill(pid, SIGTERM);
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  const std::string err = ReadFile(err_file);
  ASSERT_TRUE(WIFEXITED(status)) << err;
  EXPECT_EQ(WEXITSTATUS(status), 143) << err;
  EXPECT_THAT(err, HasSubstr("stopping: "));
  EXPECT_TRUE(fs::exists(out / "results.csv"));
  size_t done = 0;
  for (const char* id : {"a__full__s1", "a__full__s2", "a__full__s3", "a__full__s4"}) {
    done += fs::exists(out / "runs" / id / "summary.json") &&
            ReadFile(out / "runs" / id / "summary.json").find("\"partial\": true") ==
                std::string::npos;
  }
  EXPECT_LT(done, 4u) << err;

  const CliRun resumed = Run("batch " + plan.string() + " --out " + out.string());
  ASSERT_EQ(resumed.exit_code, 0) << resumed.err;
  EXPECT_THAT(resumed.err, HasSubstr(std::to_string(done) + " done, 0 held by Slurm, " +
                                     std::to_string(4 - done) + " to run"));
  const fs::path again = dir_ / "stop_again";
  ASSERT_EQ(Run("batch " + plan.string() + " --out " + again.string()).exit_code, 0);
  for (const char* id : {"a__full__s1", "a__full__s2", "a__full__s3", "a__full__s4"}) {
    EXPECT_EQ(ReadFile(out / "runs" / id / "trajectory.tum"),
              ReadFile(again / "runs" / id / "trajectory.tum"))
        << id;
  }
}

TEST_F(BatchCliTest, AFailedRunIsListedWithItsLog) {
  // A depth cache that is not there: `run` exits 2 (the plan does not look inside caches).
  const fs::path plan = Plan("fail.yaml",
                             "datasets: {a: {dataset: tum:a, frames: '0:10'}}\n"
                             "variants: {full: {depth: simulated}, broken: {depth: cache:" +
                                 (dir_ / "no-such-cache").string() + "}}\n");
  const fs::path out = dir_ / "fail";
  const CliRun r = Run("batch " + plan.string() + " --out " + out.string());
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_THAT(r.err, HasSubstr("FAILED a__broken__sconfig (exit code 2"));
  EXPECT_THAT(r.out, HasSubstr("failed: a__broken__sconfig, log: " +
                               (out / "logs" / "a__broken__sconfig.log").string()));
  EXPECT_THAT(ReadFile(out / "logs" / "a__broken__sconfig.log"), HasSubstr("no-such-cache"));
  EXPECT_TRUE(fs::exists(out / "runs" / "a__full__sconfig" / "summary.json"));
  EXPECT_THAT(ReadFile(out / "results.csv"), HasSubstr("\na,broken,config,failed,"));
}

TEST_F(BatchCliTest, BadPlansAreOneLineExitTwoAndNothingWritten) {
  const std::string variants = "variants: {full: {depth: simulated}}\n";
  struct Case {
    std::string plan, flags, expected;
  };
  const std::vector<Case> cases = {
      {"datasets: {a: tum:a}\n" + variants + "seeds: [1]\nnonsense: 3\n", "",
       "unknown key 'nonsense'"},
      {"datasets: {gone: tum:no-such-sequence}\n" + variants, "", "dataset 'gone'"},
      {"datasets: {a: tum:a}\nvariants: {v: {set: [tracking.no_such_option=1]}}\n", "",
       "tracking.no_such_option"},
      {"datasets: {a: tum:a}\n" + variants, "--engine slurm", "sbatch not found on PATH"},
      {"datasets: {a: tum:a}\n" + variants, "--engine cloud", "engine 'cloud' is not there"},
  };
  for (const Case& c : cases) {
    const fs::path plan = Plan("bad.yaml", c.plan);
    const fs::path out = dir_ / "bad_out";
    // No sbatch on this PATH, whatever the machine has.
    const std::string command = "env PATH=/nonexistent " + std::string(ADEMONO_CLI) +
                                " batch " + plan.string() + " --out " + out.string() + " " +
                                c.flags + " >" + (dir_ / "o.txt").string() + " 2>" +
                                (dir_ / "e.txt").string();
    const int status = std::system(command.c_str());
    const std::string err = ReadFile(dir_ / "e.txt");
    EXPECT_EQ(WEXITSTATUS(status), 2) << c.expected << ": " << err;
    EXPECT_THAT(err, HasSubstr(plan.string() + ": ")) << c.expected;
    EXPECT_THAT(err, HasSubstr(c.expected));
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
    EXPECT_FALSE(fs::exists(out)) << c.expected;
  }
}

}  // namespace
