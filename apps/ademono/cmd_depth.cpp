// `ademono depth`: metric depth of one image from a depth provider (normally an ONNX model).
#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <opencv2/imgcodecs.hpp>

#include "ademono/core/camera.h"
#include "ademono/core/error.h"
#include "ademono/core/file_util.h"
#include "ademono/depth/depth_factory.h"
#include "ademono/depth/onnx_depth.h"
#include "command.h"

namespace {

struct DepthArgs {
  std::string depth;
  std::string camera;
  std::string image;
  std::string out;
  int threads = 1;
};

int RunDepth(const DepthArgs& args) {
  const std::filesystem::path out = args.out;
  std::string ext = out.extension().string();
  for (auto& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext != ".png" && ext != ".tif" && ext != ".tiff") {
    ademono::ThrowInputError(out, "--out must end in .png (uint16 mm) or .tif/.tiff (float m)");
  }
  const ademono::Camera camera = ademono::LoadCameraYaml(args.camera);
  ademono::FrameData frame;
  frame.name = std::filesystem::path(args.image).stem().string();
  frame.image = ademono::ReadImage(args.image, cv::IMREAD_COLOR);
  if (frame.image.cols != camera.width || frame.image.rows != camera.height) {
    ademono::ThrowInputError(
        args.image, fmt::format("image is {}x{} but the camera ({}) is {}x{}", frame.image.cols,
                                frame.image.rows, args.camera, camera.width, camera.height));
  }
  ademono::DepthFactoryContext context;
  context.num_threads = args.threads;
  auto provider = ademono::MakeDepthProvider(args.depth, context);
  const auto start = std::chrono::steady_clock::now();
  const cv::Mat depth = provider->Depth(frame, camera);
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  std::vector<float> valid;
  for (int r = 0; r < depth.rows; ++r) {
    for (int c = 0; c < depth.cols; ++c) {
      if (depth.at<float>(r, c) > 0) valid.push_back(depth.at<float>(r, c));
    }
  }
  const cv::Mat preview = ademono::ColouriseDepth(depth);
  std::filesystem::path preview_path = out;
  preview_path.replace_filename(out.stem().string() + "_preview.png");
  ademono::WriteDepthMap(out, depth);
  ademono::WriteImageAtomic(preview_path, preview);
  std::cout << fmt::format("{}: {}x{}, {:.1f}% valid", out.string(), depth.cols, depth.rows,
                           100.0 * valid.size() / depth.total());
  if (!valid.empty()) {
    std::sort(valid.begin(), valid.end());
    std::cout << fmt::format(", depth min {:.3f} median {:.3f} max {:.3f} m", valid.front(),
                             valid[valid.size() / 2], valid.back());
  }
  std::cout << fmt::format("\npreview: {}\n", preview_path.string());
  std::cerr << fmt::format("{}: {:.1f} ms\n", provider->Name(), ms);
  return 0;
}

const bool kRegistered = ademono::cli::RegisterCommand(
    "depth", "Metric depth of one image from an ONNX model",
    [](CLI::App& app) -> ademono::cli::Runner {
      auto args = std::make_shared<DepthArgs>();
      app.add_option("--depth", args->depth, "model:FILE.onnx[,spec=SPEC.yaml]")->required();
      app.add_option("--camera", args->camera, "camera YAML (intrinsics of the image)")->required();
      app.add_option("--out", args->out,
                     "DEPTH.png (uint16 mm) or DEPTH.tiff (float m); also writes "
                     "<stem>_preview.png")
          ->required();
      app.add_option("--threads", args->threads, "ONNX Runtime intra-op threads")
          ->capture_default_str();
      app.add_option("image", args->image, "image file")->required();
      return [args] { return RunDepth(*args); };
    });

}  // namespace
