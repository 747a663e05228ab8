// `ademono ablate`: the filter ablation (full / no_dynamic / no_distant / no_dynamic_no_distant /
// no_enhancement) over one sequence; each variant's run outputs go into --out/<variant>/, the
// comparison into --out/ablation.md and --out/ablation.json. The work is in slam/ablation.h.
#include <spdlog/spdlog.h>
#include <yaml-cpp/yaml.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <opencv2/imgproc.hpp>
#include <regex>
#include <sstream>
#include <string>

#include "ademono/core/error.h"
#include "ademono/core/file_util.h"
#include "ademono/depth/depth_factory.h"
#include "ademono/detect/detector_factory.h"
#include "ademono/filter/visualize.h"
#include "ademono/io/sequence.h"
#include "ademono/slam/ablation.h"
#include "command.h"

namespace fs = std::filesystem;

namespace ademono::cli {
namespace {

struct AblateArgs {
  std::string dataset;
  std::string config;
  std::string depth = "sensor";
  std::string detector = "none";
  std::string frames;
  std::string seed;
  std::string variants;  // comma-separated subset, empty: all five
  bool no_overlap = false;
  std::string viz;
  std::string camera;
  std::string out;
};

// Same lookup as `ademono run`: $ADEMONO_CONFIG_DIR, ./configs, or the source tree of the binary.
fs::path FindConfigDir() {
  if (const char* env = std::getenv("ADEMONO_CONFIG_DIR"); env != nullptr && *env != '\0')
    return env;
  if (fs::is_directory("configs")) return "configs";
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    for (fs::path dir = exe.parent_path(); !dir.empty() && dir != dir.root_path();
         dir = dir.parent_path()) {
      if (fs::is_directory(dir / "configs") && fs::exists(dir / "CMakeLists.txt"))
        return dir / "configs";
    }
  }
  return {};
}

std::string DefaultConfigName(const std::string& kind, const std::string& path) {
  if (kind == "tum") {
    std::smatch m;
    if (std::regex_search(path, m, std::regex("(freiburg|fr)([123])")))
      return "tum_fr" + m[2].str() + ".yaml";
    return "tum_fr1.yaml";
  }
  if (kind == "kitti") {
    std::smatch m;
    int sequence = 0;
    if (std::regex_search(path, m, std::regex("(\\d{2})(?!.*\\d)")))
      sequence = std::stoi(m[1].str());
    if (sequence <= 2) return "kitti_00-02.yaml";
    if (sequence == 3) return "kitti_03.yaml";
    return "kitti_04-12.yaml";
  }
  if (kind == "7scenes") return "7scenes.yaml";
  if (kind == "euroc") return "euroc.yaml";
  return kind + ".yaml";
}

std::vector<AblationVariant> SelectVariants(const std::string& list) {
  const auto& all = DefaultAblationVariants();
  if (list.empty()) return all;
  std::vector<AblationVariant> chosen;
  std::stringstream ss(list);
  std::string name;
  while (std::getline(ss, name, ',')) {
    auto it = std::find_if(all.begin(), all.end(),
                           [&](const AblationVariant& v) { return v.name == name; });
    if (it == all.end()) {
      std::string names;
      for (const auto& v : all) names += (names.empty() ? "" : ", ") + v.name;
      throw InputError("--variants: unknown variant '" + name + "' (known: " + names + ")");
    }
    chosen.push_back(*it);
  }
  if (chosen.empty()) throw InputError("--variants: empty list");
  return chosen;
}

int Ablate(const AblateArgs& args) {
  const std::vector<AblationVariant> variants = SelectVariants(args.variants);
  std::optional<fs::path> camera_yaml;
  if (!args.camera.empty()) camera_yaml = args.camera;
  const std::unique_ptr<Sequence> sequence = OpenSequence(args.dataset, camera_yaml);

  fs::path config_path = args.config;
  if (config_path.empty()) {
    const fs::path dir = FindConfigDir();
    const fs::path candidate = dir / DefaultConfigName(sequence->Kind(), sequence->Path().string());
    if (!dir.empty() && fs::exists(candidate)) {
      config_path = candidate;
    } else {
      spdlog::warn("no config for '{}' found ({}); using built-in defaults", sequence->Kind(),
                   candidate.string());
    }
  }
  YAML::Node config;
  if (!config_path.empty()) {
    RequireFile(config_path);
    try {
      config = YAML::LoadFile(config_path.string());
    } catch (const YAML::Exception& e) {
      ThrowInputError(config_path, std::string("invalid YAML: ") + e.msg);
    }
  }
  AblationOptions options;
  options.system = SystemOptions::FromYaml(config, config_path);
  options.variants = variants;
  DetectorOptions detector_options;
  try {
    if (const YAML::Node d = config["detector"]) {
      if (d["score_threshold"]) detector_options.score_threshold = d["score_threshold"].as<float>();
      if (d["nms_iou"]) detector_options.nms_iou = d["nms_iou"].as<float>();
    }
    detector_options.Check();
  } catch (const std::exception& e) {
    ThrowInputError(config_path, std::string("detector: ") + e.what());
  }
  if (!args.seed.empty()) {
    try {
      size_t used = 0;
      options.system.filter.seed = std::stoull(args.seed, &used);
      if (used != args.seed.size()) throw std::invalid_argument("trailing characters");
    } catch (const std::exception&) {
      throw InputError("--seed '" + args.seed + "': expected a non-negative integer");
    }
  }
  if (!args.frames.empty()) {
    static const std::regex pattern("^(\\d*):(\\d*)$");
    std::smatch m;
    if (!std::regex_match(args.frames, m, pattern))
      throw InputError("--frames '" + args.frames + "': expected START:END (either may be empty)");
    if (!m[1].str().empty()) options.pipeline.start = std::stoull(m[1].str());
    if (!m[2].str().empty()) options.pipeline.end = std::stoull(m[2].str());
    if (options.pipeline.end <= options.pipeline.start)
      throw InputError("--frames '" + args.frames + "': END must be greater than START");
  }
  if (options.pipeline.start >= sequence->Size()) {
    throw InputError("--frames '" + args.frames + "': sequence has only " +
                     std::to_string(sequence->Size()) + " frames");
  }
  options.pipeline.overlap = !args.no_overlap;

  DepthFactoryContext context;
  context.sequence = sequence.get();
  context.seed = options.system.filter.seed;
  std::unique_ptr<DepthProvider> depth = MakeDepthProvider(args.depth, context);
  std::unique_ptr<Detector> detector = MakeDetector(args.detector, detector_options);

  const size_t total = std::min(options.pipeline.end, sequence->Size()) - options.pipeline.start;
  size_t done = 0;
  options.on_frame = [&](const AblationVariant& v, const FrameData& frame,
                         const std::vector<Detection>& detections, const TrackResult& r) {
    ++done;
    if (!args.viz.empty()) {
      FilterOptions filter = options.system.filter;
      filter.enable_dynamic_removal = v.dynamic_removal;
      std::ostringstream name;
      name << "frame-" << std::setw(6) << std::setfill('0') << frame.index << ".jpg";
      WriteImageAtomic(fs::path(args.viz) / v.name / name.str(),
                       DrawFilterResult(frame.image, r.keypoints, r.labels, detections, filter));
    }
    if (done % total == 0) {
      std::fprintf(stderr, "ademono ablate: variant %s done (%zu frames)\n", v.name.c_str(), total);
    }
  };
  if (!args.viz.empty()) {
    for (const auto& v : variants) fs::create_directories(fs::path(args.viz) / v.name);
  }
  const std::vector<VariantResult> results =
      RunAblation(*sequence, depth.get(), detector.get(), options, args.out);
  std::cout << AblationMarkdown(results);
  return 0;
}

const bool kRegistered = RegisterCommand(
    "ablate",
    "Run the filter ablation (5 variants) over a sequence: ATE, tracking, filter counts table",
    [](CLI::App& app) -> Runner {
      auto args = std::make_shared<AblateArgs>();
      app.add_option("--dataset", args->dataset,
                     "KIND:PATH (tum, kitti, euroc, 7scenes, folder, video)")
          ->required();
      app.add_option("--config", args->config, "config YAML (default: configs/<family>.yaml)");
      app.add_option("--depth", args->depth,
                     "sensor | cache:DIR | simulated[:k=v,...] | model:FILE.onnx")
          ->capture_default_str();
      app.add_option("--detector", args->detector, "none | cache:FILE.jsonl | model:FILE.onnx")
          ->capture_default_str();
      app.add_option("--frames", args->frames, "START:END frame range (END exclusive)");
      app.add_option("--seed", args->seed,
                     "random seed of the distant filter (default: the config's filter.seed)");
      app.add_option("--variants", args->variants,
                     "comma-separated subset of full,no_dynamic,no_distant,"
                     "no_dynamic_no_distant,no_enhancement (default: all)");
      app.add_flag("--no-overlap", args->no_overlap,
                   "compute depth/detections sequentially (no prefetch)");
      app.add_option("--viz", args->viz,
                     "write per-frame images with filter labels into DIR/<variant>/");
      app.add_option("--camera", args->camera, "camera YAML (overrides the dataset's)");
      app.add_option("--out", args->out, "output directory")->required();
      return [args] { return Ablate(*args); };
    });

}  // namespace
}  // namespace ademono::cli
