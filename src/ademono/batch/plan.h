#pragma once
// A batch plan (docs/batch.md): datasets x variants x seeds, read strictly from YAML.
//
//   root: ../shared/data            # dataset paths are relative to it (--root overrides)
//   datasets:
//     seq-a: 7scenes:7scenes-seq-a  # NAME: KIND:PATH, or NAME: {dataset:, frames:, camera:}
//   variants:
//     full: {detector: model:../shared/models/yolox_nano.onnx}
//     no_dynamic: {ablation: no_dynamic, detector: model:../shared/models/yolox_nano.onnx}
//   seeds: [1, 2, 3]
//   slurm: {partition: debug, time: "01:00:00", mem: 4G, cpus_per_task: 2}
//   local: {jobs: 0}                # 0: one run per CPU
//
// Every problem is an InputError "PLAN: problem" naming the key: an unknown key, a dataset that
// does not open, a variant whose config, --set override or ablation name is unknown, a model file
// that is missing.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace ademono::batch {

struct PlanDataset {
  std::string name;
  std::string kind;             // tum, kitti, euroc, 7scenes, folder, video
  std::filesystem::path path;   // absolute
  std::string frames;           // "A:B" or empty (all)
  std::filesystem::path camera; // absolute, or empty (the dataset's)
  size_t size = 0;              // frames in the sequence
  std::string Spec() const { return kind + ":" + path.string(); }
};

struct PlanVariant {
  std::string name;
  std::filesystem::path config;   // absolute, or empty: `run` picks the dataset family's
  std::string depth = "sensor";   // sensor | cache:DIR | simulated[:...] | model:FILE[,spec=Y]
  std::string detector = "none";  // none | cache:FILE | model:FILE[,arch=A]
  std::string ablation;           // a name of `ademono ablate --variants`, or empty
  std::vector<std::string> set;   // SECTION.KEY=VALUE, after the ablation's own overrides
};

struct SlurmSettings {
  std::string partition, time, mem, account, qos;
  int cpus_per_task = 0;               // 0: not given (Slurm's default)
  int max_parallel = 0;                // array throttle (%N), 0: none
  std::vector<std::string> sbatch_args;  // passed to sbatch as they are
};

struct Plan {
  std::filesystem::path file;
  std::string name;  // the file's stem unless `name:` says otherwise
  std::filesystem::path root;
  std::vector<PlanDataset> datasets;
  std::vector<PlanVariant> variants;
  // nullopt: the config's filter.seed and initializer.seed (--seed sets both)
  std::vector<std::optional<uint64_t>> seeds;
  SlurmSettings slurm;
  int jobs = 0;  // local engine pool size, 0: the CPU count
};

// Reads and checks a plan. `root_override` (--root) replaces the plan's `root:`. Relative paths
// (root, config, camera, models) are taken from the current directory, as on a command line.
// Every dataset is opened (to check it and count its frames); every variant's config and
// overrides go through the strict option readers.
Plan LoadPlan(const std::filesystem::path& file, const std::string& root_override = "");

}  // namespace ademono::batch
