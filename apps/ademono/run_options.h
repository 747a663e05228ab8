#pragma once
// Options shared by `ademono run` and `ademono ablate`: the dataset family's config file, the
// detector options in it, and the --frames / --seed arguments.

#include <yaml-cpp/yaml.h>

#include <CLI/CLI.hpp>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "ademono/detect/detector_factory.h"
#include "ademono/io/sequence.h"
#include "ademono/slam/options.h"

namespace ademono::cli {

// Arguments `run` and `ablate` share: what to run on, with which depth and detections, and where
// to write.
struct SequenceRunArgs {
  std::string dataset;
  std::string config;
  std::string depth = "sensor";
  std::string detector = "none";
  std::string frames;
  std::string seed;  // empty: the config's filter.seed and initializer.seed
  bool no_overlap = false;
  int prefetch_frames = 2;
  std::string viz;
  std::string camera;
  std::string out;
  std::vector<std::string> set;  // --set section.key=value overrides of the config
};
// --dataset --config --depth --detector --frames --seed --no-overlap --prefetch-frames --viz
// --camera --out.
void AddSequenceRunOptions(CLI::App& app, SequenceRunArgs& args);

// Where the dataset-family configs live: $ADEMONO_CONFIG_DIR, ./configs, or the source tree the
// binary was built from (bin/ is build/<name>/bin). Empty when none is found.
std::filesystem::path FindConfigDir();
struct ConfigChoice {
  std::string name;  // file name in configs/
  std::string why;   // logged with the choice
};
// The default config of a dataset: by the sequence's camera where the family holds several
// sensors (tum: the three Kinects by their intrinsics, anything else rgbd_generic.yaml), else by
// the family (and KITTI's sequence number in the path).
ConfigChoice DefaultConfig(const std::string& kind, const std::string& path, const Camera& camera);
// `config_arg` if given, else the family's file; empty (with a warning) when there is none.
// Depth from a network (`depth_arg` model:...) picks network_indoor.yaml, or
// network_outdoor.yaml for a spec with `domain: outdoor` or a KITTI dataset. Logs the choice.
std::filesystem::path ResolveConfigPath(const std::string& config_arg, const Sequence& sequence,
                                        const std::string& depth_arg = "");
// A network model's spec with an `uncertainty:` error model sets the depth error model of
// settings that treat depth as a prior (a network settings family).
void ApplyDepthSource(const std::string& depth_arg, SystemOptions& options);
// The dataset's rig height (Sequence::CameraHeight: KITTI's 1.65 m) as depth.camera_height,
// unless `config` (the file with its --set overrides) gives that key itself: a user with
// another vehicle sets it, 0 turns the ground scale off. Logs the choice.
void ApplyDatasetCameraHeight(const YAML::Node& config, const Sequence& sequence,
                              SystemOptions& options);
// The YAML of `path` (an empty node for an empty path); InputError naming the file when invalid.
// `overrides` ("section.key=value", value in YAML) replace keys of the file; the strict option
// readers then reject unknown ones as they would in the file.
YAML::Node LoadConfig(const std::filesystem::path& path,
                      const std::vector<std::string>& overrides = {});
// SystemOptions::FromYaml of `config`, the file at `path` with `overrides` applied. An error the
// file alone does not have came from the overrides: the InputError names them ("--set ...: ...")
// rather than the file.
SystemOptions SystemOptionsFromConfig(const YAML::Node& config, const std::filesystem::path& path,
                                      const std::vector<std::string>& overrides);
// The `detector:` node (DetectorOptions::FromYaml); InputError naming the file and the key.
DetectorOptions DetectorOptionsFromConfig(const YAML::Node& config,
                                          const std::filesystem::path& config_path);
// "START:END" (either may be empty; END exclusive) within a sequence of `size` frames.
void ParseFrames(const std::string& text, size_t size, size_t* start, size_t* end);
// A non-negative integer, or "time" for a time-based seed (the paper's choice).
uint64_t ParseSeed(const std::string& text);

}  // namespace ademono::cli
