// End-to-end test of `ademono ablate` on a tiny synthetic office (20 frames with walking persons
// and ground-truth boxes): five variant folders with run outputs, the table's columns, truth
// scoring, filter counts in `run`'s summary.json (schema ademono.run/1) and --viz images; bad input
// gives one line and exit code 2 with no output left.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cli_test_util.h"

namespace fs = std::filesystem;

namespace {

using ::testing::HasSubstr;

using RunResult = ademono::cli_test::CliRun;
using ademono::cli_test::ReadFile;


class AblateCliTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("ademono_ablate_cli_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    const RunResult r =
        Run("synth --scene office --motion xyz --persons 2 --frames 20 --seed 3 "
            "--out " +
            (dir_ / "office").string());
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  static void TearDownTestSuite() {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  static RunResult Run(const std::string& args) {
    return ademono::cli_test::RunAdemono("--log-level warn " + args, dir_);
  }
  static std::string Sequence() { return (dir_ / "office").string(); }

  static fs::path dir_;
};
fs::path AblateCliTest::dir_;

TEST_F(AblateCliTest, FiveVariantsAndTable) {
  const fs::path out = dir_ / "ablate";
  const RunResult r = Run("ablate --dataset tum:" + Sequence() +
                          " --depth simulated --detector cache:" + Sequence() +
                          "/detections.jsonl --out " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* v :
       {"full", "no_dynamic", "no_distant", "no_dynamic_no_distant", "no_enhancement"}) {
    EXPECT_THAT(r.out, HasSubstr(std::string("| ") + v + " |"));
    for (const char* f :
         {"trajectory.tum", "keyframes.tum", "map.ply", "groundtruth.tum", "summary.json"})
      EXPECT_TRUE(fs::exists(out / v / f)) << v << "/" << f;
  }
  const std::string md = ReadFile(out / "ablation.md");
  EXPECT_EQ(md, r.out);
  for (const char* column :
       {"ATE se3 (m)", "ATE sim3 (m)", "tracked", "keyframes", "removed enh", "removed dyn",
        "removed distant", "moving removed", "moving kept out of tracking and map",
        "unboxed moving removed", "static removed",
        "static person removed"})
    EXPECT_THAT(md, HasSubstr(column));
  std::ifstream in(out / "ablation.json");
  const nlohmann::json json = nlohmann::json::parse(in);
  ASSERT_EQ(json["variants"].size(), 5u);
  for (const auto& v : json["variants"]) {
    EXPECT_EQ(v["frames"], 20);
    EXPECT_TRUE(v["ate_se3_rmse_m"].is_number()) << v["variant"];
    EXPECT_TRUE(v["truth"].is_object()) << v["variant"];
    const bool dynamic = v["filters"]["dynamic_removal"].get<bool>();
    EXPECT_EQ(v["filter_counts"]["removed_dynamic"].get<long long>() > 0, dynamic) << v["variant"];
    EXPECT_EQ(v["filter_counts"]["removed_enhancement"].get<long long>() > 0,
              v["filters"]["enhancement"].get<bool>())
        << v["variant"];
  }
}

TEST_F(AblateCliTest, RunSummaryCountsFiltersAndVizWritesOneImagePerFrame) {
  const fs::path out = dir_ / "run", viz = dir_ / "viz";
  const RunResult r =
      Run("run --dataset tum:" + Sequence() + " --depth simulated --detector cache:" + Sequence() +
          "/detections.jsonl --frames 0:6 --viz " + viz.string() + " --out " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::ifstream in(out / "summary.json");
  const nlohmann::json summary = nlohmann::json::parse(in);
  const auto& total = summary["filter_counts"];
  EXPECT_EQ(summary["schema"], "ademono.run/1");
  ASSERT_EQ(summary["per_frame"].size(), 6u);
  long long removed_dynamic = 0, boxes = 0;
  for (const auto& frame : summary["per_frame"]) {
    const auto& f = frame["filter"];
    removed_dynamic += f["removed_small_box"].get<long long>() +
                       f["removed_stage1"].get<long long>() + f["removed_stage2"].get<long long>() +
                       f["removed_box_vote"].get<long long>();
    boxes += f["boxes_small"].get<long long>() + f["boxes_large"].get<long long>();
  }
  EXPECT_EQ(total["removed_dynamic"].get<long long>(), removed_dynamic);
  EXPECT_EQ(total["boxes_small"].get<long long>() + total["boxes_large"].get<long long>(), boxes);
  EXPECT_GT(boxes, 0);
  size_t images = 0;
  for (const auto& e : fs::directory_iterator(viz)) images += e.path().extension() == ".jpg";
  EXPECT_EQ(images, 6u);
}

TEST_F(AblateCliTest, BadInputGivesOneLineAndNoOutput) {
  const fs::path out = dir_ / "bad";
  RunResult r =
      Run("ablate --dataset tum:" + (dir_ / "missing").string() + " --out " + out.string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("ademono ablate: error:"));
  EXPECT_FALSE(fs::exists(out));
  r = Run("ablate --dataset tum:" + Sequence() + " --variants full,bogus --out " + out.string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("unknown variant 'bogus'"));
  EXPECT_FALSE(fs::exists(out));
}

}  // namespace
