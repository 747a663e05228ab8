// `ademono infer` end to end: cache depth and detections for a few real frames, then read them
// back through `cache:` providers exactly as `ademono run` would.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "ademono/depth/depth_factory.h"
#include "ademono/depth/onnx_depth.h"
#include "ademono/detect/detector_factory.h"
#include "ademono/io/sequence.h"
#include "cli_test_util.h"

namespace {

using namespace ademono::cli_test;
namespace fs = std::filesystem;
const fs::path kModels = fs::path(ADEMONO_SOURCE_DIR) / "tests/data/models";
const fs::path kSevenScenes = fs::path(ADEMONO_SHARED_DIR) / "data/7scenes-seq-a";
const std::string kDataset = "7scenes:" + kSevenScenes.string();

// The largest difference between the cached depth of each frame in [begin, end) and the model's
// own depth for it, as `run --depth cache:DEPTH_DIR` would read it.
std::vector<double> ReplayErrors(const fs::path& depth_dir, size_t begin, size_t end) {
  auto sequence = ademono::OpenSequence(kDataset);
  ademono::DepthFactoryContext context;
  context.sequence = sequence.get();
  auto cached = ademono::MakeDepthProvider("cache:" + depth_dir.string(), context);
  ademono::OnnxDepthProvider model(kModels / "depth_metric.onnx", {}, {});
  std::vector<double> errors;
  for (size_t i = begin; i < end; ++i) {
    const ademono::FrameData frame = sequence->Load(i);
    const cv::Mat expected = model.Depth(frame, sequence->GetCamera());
    const cv::Mat actual = cached->Depth(frame, sequence->GetCamera());
    EXPECT_EQ(actual.size(), expected.size()) << "frame " << i;
    errors.push_back(actual.size() == expected.size()
                         ? cv::norm(actual, expected, cv::NORM_INF)
                         : std::numeric_limits<double>::infinity());
  }
  return errors;
}

TEST(InferCliTest, CachesReadBackThroughCacheProviders) {
  if (!fs::exists(kSevenScenes)) GTEST_SKIP() << "no " << kSevenScenes;
  const fs::path dir = FreshTempDir("infer_cli");
  const fs::path out = dir / "cache";
  const CliResult r = RunCli("infer --dataset " + kDataset + " --frames 2:5 --depth-model model:" +
                             (kModels / "depth_metric.onnx").string() +
                             " --detector model:" + (kModels / "det_yolov5.onnx").string() +
                             ",arch=yolov5 --classes all --out " + out.string());
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_THAT(r.out, testing::HasSubstr("3 frames (2..4)"));
  // Nothing but the results is left behind.
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);

  // float32 metres: the replay is the network's depth to the bit.
  for (const double error : ReplayErrors(out / "depth", 2, 5)) EXPECT_EQ(error, 0.0);
  auto sequence = ademono::OpenSequence(kDataset);
  ademono::DetectorOptions all;
  all.class_ids.clear();
  auto detections = ademono::MakeDetector("cache:" + (out / "detections.jsonl").string(), all);
  for (size_t i = 2; i < 5; ++i) {
    const auto boxes = detections->Detect(sequence->Load(i));
    ASSERT_EQ(boxes.size(), 2u);  // the constant head's two boxes
    EXPECT_EQ(boxes[0].class_id, 1);
  }
  EXPECT_EQ(std::distance(fs::directory_iterator(out / "depth"), fs::directory_iterator()), 3);
  EXPECT_TRUE(fs::exists(out / "depth" / (sequence->Load(2).name + ".tiff")));
  fs::remove_all(dir);
}

TEST(InferCliTest, PngDepthIsMillimetres) {
  if (!fs::exists(kSevenScenes)) GTEST_SKIP() << "no " << kSevenScenes;
  const fs::path dir = FreshTempDir("infer_cli_png");
  const fs::path out = dir / "cache";
  const CliResult r = RunCli("infer --dataset " + kDataset + " --frames 2:4 --depth-model model:" +
                             (kModels / "depth_metric.onnx").string() +
                             " --depth-format png --out " + out.string());
  ASSERT_EQ(r.code, 0) << r.out;
  auto sequence = ademono::OpenSequence(kDataset);
  for (size_t i = 2; i < 4; ++i) {
    EXPECT_TRUE(fs::exists(out / "depth" / (sequence->Load(i).name + ".png")));
  }
  for (const double error : ReplayErrors(out / "depth", 2, 4)) {
    EXPECT_LE(error, 0.0005 + 1e-6);  // millimetre rounding
    EXPECT_GT(error, 0.0);
  }
  // An unknown format is refused by the option parser (its own "ademono: error:" line).
  const CliResult bad = RunCli("infer --dataset " + kDataset + " --frames 2:4 --depth-model model:" +
                               (kModels / "depth_metric.onnx").string() +
                               " --depth-format jpg --out " + (dir / "bad").string());
  EXPECT_EQ(bad.code, 2) << bad.out;
  EXPECT_THAT(bad.out, testing::HasSubstr("--depth-format"));
  EXPECT_FALSE(fs::exists(dir / "bad"));
  fs::remove_all(dir);
}

TEST(InferCliTest, BadInputLeavesNoOutput) {
  if (!fs::exists(kSevenScenes)) GTEST_SKIP() << "no " << kSevenScenes;
  const fs::path dir = FreshTempDir("infer_cli_bad");
  const fs::path out = dir / "cache";
  const std::string base = "infer --dataset " + kDataset + " --out " + out.string() + " ";
  const std::string metric = "model:" + (kModels / "depth_metric.onnx").string();
  const std::vector<std::pair<std::string, std::string>> cases{
      {base, "nothing to do"},
      {base + "--depth-model " + metric + " --frames 5:2", "END must be greater"},
      {base + "--depth-model " + metric + " --frames 9000:", "only 600 frames"},
      {base + "--depth-model " + metric + " --frames 1-5", "expected START:END"},
      {base + "--depth-model model:" + (kModels / "depth_bad_output.onnx").string(), "1x2x48x64"},
      {base + "--detector model:" + (dir / "missing.onnx").string(), "missing.onnx"},
      {"infer --dataset 7scenes:" + (dir / "nowhere").string() + " --out " + out.string() +
           " --depth-model " + metric,
       "nowhere"},
  };
  for (const auto& [args, message] : cases) {
    SCOPED_TRACE(args);
    const CliResult r = RunCli(args);
    EXPECT_EQ(r.code, 2) << r.out;
    EXPECT_THAT(r.out, testing::StartsWith("ademono infer: error: "));
    EXPECT_THAT(r.out, testing::HasSubstr(message));
    EXPECT_FALSE(fs::exists(out));
  }
  fs::remove_all(dir);
}

}  // namespace
