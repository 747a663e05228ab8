// The batch plan: strict reading (each bad plan one line naming the file and the problem),
// expansion into `ademono infer` / `ademono run` command lines with stable names, completeness of
// run folders, the Slurm job script, and the table over seeds.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "ademono/batch/collect.h"
#include "ademono/batch/engine.h"
#include "ademono/batch/plan.h"
#include "ademono/batch/tasks.h"
#include "ademono/core/error.h"
#include "ademono/runner/ablation.h"
#include "ademono/runner/config_file.h"
#include "ademono/slam/options.h"
#include "ademono/synth/generator.h"

namespace fs = std::filesystem;

namespace ademono::batch {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

const fs::path kModel = fs::path(ADEMONO_SHARED_DIR) / "models" / "yolox_nano.onnx";

class PlanTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("ademono_batch_plan_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    synth::GeneratorOptions options;
    options.scene.scene = "office";
    options.scene.frames = 12;
    options.scene.seed = 3;
    synth::GenerateSequence(options, dir_ / "data" / "office");
  }
  static void TearDownTestSuite() {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  static fs::path Write(const std::string& name, const std::string& text) {
    const fs::path file = dir_ / name;
    std::ofstream(file) << text;
    return file;
  }
  // The one-line message of a bad plan.
  static std::string Error(const std::string& text) {
    const fs::path file = Write("bad.yaml", text);
    try {
      LoadPlan(file);
    } catch (const InputError& e) {
      const std::string message = e.what();
      EXPECT_EQ(message.find('\n'), std::string::npos) << message;
      EXPECT_EQ(message.rfind(file.string() + ": ", 0), 0u) << message;
      return message;
    }
    ADD_FAILURE() << "accepted: " << text;
    return "";
  }
  static std::string Root() { return "root: " + (dir_ / "data").string() + "\n"; }
  static fs::path dir_;
};
fs::path PlanTest::dir_;

TEST_F(PlanTest, ReadsDatasetsVariantsSeedsAndSlurm) {
  const fs::path file = Write(
      "plan.yaml", Root() +
                       "datasets:\n"
                       "  office: tum:office\n"
                       "  part: {dataset: tum:office, frames: '2:10'}\n"
                       "variants:\n"
                       "  full:\n"
                       "  no_distant: {ablation: no_distant, set: [orb.num_features=800]}\n"
                       "  sim: {depth: simulated, set: {depth.max_depth: 6}}\n"
                       "seeds: [1, 2]\n"
                       "slurm: {partition: debug, time: '00:10:00', mem: 2G, cpus_per_task: 2}\n");
  const Plan plan = LoadPlan(file);
  EXPECT_EQ(plan.name, "plan");
  ASSERT_EQ(plan.datasets.size(), 2u);
  EXPECT_EQ(plan.datasets[0].Spec(), "tum:" + (dir_ / "data" / "office").string());
  EXPECT_EQ(plan.datasets[0].size, 12u);
  EXPECT_EQ(plan.datasets[1].frames, "2:10");
  ASSERT_EQ(plan.variants.size(), 3u);
  EXPECT_EQ(plan.variants[0].name, "full");
  EXPECT_EQ(plan.variants[1].ablation, "no_distant");
  EXPECT_THAT(plan.variants[2].set, ElementsAre("depth.max_depth=6"));
  ASSERT_EQ(plan.seeds.size(), 2u);
  EXPECT_EQ(*plan.seeds[1], 2u);
  EXPECT_EQ(plan.slurm.partition, "debug");
  EXPECT_EQ(plan.slurm.cpus_per_task, 2);

  // --root moves every dataset.
  fs::create_directories(dir_ / "other");
  fs::create_symlink(dir_ / "data" / "office", dir_ / "other" / "office");
  EXPECT_EQ(LoadPlan(file, (dir_ / "other").string()).datasets[0].path, dir_ / "other" / "office");
}

TEST_F(PlanTest, BadPlansAreOneLineNamingTheFileAndTheProblem) {
  const std::string ok_datasets = "datasets: {office: tum:office}\n";
  const std::string ok_variants = "variants: {full: }\n";
  EXPECT_THAT(Error(Root() + ok_datasets + ok_variants + "sedes: [1]\n"),
              HasSubstr("unknown key 'sedes'"));
  EXPECT_THAT(Error(Root() + ok_datasets + "variants: {full: {detektor: none}}\n"),
              HasSubstr("unknown key 'variants.full.detektor'"));
  EXPECT_THAT(Error(Root() + "datasets: {gone: tum:missing-folder}\n" + ok_variants),
              HasSubstr("dataset 'gone'"));
  EXPECT_THAT(Error(Root() + ok_datasets + "variants: {v: {set: [filter.no_such_option=1]}}\n"),
              HasSubstr("variant 'v'"));
  EXPECT_THAT(Error(Root() + ok_datasets + "variants: {v: {set: [filter.no_such_option=1]}}\n"),
              HasSubstr("no_such_option"));
  EXPECT_THAT(Error(Root() + ok_datasets + "variants: {v: {ablation: no_such_variant}}\n"),
              HasSubstr("unknown variant 'no_such_variant'"));
  EXPECT_THAT(Error(Root() + ok_datasets + "variants: {v: {detector: model:/no/such.onnx}}\n"),
              HasSubstr("/no/such.onnx not found"));
  EXPECT_THAT(Error(Root() + ok_datasets + ok_variants + "slurm: {partitoin: x}\n"),
              HasSubstr("unknown key 'slurm.partitoin'"));
  EXPECT_THAT(Error(Root() + "datasets: {office: {dataset: tum:office, frames: '20:30'}}\n" +
                    ok_variants),
              HasSubstr("12 frames"));
  EXPECT_THAT(Error(Root() + "datasets: {a__b: tum:office}\n" + ok_variants),
              HasSubstr("names folders"));
}

TEST_F(PlanTest, ExpandsIntoStableCommandLinesWithOneCachePerDatasetAndNetwork) {
  if (!fs::exists(kModel)) GTEST_SKIP() << "no shared data";
  const std::string detector = "detector: model:" + kModel.string();
  const fs::path file = Write("plan.yaml", Root() +
                                               "datasets: {office: tum:office}\n"
                                               "variants:\n"
                                               "  full: {" +
                                               detector +
                                               "}\n"
                                               "  no_distant: {ablation: no_distant, " +
                                               detector +
                                               "}\n"
                                               "  geometry_only: {ablation: geometry_only, " +
                                               detector +
                                               "}\n"
                                               "seeds: [4, 5]\n");
  const Batch b = ExpandPlan(LoadPlan(file), dir_ / "out", "/bin/ademono");
  ASSERT_EQ(b.caches.size(), 1u);  // one network on one dataset, shared
  const Task& cache = b.caches[0];
  EXPECT_EQ(cache.argv[1], "infer");
  EXPECT_EQ(cache.out.parent_path(), dir_ / "out" / "cache" / "office");
  EXPECT_EQ(cache.product, cache.out / "detections.jsonl");
  ASSERT_EQ(b.runs.size(), 6u);
  EXPECT_EQ(b.runs[0].id, "office__full__s4");
  EXPECT_EQ(b.runs[5].id, "office__geometry_only__s5");
  EXPECT_EQ(b.runs[0].out, dir_ / "out" / "runs" / "office__full__s4");
  EXPECT_THAT(b.runs[0].needs, ElementsAre(cache.id));
  const std::string run = ShellCommand(b.runs[2].argv);
  EXPECT_THAT(run, HasSubstr("/bin/ademono run --dataset tum:"));
  EXPECT_THAT(run, HasSubstr("--detector cache:" + cache.product.string()));
  EXPECT_THAT(run, HasSubstr("--seed 4"));
  EXPECT_THAT(run, HasSubstr("--set filter.enable_distant_filter=false"));
  EXPECT_THAT(run, HasSubstr("--overwrite --out " + (dir_ / "out" / "runs").string()));
  // geometry_only runs without detections, so it reads no cache.
  EXPECT_THAT(ShellCommand(b.runs[4].argv), HasSubstr("--detector none"));
  EXPECT_TRUE(b.runs[4].needs.empty());

  // The same plan gives the same names and commands; batch.json reads back to it.
  const Batch again = ExpandPlan(LoadPlan(file), dir_ / "out", "/bin/ademono");
  EXPECT_EQ(again.ToJson(), b.ToJson());
  EXPECT_EQ(Batch::FromJson(b.ToJson()).ToJson(), b.ToJson());
}

TEST_F(PlanTest, ARunIsCompleteOnlyWithAWholeSummary) {
  Task t;
  t.out = dir_ / "complete";
  fs::create_directories(t.out);
  EXPECT_FALSE(IsComplete(t));
  std::ofstream(t.out / "trajectory.tum") << "# timestamp tx ty tz qx qy qz qw\n";
  EXPECT_FALSE(IsComplete(t));
  std::ofstream(t.out / "summary.json") << R"({"schema": "ademono.run/1", "partial": true})";
  EXPECT_FALSE(IsComplete(t));  // a run stopped by a signal (scancel) is not done
  std::ofstream(t.out / "summary.json") << R"({"schema": "ademono.run/1", "partial": false})";
  EXPECT_TRUE(IsComplete(t));
  std::ofstream(t.out / "summary.json") << R"({"schema": "ademono.run/1", "par)";
  EXPECT_FALSE(IsComplete(t));
}

TEST_F(PlanTest, SlurmScriptRunsTaskIOfTheArrayWithItsLog) {
  Task a, b;
  a.id = "x__full__s1";
  a.argv = {"/bin/ademono", "run", "--out", "/o/runs/x__full__s1"};
  a.log = "/o/logs/x__full__s1.log";
  b.id = "x__full__s2";
  b.argv = {"/bin/ademono",           "run",   "--set",
            "depth.max_depth=6 ; rm", "--out", "/o/runs/x__full__s2"};
  b.log = "/o/logs/x__full__s2.log";
  SlurmSettings s;
  s.partition = "gpu";
  s.time = "01:00:00";
  s.mem = "4G";
  s.cpus_per_task = 2;
  s.max_parallel = 5;
  const std::string script = SlurmScript("ademono-p-runs", {&a, &b}, s, "/o/slurm", "runs", 1);
  EXPECT_THAT(script, HasSubstr("#SBATCH --array=0-1%5\n"));
  EXPECT_THAT(script, HasSubstr("#SBATCH --partition=gpu\n"));
  EXPECT_THAT(script, HasSubstr("#SBATCH --time=01:00:00\n"));
  EXPECT_THAT(script, HasSubstr("#SBATCH --mem=4G\n"));
  EXPECT_THAT(script, HasSubstr("#SBATCH --cpus-per-task=2\n"));
  EXPECT_THAT(
      script,
      HasSubstr("  0)  # x__full__s1\n    mkdir -p /o/logs\n    exec /bin/ademono run --out "
                "/o/runs/x__full__s1 >/o/logs/x__full__s1.log 2>&1 ;;\n"));
  // A word with shell syntax stays one quoted word.
  EXPECT_THAT(script, HasSubstr("--set 'depth.max_depth=6 ; rm' --out"));
}

// Every `ablate` variant as `run --set` overrides gives the switches RunAblationVariant sets.
TEST(AblationOverridesTest, SetTheSameSwitchesAsAblate) {
  for (const AblationVariant& v : AllAblationVariants()) {
    SCOPED_TRACE(v.name);
    const SystemOptions o =
        SystemOptions::FromYaml(LoadConfigWithOverrides("", AblationSetOverrides(v)), "(test)");
    EXPECT_EQ(o.filter.enable_enhancement, v.enhancement);
    EXPECT_EQ(o.filter.enable_dynamic_removal, v.dynamic_removal);
    EXPECT_EQ(o.filter.enable_distant_filter, v.distant_filter);
    EXPECT_EQ(o.tracking.static_test, v.geometric_test);
    EXPECT_EQ(o.filter.dynamic.judge_small_boxes,
              v.paper_small_boxes ? false : SystemOptions().filter.dynamic.judge_small_boxes);
    EXPECT_EQ(FindAblationVariant(v.name), &v);
  }
  EXPECT_EQ(FindAblationVariant("no_such_variant"), nullptr);
}

}  // namespace
}  // namespace ademono::batch
