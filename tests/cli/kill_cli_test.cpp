// `ademono run` killed at random moments (SIGKILL) leaves every output complete or absent, never
// partial; SIGINT stops after the current frame and writes the frames done so far, marked partial;
// a folder that already holds files is refused without --overwrite. Real runs on a 7-Scenes slice.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "cli_test_util.h"

namespace {

namespace fs = std::filesystem;
using ademono::cli_test::ReadFile;
using ademono::cli_test::RunCli;

// Starts `ademono ARGS...` with stdout and stderr discarded; returns its pid.
pid_t Spawn(const std::vector<std::string>& args) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int null = ::open("/dev/null", O_WRONLY);
    ::dup2(null, STDOUT_FILENO);
    ::dup2(null, STDERR_FILENO);
    std::vector<char*> argv;
    std::string cli = ADEMONO_CLI;
    argv.push_back(cli.data());
    std::vector<std::string> copy = args;
    for (std::string& a : copy) argv.push_back(a.data());
    argv.push_back(nullptr);
    ::execv(ADEMONO_CLI, argv.data());
    ::_exit(127);
  }
  return pid;
}

int Wait(pid_t pid) {
  int status = 0;
  ::waitpid(pid, &status, 0);
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
  return -1;
}

int CountDataLines(const std::string& text) {
  std::istringstream in(text);
  int n = 0;
  for (std::string line; std::getline(in, line);) n += (!line.empty() && line[0] != '#') ? 1 : 0;
  return n;
}

// The files a deterministic run writes identically every time.
const char* const kStableOutputs[] = {"trajectory.tum", "trajectory.kitti", "keyframes.tum",
                                      "map.ply", "groundtruth.tum", "config.resolved.yaml"};

class KillCliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() /
            ("ademono_kill_cli_" + std::to_string(::getpid()) + "_" +
             ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(root_);
    fs::create_directories(root_);
  }
  void TearDown() override { fs::remove_all(root_); }
  std::vector<std::string> RunArgs(const fs::path& out, const std::string& frames) const {
    return {"run",      "--dataset",
            std::string("7scenes:") + ADEMONO_SHARED_DIR + "/data/7scenes-seq-a",
            "--config", std::string(ADEMONO_SOURCE_DIR) + "/configs/7scenes.yaml",
            "--frames", frames,
            "--out",    out.string()};
  }
  fs::path root_;
};

TEST_F(KillCliTest, SigkillLeavesEachOutputCompleteOrAbsent) {
  const std::string frames = "0:30";
  const fs::path reference = root_ / "reference";
  const auto start = std::chrono::steady_clock::now();
  ASSERT_EQ(Wait(Spawn(RunArgs(reference, frames))), 0);
  const double full_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  // Kill moments spread over the whole run, start-up and output writing included.
  std::mt19937 rng(16);
  std::uniform_real_distribution<double> when(0.0, 1.1 * full_seconds);
  int killed = 0, finished = 0;
  for (int k = 0; k < 20; ++k) {
    const fs::path out = root_ / ("kill" + std::to_string(k));
    std::vector<std::string> args = RunArgs(out, frames);
    const bool previous = k % 2 == 1;  // odd: over a complete earlier run, with --overwrite
    if (previous) {
      fs::copy(reference, out, fs::copy_options::recursive);
      args.push_back("--overwrite");
    }
    const pid_t pid = Spawn(args);
    std::this_thread::sleep_for(std::chrono::duration<double>(when(rng)));
    ::kill(pid, SIGKILL);
    const int code = Wait(pid);
    (code == 128 + SIGKILL ? killed : finished) += 1;
    ASSERT_TRUE(code == 0 || code == 128 + SIGKILL) << "kill " << k << ": exit " << code;

    if (!fs::exists(out)) continue;
    for (const char* name : kStableOutputs) {
      if (fs::exists(out / name)) {
        EXPECT_EQ(ReadFile(out / name), ReadFile(reference / name)) << "kill " << k << " " << name;
      }
    }
    if (fs::exists(out / "summary.json")) {
      const nlohmann::json summary = nlohmann::json::parse(ReadFile(out / "summary.json"));
      EXPECT_EQ(summary["frames"], 30) << "kill " << k;
      EXPECT_FALSE(summary["partial"].get<bool>()) << "kill " << k;
      // summary.json is committed last: with it, the whole set is there.
      for (const char* name : kStableOutputs) EXPECT_TRUE(fs::exists(out / name)) << name;
    }
    if (fs::exists(out / "report.html")) {
      EXPECT_NE(ReadFile(out / "report.html").find("</html>"), std::string::npos);
    }
    // Nothing else: no temp file outside the (ignored) staging folder.
    for (const auto& entry : fs::directory_iterator(out)) {
      const std::string name = entry.path().filename().string();
      const bool known = name == "summary.json" || name == "report.html" ||
                         name.rfind(".staging.", 0) == 0 ||
                         std::find_if(std::begin(kStableOutputs), std::end(kStableOutputs),
                                      [&](const char* n) { return name == n; }) !=
                             std::end(kStableOutputs);
      EXPECT_TRUE(known) << "kill " << k << ": stray " << name;
    }
  }
  EXPECT_GE(killed, 10) << "most kills should land during the run (finished " << finished << ")";
}

TEST_F(KillCliTest, SigintWritesThePartialRunAndTheLiveTrajectoryMatchesIt) {
  const fs::path out = root_ / "run";
  std::vector<std::string> args = RunArgs(out, "0:400");
  args.push_back("--live-trajectory");
  const pid_t pid = Spawn(args);
  // Interrupt once the live trajectory shows 10 tracked frames.
  const fs::path live = out / "trajectory.live.tum";
  for (int i = 0; i < 3000 && !(fs::exists(live) && CountDataLines(ReadFile(live)) >= 10); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  ::kill(pid, SIGINT);
  ASSERT_EQ(Wait(pid), 130);

  const nlohmann::json summary = nlohmann::json::parse(ReadFile(out / "summary.json"));
  EXPECT_TRUE(summary["partial"].get<bool>());
  const int frames = summary["frames"].get<int>();
  EXPECT_GE(frames, 10);
  EXPECT_LT(frames, 400);
  EXPECT_EQ(summary["per_frame"].size(), static_cast<size_t>(frames));
  const int tracked = summary["tracked"].get<int>();
  EXPECT_EQ(CountDataLines(ReadFile(out / "trajectory.tum")), tracked);
  // One fsynced live line per tracked frame, same timestamps as the final trajectory.
  EXPECT_EQ(CountDataLines(ReadFile(live)), tracked);
  std::istringstream a(ReadFile(live)), b(ReadFile(out / "trajectory.tum"));
  for (std::string la, lb; std::getline(a, la) && std::getline(b, lb);)
    EXPECT_EQ(la.substr(0, la.find(' ')), lb.substr(0, lb.find(' ')));
  EXPECT_TRUE(fs::exists(out / "map.ply"));
  EXPECT_TRUE(fs::exists(out / "report.html"));
}

TEST_F(KillCliTest, RefusesAFolderWithFilesUnlessOverwrite) {
  const fs::path out = root_ / "run";
  fs::create_directories(out);
  {
    std::ofstream(out / "notes.txt") << "mine\n";
  }
  std::string command;
  for (const std::string& a : RunArgs(out, "0:5")) command += a + " ";
  const auto r = RunCli(command);
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << r.out;
  EXPECT_NE(r.out.find(out.string()), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("not empty"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(out / "summary.json"));

  EXPECT_EQ(RunCli(command + "--overwrite").code, 0);
  EXPECT_TRUE(fs::exists(out / "summary.json"));
  EXPECT_EQ(ReadFile(out / "notes.txt"), "mine\n");  // --overwrite replaces run outputs only
}

}  // namespace
