// Issue 16 part 5: more bad input, end to end. Every case: exit code 2, one line naming the file
// and the problem, and no output written.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <string>
#include <tuple>
#include <vector>

#include "ademono/core/camera.h"
#include "cli_test_util.h"

namespace {

using namespace ademono::cli_test;
namespace fs = std::filesystem;
const fs::path kModels = fs::path(ADEMONO_SOURCE_DIR) / "tests/data/models";

constexpr int kW = 64, kH = 48;  // the test depth models' input size

cv::Mat Textured(int width, int height, int seed) {
  cv::Mat image(height, width, CV_8UC3);
  cv::RNG rng(seed);
  rng.fill(image, cv::RNG::UNIFORM, 0, 255);
  cv::GaussianBlur(image, image, cv::Size(3, 3), 0);
  return image;
}

ademono::Camera TestCamera(int width = kW, int height = kH) {
  return ademono::Camera::Pinhole(width, height, 50, width / 2.0, height / 2.0);
}

class BadInputCliTest : public testing::Test {
 protected:
  void SetUp() override {
    dir_ = FreshTempDir(std::string("bad_input_") +
                        testing::UnitTest::GetInstance()->current_test_info()->name());
    out_ = dir_ / "out";
  }
  void TearDown() override { fs::remove_all(dir_); }

  // folder: dataset of `frames` images named 000000.png ... with the test camera beside them.
  fs::path MakeFolder(int frames) const {
    const fs::path folder = dir_ / "seq";
    fs::create_directories(folder);
    for (int i = 0; i < frames; ++i) {
      char name[32];
      std::snprintf(name, sizeof(name), "%06d.png", i);
      cv::imwrite((folder / name).string(), Textured(kW, kH, i));
    }
    ademono::WriteCameraYaml(folder / "camera.yaml", TestCamera());
    return folder;
  }

  // Runs `ademono ARGS` and checks the contract; `needle` must be in the one line printed.
  void ExpectBadInput(const std::string& args, const std::string& needle,
                      const fs::path& output) const {
    SCOPED_TRACE(args);
    const CliResult r = RunCli(args);
    EXPECT_EQ(r.code, 2) << r.out;
    // The error is one line, the last one printed (a warning such as "no config found" may
    // come before it).
    std::vector<std::string> lines;
    for (size_t begin = 0; begin < r.out.size();) {
      const size_t end = std::min(r.out.find('\n', begin), r.out.size());
      lines.push_back(r.out.substr(begin, end - begin));
      begin = end + 1;
    }
    ASSERT_FALSE(lines.empty());
    EXPECT_EQ(std::count_if(lines.begin(), lines.end(),
                            [](const std::string& l) { return l.find("error") != l.npos; }),
              1)
        << r.out;
    EXPECT_THAT(lines.back(), testing::HasSubstr(": error: "));
    EXPECT_THAT(lines.back(), testing::HasSubstr(needle));
    EXPECT_FALSE(fs::exists(output)) << output;
  }

  void ExpectRunFails(const std::string& args, const std::string& needle) const {
    ExpectBadInput("run " + args + " --out " + out_.string(), needle, out_ / "trajectory.tum");
    EXPECT_FALSE(fs::exists(out_ / "summary.json"));
    EXPECT_FALSE(fs::exists(out_ / "map.ply"));
  }

  fs::path dir_, out_;
};

// Arguments the parser rejects are bad input too: one line naming the option, exit code 2.
TEST_F(BadInputCliTest, ArgumentsOutOfRangeOrUnknown) {
  const fs::path folder = MakeFolder(3);
  ExpectRunFails("--dataset folder:" + folder.string() + " --prefetch-frames 0",
                 "--prefetch-frames: Value 0 not in range 1 to 8");
  ExpectRunFails("--dataset folder:" + folder.string() + " --no-such-flag", "--no-such-flag");
  ExpectBadInput("--log-level loud run --dataset folder:" + folder.string() + " --out " +
                     out_.string(),
                 "--log-level", out_ / "trajectory.tum");
  // Every name spdlog reads stays valid ("warning" as well as "warn").
  EXPECT_EQ(RunCli("--log-level warning synth --scene office --frames 2 --out " +
                   (dir_ / "warning").string())
                .code,
            0);
}

TEST_F(BadInputCliTest, DepthModelsOfTheWrongShapeTypeOrOpset) {
  const fs::path folder = MakeFolder(3);
  const fs::path image = folder / "000000.png";
  const fs::path depth_out = dir_ / "depth.png";
  const std::string camera = (folder / "camera.yaml").string();
  const std::vector<std::pair<std::string, std::string>> cases{
      {"depth_bad_output.onnx", "1x2x48x64"},
      {"depth_uint8_input.onnx", "is not a float tensor"},
      {"depth_double_output.onnx", "is not a float tensor"},
      {"depth_opset99.onnx", "cannot load ONNX model"},
      {"det_yolov8.onnx", "depth model output must be"},
  };
  for (const auto& [model, problem] : cases) {
    const std::string path = (kModels / model).string();
    ExpectBadInput("depth --depth model:" + path + " --camera " + camera + " --out " +
                       depth_out.string() + " " + image.string(),
                   path + ": ", depth_out);
    ExpectBadInput("depth --depth model:" + path + " --camera " + camera + " --out " +
                       depth_out.string() + " " + image.string(),
                   problem, depth_out);
    ExpectRunFails("--dataset folder:" + folder.string() + " --depth model:" + path, path + ": ");
  }
}

TEST_F(BadInputCliTest, DetectorModelsOfTheWrongShapeTypeOrOpset) {
  const fs::path folder = MakeFolder(3);
  const fs::path json = dir_ / "det.json";
  const std::vector<std::pair<std::string, std::string>> cases{
      {"det_double_output.onnx,arch=yolov8", "is not a float tensor"},
      {"depth_opset99.onnx,arch=yolov8", "cannot load ONNX model"},
      {"depth_metric.onnx,arch=yolov8", "1x1x48x64"},
      {"det_yolov5.onnx,arch=yolox", "grid cells"},
  };
  for (const auto& [model, problem] : cases) {
    const std::string path = (kModels / model.substr(0, model.find(','))).string();
    ExpectBadInput("detect --detector model:" + (kModels / model).string() + " --json " +
                       json.string() + " " + (folder / "000000.png").string(),
                   problem, json);
    ExpectRunFails("--dataset folder:" + folder.string() + " --depth model:" +
                       (kModels / "depth_metric.onnx").string() + " --detector model:" +
                       (kModels / model).string(),
                   path + ": ");
  }
}

TEST_F(BadInputCliTest, ModelSpecThatDoesNotFitItsModel) {
  const fs::path folder = MakeFolder(3);
  const std::vector<std::pair<std::string, std::string>> specs{
      {"input:\n  width: 32\n  height: 32\n", "32x32"},            // fixed model is 64x48
      {"input:\n  resize: multiple\n  multiple_of: 8\n", "fixed size"},  // needs a dynamic model
      {"output:\n  kind: metric\n  scale: -1\n", "scale"},
  };
  for (size_t i = 0; i < specs.size(); ++i) {
    const fs::path spec = dir_ / ("spec" + std::to_string(i) + ".yaml");
    std::ofstream(spec) << specs[i].first;
    ExpectRunFails("--dataset folder:" + folder.string() + " --depth model:" +
                       (kModels / "depth_metric.onnx").string() + ",spec=" + spec.string(),
                   specs[i].second);
  }
}

TEST_F(BadInputCliTest, ImageSizeThatChangesMidSequence) {
  const fs::path folder = MakeFolder(6);
  cv::imwrite((folder / "000003.png").string(), Textured(kW + 8, kH, 3));
  ExpectRunFails("--dataset folder:" + folder.string() + " --depth model:" +
                     (kModels / "depth_metric.onnx").string(),
                 (folder / "000003.png").string() + ": image is 72x48, the camera is 64x48");
}

TEST_F(BadInputCliTest, CameraThatContradictsTheImages) {
  const fs::path folder = MakeFolder(3);
  const std::string run = "--dataset folder:" + folder.string() + " --depth model:" +
                          (kModels / "depth_metric.onnx").string() + " --camera ";
  // Calibrated at another resolution.
  const fs::path big = dir_ / "big.yaml";
  ademono::WriteCameraYaml(big, TestCamera(640, 480));
  ExpectRunFails(run + big.string(),
                 (folder / "000000.png").string() + ": image is 64x48, the camera is 640x480");
  // Principal point outside the image.
  for (const auto& [name, cx, cy] : {std::tuple{"cx.yaml", 70.0, 24.0},
                                     std::tuple{"cy.yaml", 32.0, -3.0}}) {
    ademono::Camera camera = TestCamera();
    camera.cx = cx;
    camera.cy = cy;
    const fs::path yaml = dir_ / name;
    ademono::WriteCameraYaml(yaml, camera);
    ExpectRunFails(run + yaml.string(), yaml.string() + ": ");
    ExpectRunFails(run + yaml.string(), "outside the image");
  }
}

// An MJPG video of `frames` textured frames.
fs::path WriteVideo(const fs::path& path, int frames) {
  cv::VideoWriter writer(path.string(), cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 10.0,
                         cv::Size(kW, kH));
  if (!writer.isOpened()) return {};
  for (int i = 0; i < frames; ++i) writer.write(Textured(kW, kH, i));
  writer.release();
  return path;
}

TEST_F(BadInputCliTest, VideoWithCorruptOrMissingFrames) {
  const fs::path video = WriteVideo(dir_ / "clip.avi", 12);
  if (video.empty()) GTEST_SKIP() << "OpenCV cannot write MJPG AVI here";
  ademono::WriteCameraYaml(dir_ / "camera.yaml", TestCamera());
  std::string bytes = ReadFile(video);
  ASSERT_GT(bytes.size(), 4000u);

  const std::string depth = " --depth model:" + (kModels / "depth_metric.onnx").string();
  // Not a video at all, and a file cut off inside its header.
  const fs::path text = dir_ / "text.avi";
  std::ofstream(text) << "not a video";
  ExpectRunFails("--dataset video:" + text.string() + depth, text.string() + ": ");
  const fs::path header_only = dir_ / "header_only.avi";
  std::ofstream(header_only, std::ios::binary) << bytes.substr(0, 200);
  ExpectRunFails("--dataset video:" + header_only.string() + depth, header_only.string() + ": ");
  // Ends early: cut off after about half of its 12 frames.
  const fs::path cut = dir_ / "cut.avi";
  std::ofstream(cut, std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  ExpectRunFails("--dataset video:" + cut.string() + depth,
                 cut.string() + ": frame 5 does not decode, but the video declares 12 frames");
  // A corrupt frame in the middle: frame 6's JPEG data zeroed.
  size_t soi = 0;
  for (int frame = 0; frame <= 6; ++frame) soi = bytes.find("\xff\xd8", soi + 1);
  ASSERT_NE(soi, std::string::npos);
  std::fill(bytes.begin() + soi, bytes.begin() + soi + 2000, '\0');
  const fs::path corrupt = dir_ / "corrupt.avi";
  std::ofstream(corrupt, std::ios::binary) << bytes;
  ExpectRunFails("--dataset video:" + corrupt.string() + depth,
                 corrupt.string() + ": frame 6 does not decode, but the video declares 12 frames");
}

}  // namespace

namespace {

// Issue 15 part 4: a live camera that is not there fails like any bad input (this machine, like
// CI, has no camera; device 63 and a path that is not a device are never one).
TEST_F(BadInputCliTest, CameraThatDoesNotExist) {
  const fs::path yaml = dir_ / "camera.yaml";
  ademono::WriteCameraYaml(yaml, TestCamera());
  ExpectRunFails("--dataset camera:63 --camera " + yaml.string(),
                 "camera:63: cannot open the camera");
  ExpectRunFails("--dataset camera:" + (dir_ / "nodevice").string() + " --camera " + yaml.string(),
                 "cannot open the camera");
  ExpectRunFails("--dataset camera:0", "camera:0: a live camera needs a camera YAML");
}

}  // namespace
