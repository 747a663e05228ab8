// The ablation library: variants on a short 7-Scenes slice (run folders, ATE, filter counts that
// follow the switches) and a sequence without ground truth (ATE null with a note).
#include "ademono/runner/ablation.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "../slam/slam_test_util.h"
#include "ademono/core/error.h"
#include "runner_test_util.h"

namespace fs = std::filesystem;

namespace ademono {
namespace {

using runner_test::FrameDepth;
using testing_util::Slice;

fs::path TempDir(const std::string& name) { return runner_test::TempDir("ablation_" + name); }

AblationOptions SliceOptions() {
  AblationOptions options;
  options.system.depth.min_depth = 0.3;
  options.system.depth.max_depth = 6.0;
  return options;
}

// Drops the ground truth of a sequence.
class NoGroundTruth : public Sequence {
 public:
  explicit NoGroundTruth(std::unique_ptr<Sequence> base) : base_(std::move(base)) {}
  std::string Kind() const override { return base_->Kind(); }
  fs::path Path() const override { return base_->Path(); }
  size_t Size() const override { return base_->Size(); }
  const Camera& GetCamera() const override { return base_->GetCamera(); }
  bool HasDepth() const override { return true; }
  bool HasGroundTruth() const override { return false; }
  double Timestamp(size_t i) const override { return base_->Timestamp(i); }
  FrameData Load(size_t i) const override {
    FrameData f = base_->Load(i);
    f.world_from_cam_gt.reset();
    return f;
  }

 private:
  std::unique_ptr<Sequence> base_;
};

TEST(AblationTest, VariantsWriteRunOutputsAndTables) {
  const auto sequence = Slice(0, 15);
  FrameDepth depth;
  // A person box over the right half from frame 5 on: the dynamic filter has work to do.
  class HalfBox : public Detector {
   public:
    std::string Name() const override { return "half-box"; }
    std::vector<Detection> Detect(const FrameData& frame) override {
      if (frame.index < 5) return {};
      Detection d;
      d.class_id = 0;
      d.score = 1.f;
      d.box = cv::Rect2f(320, 0, 320, 480);
      return {d};
    }
  } detector;
  AblationOptions options = SliceOptions();
  options.variants = {DefaultAblationVariants()[0], DefaultAblationVariants()[1]};
  const fs::path out = TempDir("variants");
  const std::vector<VariantResult> results =
      RunAblation(*sequence, &depth, &detector, options, out);
  ASSERT_EQ(results.size(), 2u);
  for (const VariantResult& r : results) {
    for (const char* file : {"trajectory.tum", "trajectory.kitti", "keyframes.tum", "map.ply",
                             "groundtruth.tum", "summary.json"})
      EXPECT_TRUE(fs::exists(out / r.variant.name / file)) << r.variant.name << " " << file;
    EXPECT_EQ(r.frames, 15u);
    EXPECT_EQ(r.tracked, 15u);
    ASSERT_TRUE(r.ate_se3_m.has_value());
    EXPECT_LT(*r.ate_se3_m, 0.05);
    EXPECT_TRUE(r.ate_sim3_m.has_value());
    EXPECT_TRUE(r.note.empty());
    EXPECT_FALSE(r.truth.has_value());           // no masks/ in 7-Scenes
    EXPECT_EQ(r.filters.distant_candidates, 0);  // all depth < 6 m
    EXPECT_GT(r.filters.removed_enhancement, 0);
  }
  EXPECT_EQ(results[0].variant.name, "full");
  EXPECT_EQ(results[0].filters.boxes_large, 10);
  EXPECT_GT(results[0].filters.RemovedDynamic(), 0);
  EXPECT_EQ(results[1].filters.RemovedDynamic(), 0);
  EXPECT_EQ(results[1].filters.boxes_large, 0);

  const std::string md = AblationMarkdown(results);
  EXPECT_NE(
      md.find(
          "| variant | enh | dyn | dist | geo | boxes | ATE se3 (m) | ATE sim3 (m) | tracked |"),
      std::string::npos);
  EXPECT_NE(md.find("| full | on | on | on | on | on |"), std::string::npos);
  EXPECT_NE(md.find("| no_dynamic | on | off | on | off | on |"), std::string::npos);
  std::ifstream json_file(out / "ablation.json");
  const nlohmann::json json = nlohmann::json::parse(json_file);
  ASSERT_EQ(json["variants"].size(), 2u);
  EXPECT_EQ(json["variants"][1]["variant"], "no_dynamic");
  EXPECT_EQ(json["variants"][0]["filter_counts"]["removed_dynamic"].get<long long>(),
            results[0].filters.RemovedDynamic());
  EXPECT_TRUE(fs::exists(out / "ablation.md"));
  std::ifstream summary_file(out / "full" / "summary.json");
  const nlohmann::json summary = nlohmann::json::parse(summary_file);
  EXPECT_EQ(summary["schema"], "ademono.run/1");  // the same run folder as `ademono run`
  EXPECT_EQ(summary["per_frame"].size(), 15u);
  EXPECT_EQ(summary["accuracy"]["ate_se3_rmse_m"].get<double>(), *results[0].ate_se3_m);
  EXPECT_FALSE(summary["filters"]["dynamic_removal"].is_null());
  std::ifstream no_dynamic_file(out / "no_dynamic" / "summary.json");
  EXPECT_FALSE(nlohmann::json::parse(no_dynamic_file)["filters"]["dynamic_removal"].get<bool>());
  fs::remove_all(out);
}

TEST(AblationTest, WithoutGroundTruthAteIsNullWithANote) {
  const NoGroundTruth sequence(Slice(0, 8));
  FrameDepth depth;
  AblationOptions options = SliceOptions();
  const fs::path out = TempDir("nogt");
  const VariantResult r = RunAblationVariant(sequence, &depth, nullptr, options,
                                             DefaultAblationVariants()[0], out / "full");
  EXPECT_FALSE(fs::exists(out / "full" / "groundtruth.tum"));
  std::ifstream summary_file(out / "full" / "summary.json");
  EXPECT_FALSE(nlohmann::json::parse(summary_file).contains("accuracy"));
  EXPECT_FALSE(r.ate_se3_m.has_value());
  EXPECT_EQ(r.note, "dataset has no ground truth");
  EXPECT_TRUE(r.ToJson()["ate_se3_rmse_m"].is_null());
  EXPECT_NE(AblationMarkdown({r}).find("n/a"), std::string::npos);
  fs::remove_all(out);
}

TEST(AblationTest, DefaultVariantsAreTheFivePaperVariants) {
  const auto& v = DefaultAblationVariants();
  ASSERT_EQ(v.size(), 5u);
  EXPECT_EQ(v[0].name, "full");
  EXPECT_TRUE(v[0].enhancement && v[0].dynamic_removal && v[0].distant_filter);
  EXPECT_FALSE(v[3].dynamic_removal || v[3].distant_filter);
  EXPECT_FALSE(v[4].enhancement);
  EXPECT_TRUE(v[4].dynamic_removal && v[4].distant_filter);
  // No dynamic handling at all: the geometric test goes with the boxes.
  EXPECT_FALSE(v[1].geometric_test || v[3].geometric_test);
}

TEST(AblationTest, AllVariantsAddBoxesOnlyAndGeometryOnly) {
  const auto& all = AllAblationVariants();
  ASSERT_EQ(all.size(), 7u);
  EXPECT_EQ(all[5].name, "boxes_only");
  EXPECT_TRUE(all[5].use_detector && all[5].dynamic_removal);
  EXPECT_FALSE(all[5].geometric_test);
  // The paper's rule: small boxes dropped whole; every other variant judges them.
  EXPECT_TRUE(all[5].paper_small_boxes);
  for (size_t i = 0; i < all.size(); ++i) {
    if (i != 5) {
      EXPECT_FALSE(all[i].paper_small_boxes) << all[i].name;
    }
  }
  EXPECT_EQ(all[6].name, "geometry_only");
  EXPECT_FALSE(all[6].use_detector);
  EXPECT_TRUE(all[6].geometric_test);
}

}  // namespace
}  // namespace ademono
