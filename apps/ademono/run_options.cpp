#include "run_options.h"

#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <regex>

#include "ademono/core/error.h"
#include "ademono/depth/depth_factory.h"
#include "ademono/runner/config_file.h"

namespace fs = std::filesystem;

namespace ademono::cli {

void AddSequenceRunOptions(CLI::App& app, SequenceRunArgs& args) {
  app.add_option("--dataset", args.dataset, "KIND:PATH (tum, kitti, euroc, 7scenes, folder, video)")
      ->required();
  app.add_option("--config", args.config, "config YAML (default: configs/<family>.yaml)");
  app.add_option("--depth", args.depth,
                 "none | sensor | cache:DIR | simulated[:k=v,...] | model:FILE.onnx")
      ->capture_default_str();
  app.add_option("--detector", args.detector, "none | cache:FILE.jsonl | model:FILE.onnx")
      ->capture_default_str();
  app.add_option("--frames", args.frames, "START:END frame range (END exclusive)");
  app.add_option(
      "--seed", args.seed,
      "random seed of the distant filter and the two-view initialiser's RANSAC: N or 'time' "
      "(default: the config's filter.seed and initializer.seed)");
  app.add_flag("--no-overlap", args.no_overlap,
               "compute depth/detections sequentially (no prefetch)");
  app.add_option("--prefetch-frames", args.prefetch_frames,
                 "frames prepared ahead at once, on both cores (default: 2)")
      ->check(CLI::Range(1, 8));
  app.add_option("--viz", args.viz, "write per-frame images with filter labels into DIR");
  app.add_option("--camera", args.camera, "camera YAML (overrides the dataset's)");
  app.add_option("--set", args.set,
                 "override a config key: SECTION.KEY=VALUE (repeatable), e.g. "
                 "--set depth.scale_correction=false");
  app.add_option("--out", args.out, "output directory")->required();
}

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

namespace {

// The three TUM Kinects by their published intrinsics (io/sequence_tum.cpp), so that a TUM-layout
// folder is recognised by its camera, not by its name.
std::string TumKinectOf(const Camera& camera) {
  struct Kinect {
    const char* name;
    double fx, fy, cx, cy;
  };
  static const Kinect kKinects[] = {{"tum_fr1.yaml", 517.3, 516.5, 318.6, 255.3},
                                    {"tum_fr2.yaml", 520.9, 521.0, 325.1, 249.7},
                                    {"tum_fr3.yaml", 535.4, 539.2, 320.1, 247.6}};
  if (camera.width != 640 || camera.height != 480) return {};
  for (const Kinect& k : kKinects) {
    if (std::abs(camera.fx - k.fx) < 1.0 && std::abs(camera.fy - k.fy) < 1.0 &&
        std::abs(camera.cx - k.cx) < 1.0 && std::abs(camera.cy - k.cy) < 1.0)
      return k.name;
  }
  return {};
}

}  // namespace

ConfigChoice DefaultConfig(const std::string& kind, const std::string& path, const Camera& camera) {
  if (kind == "tum") {
    const std::string kinect = TumKinectOf(camera);
    if (!kinect.empty())
      return {kinect, "a TUM RGB-D freiburg" + kinect.substr(6, 1) + " Kinect by its intrinsics"};
    // Another sensor in the TUM layout (Bonn RGB-D Dynamic, own recordings): no Kinect's tuning.
    return {"rgbd_generic.yaml",
            fmt::format("a TUM-layout folder whose camera (fx {:.1f}, {}x{}) is no TUM Kinect",
                        camera.fx, camera.width, camera.height)};
  }
  const std::string why = "the " + kind + " dataset family";
  if (kind == "kitti") {
    std::smatch m;
    int sequence = 0;
    if (std::regex_search(path, m, std::regex("(\\d{2})(?!.*\\d)")))
      sequence = std::stoi(m[1].str());
    if (sequence <= 2) return {"kitti_00-02.yaml", why};
    if (sequence == 3) return {"kitti_03.yaml", why};
    return {"kitti_04-12.yaml", why};
  }
  if (kind == "7scenes") return {"7scenes.yaml", why};
  if (kind == "euroc") return {"euroc.yaml", why};
  return {kind + ".yaml", why};
}

fs::path ResolveConfigPath(const std::string& config_arg, const Sequence& sequence,
                           const std::string& depth_arg) {
  if (!config_arg.empty()) {
    spdlog::info("config: {} (--config)", config_arg);
    return config_arg;
  }
  const fs::path dir = FindConfigDir();
  const DepthSourceInfo depth = DescribeDepthSource(depth_arg);
  const ConfigChoice choice =
      DefaultConfig(sequence.Kind(), sequence.Path().string(), sequence.GetCamera());
  std::string name = choice.name;
  std::string why = choice.why;
  if (depth.network || depth.none) {
    // The monocular core's two families, with a network or without depth.
    const bool outdoor =
        depth.domain == "outdoor" || (depth.domain.empty() && sequence.Kind() == "kitti");
    name = outdoor ? "network_outdoor.yaml" : "network_indoor.yaml";
    why = std::string(depth.none ? "no depth (monocular), " : "depth from a network, ") +
          (outdoor ? "outdoor" : "indoor");
  }
  const fs::path candidate = dir / name;
  if (!dir.empty() && fs::exists(candidate)) {
    spdlog::info("config: {} ({})", candidate.string(), why);
    return candidate;
  }
  spdlog::warn("no config for '{}' found ({}); using built-in defaults", sequence.Kind(),
               candidate.string());
  return {};
}

void ApplyDepthSource(const std::string& depth_arg, SystemOptions& options) {
  const DepthSourceInfo depth = DescribeDepthSource(depth_arg);
  if (depth.none) {
    // Whatever the config: without depth only the monocular core can run, and no error model
    // describes depths that do not exist.
    options.tracking.monocular = true;
    options.depth.error_relative = 0;
    options.depth.error_per_metre = 0;
    // The enhancement walk is weighted by depth: without depth it would only drop keypoints.
    options.filter.enable_enhancement = false;
    return;
  }
  if (!depth.network || !depth.error_model.Enabled() || !options.depth.IsPrior()) return;
  options.depth.error_relative = depth.error_model.relative;
  options.depth.error_per_metre = depth.error_model.per_metre;
}

void ApplyDatasetCameraHeight(const YAML::Node& config, const Sequence& sequence,
                              SystemOptions& options) {
  const std::optional<double> height = sequence.CameraHeight();
  if (!height) return;
  const bool set = config && config.IsMap() && config["depth"] && config["depth"].IsMap() &&
                   config["depth"]["camera_height"];
  if (set) {
    spdlog::info("depth.camera_height: {} m from the config (the {} rig's is {} m)",
                 options.depth.camera_height, sequence.Kind(), *height);
    return;
  }
  options.depth.camera_height = *height;
  spdlog::info("depth.camera_height: {} m, the {} rig's (set depth.camera_height to change it)",
               *height, sequence.Kind());
}

YAML::Node LoadConfig(const fs::path& path, const std::vector<std::string>& overrides) {
  return LoadConfigWithOverrides(path, overrides);
}

SystemOptions SystemOptionsFromConfig(const YAML::Node& config, const fs::path& path,
                                      const std::vector<std::string>& overrides) {
  try {
    return SystemOptions::FromYaml(config, path);
  } catch (const InputError&) {
    if (overrides.empty()) throw;
    SystemOptions::FromYaml(LoadConfigWithOverrides(path), path);  // the file's own error
    std::string label = "--set";
    for (const std::string& item : overrides) label += " " + item;
    return SystemOptions::FromYaml(config, label);
  }
}

DetectorOptions DetectorOptionsFromConfig(const YAML::Node& config, const fs::path& config_path) {
  try {
    return DetectorOptions::FromYaml(config["detector"]);
  } catch (const std::exception& e) {
    ThrowInputError(config_path, e.what());
  }
}

void ParseFrames(const std::string& text, size_t size, size_t* start, size_t* end) {
  static const std::regex pattern("^(\\d*):(\\d*)$");
  std::smatch m;
  if (!std::regex_match(text, m, pattern)) {
    throw InputError("--frames '" + text + "': expected START:END (either may be empty)");
  }
  if (!m[1].str().empty()) *start = std::stoull(m[1].str());
  if (!m[2].str().empty()) *end = std::stoull(m[2].str());
  if (*end <= *start) throw InputError("--frames '" + text + "': END must be greater than START");
  if (*start >= size) {
    throw InputError("--frames '" + text + "': sequence has only " + std::to_string(size) +
                     " frames");
  }
}

uint64_t ParseSeed(const std::string& text) {
  if (text == "time") {
    return static_cast<uint64_t>(std::chrono::system_clock::now().time_since_epoch().count());
  }
  try {
    size_t used = 0;
    const uint64_t seed = std::stoull(text, &used);
    if (used == text.size() && text.find('-') == std::string::npos) return seed;
  } catch (const std::exception&) {
  }
  throw InputError("--seed '" + text + "': expected a non-negative integer or 'time'");
}

}  // namespace ademono::cli
