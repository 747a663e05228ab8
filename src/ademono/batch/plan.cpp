#include "ademono/batch/plan.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <regex>
#include <set>

#include "ademono/core/error.h"
#include "ademono/dnn/model_arg.h"
#include "ademono/io/sequence.h"
#include "ademono/perception/detector_options.h"
#include "ademono/runner/ablation.h"
#include "ademono/runner/config_file.h"
#include "ademono/slam/options.h"

namespace fs = std::filesystem;

namespace ademono::batch {
namespace {

// Reads one plan file; every message is "FILE: problem".
class Reader {
 public:
  explicit Reader(fs::path file) : file_(std::move(file)) {}

  [[noreturn]] void Fail(const std::string& message) const { ThrowInputError(file_, message); }

  // `node` must be a map whose keys are all in `allowed`.
  void Keys(const YAML::Node& node, const std::string& where,
            const std::vector<std::string>& allowed) const {
    if (!node.IsMap()) Fail("'" + where + "' must be a map");
    for (const auto& item : node) {
      const std::string key = item.first.as<std::string>();
      if (std::find(allowed.begin(), allowed.end(), key) == allowed.end()) {
        Fail("unknown key '" + (where == "(root)" ? key : where + "." + key) + "'");
      }
    }
  }
  std::string Scalar(const YAML::Node& node, const std::string& where) const {
    if (!node.IsScalar()) Fail("'" + where + "' must be a single value");
    return node.as<std::string>();
  }
  int Int(const YAML::Node& node, const std::string& where, int low) const {
    const std::string text = Scalar(node, where);
    try {
      size_t used = 0;
      const int value = std::stoi(text, &used);
      if (used == text.size() && value >= low) return value;
    } catch (const std::exception&) {
    }
    Fail("'" + where + "' must be an integer >= " + std::to_string(low) + ", got '" + text + "'");
  }
  // A name used in folder names and job names.
  std::string Name(const YAML::Node& node, const std::string& where) const {
    const std::string name = Scalar(node, where);
    static const std::regex pattern("^[A-Za-z0-9][A-Za-z0-9_.-]*$");
    if (!std::regex_match(name, pattern) || name.find("__") != std::string::npos) {
      Fail("'" + where + "': name '" + name +
           "' must be letters, digits, '.', '-' or single '_' (it names folders)");
    }
    return name;
  }

 private:
  fs::path file_;
};

fs::path Absolute(const fs::path& path) { return fs::absolute(path).lexically_normal(); }

// A model spec "model:FILE[,key=V]" with FILE and a spec= file made absolute; Fail if FILE is
// missing.
std::string AbsoluteModel(const Reader& r, const std::string& spec, const std::string& where,
                          const std::vector<std::string>& keys) {
  ModelArg model;
  try {
    model = ParseModelArg(spec.substr(6), keys);
  } catch (const InputError& e) {
    r.Fail("'" + where + "': " + e.what());
  }
  const fs::path file = Absolute(model.file);
  if (!fs::is_regular_file(file))
    r.Fail("'" + where + "': model file " + file.string() + " not found");
  std::string out = "model:" + file.string();
  for (const auto& [key, value] : model.options) {
    out += "," + key + "=";
    if (key == "spec") {
      const fs::path spec_file = Absolute(value);
      if (!fs::is_regular_file(spec_file)) {
        r.Fail("'" + where + "': model spec " + spec_file.string() + " not found");
      }
      out += spec_file.string();
    } else {
      out += value;
    }
  }
  return out;
}

PlanDataset ReadDataset(const Reader& r, const std::string& name, const YAML::Node& node,
                        const fs::path& root) {
  const std::string where = "datasets." + name;
  PlanDataset d;
  d.name = name;
  std::string spec;
  if (node.IsScalar()) {
    spec = node.as<std::string>();
  } else {
    r.Keys(node, where, {"dataset", "frames", "camera"});
    if (!node["dataset"]) r.Fail("'" + where + "' needs 'dataset: KIND:PATH'");
    spec = r.Scalar(node["dataset"], where + ".dataset");
    if (node["frames"]) d.frames = r.Scalar(node["frames"], where + ".frames");
    if (node["camera"]) d.camera = Absolute(r.Scalar(node["camera"], where + ".camera"));
  }
  const size_t colon = spec.find(':');
  if (colon == std::string::npos || colon == 0 || colon + 1 == spec.size()) {
    r.Fail("'" + where + "': expected KIND:PATH, got '" + spec + "'");
  }
  d.kind = spec.substr(0, colon);
  if (d.kind == "camera") r.Fail("'" + where + "': a live camera cannot be part of a batch");
  const fs::path path = spec.substr(colon + 1);
  d.path = Absolute(path.is_absolute() || root.empty() ? path : root / path);
  std::optional<fs::path> camera;
  if (!d.camera.empty()) camera = d.camera;
  try {
    d.size = OpenSequence(d.Spec(), camera)->Size();
  } catch (const InputError& e) {
    r.Fail("dataset '" + name + "': " + e.what());
  }
  if (!d.frames.empty()) {
    static const std::regex pattern("^(\\d{0,9}):(\\d{0,9})$");
    std::smatch m;
    size_t start = 0, end = d.size;
    if (!std::regex_match(d.frames, m, pattern)) {
      r.Fail("'" + where + ".frames': expected START:END, got '" + d.frames + "'");
    }
    if (!m[1].str().empty()) start = std::stoul(m[1].str());
    if (!m[2].str().empty()) end = std::stoul(m[2].str());
    if (end <= start || start >= d.size) {
      r.Fail("'" + where + ".frames' " + d.frames + " does not fit the sequence's " +
             std::to_string(d.size) + " frames");
    }
  }
  return d;
}

PlanVariant ReadVariant(const Reader& r, const std::string& name, const YAML::Node& node) {
  const std::string where = "variants." + name;
  PlanVariant v;
  v.name = name;
  if (node.IsNull()) return v;  // `full:` alone: the defaults
  r.Keys(node, where, {"config", "depth", "detector", "ablation", "set"});
  if (node["config"]) {
    v.config = Absolute(r.Scalar(node["config"], where + ".config"));
    if (!fs::is_regular_file(v.config))
      r.Fail("'" + where + ".config': " + v.config.string() + " not found");
  }
  if (node["depth"]) v.depth = r.Scalar(node["depth"], where + ".depth");
  if (node["detector"]) v.detector = r.Scalar(node["detector"], where + ".detector");
  if (node["ablation"]) v.ablation = r.Scalar(node["ablation"], where + ".ablation");
  if (const YAML::Node set = node["set"]) {
    // A list of "section.key=value", or a map {section.key: value}.
    if (set.IsSequence()) {
      for (const auto& item : set) v.set.push_back(r.Scalar(item, where + ".set"));
    } else if (set.IsMap()) {
      for (const auto& item : set) {
        YAML::Emitter value;
        value << YAML::Flow << item.second;
        v.set.push_back(item.first.as<std::string>() + "=" + value.c_str());
      }
    } else {
      r.Fail("'" + where + ".set' must be a list of SECTION.KEY=VALUE or a map");
    }
  }

  // Depth and detector: the kinds `run` knows; model files must exist (paths made absolute).
  const std::string depth_kind = v.depth.substr(0, v.depth.find(':'));
  if (depth_kind == "model") {
    v.depth = AbsoluteModel(r, v.depth, where + ".depth", {"spec"});
  } else if (depth_kind != "sensor" && depth_kind != "cache" && depth_kind != "simulated") {
    r.Fail("'" + where + ".depth': unknown depth '" + v.depth +
           "' (expected sensor, cache:DIR, simulated[:k=v,...] or model:FILE.onnx)");
  }
  const std::string detector_kind = v.detector.substr(0, v.detector.find(':'));
  if (detector_kind == "model") {
    v.detector = AbsoluteModel(r, v.detector, where + ".detector", {"arch"});
  } else if (detector_kind != "none" && detector_kind != "cache") {
    r.Fail("'" + where + ".detector': unknown detector '" + v.detector +
           "' (expected none, cache:FILE.jsonl or model:FILE.onnx)");
  }

  // The options as `run` will read them: config, the ablation's overrides, then the variant's.
  std::vector<std::string> overrides;
  if (!v.ablation.empty()) {
    const AblationVariant* ablation = FindAblationVariant(v.ablation);
    if (ablation == nullptr) {
      std::string names;
      for (const auto& a : AllAblationVariants()) names += (names.empty() ? "" : ", ") + a.name;
      r.Fail("'" + where + ".ablation': unknown variant '" + v.ablation + "' (known: " + names +
             ")");
    }
    overrides = AblationSetOverrides(*ablation);
  }
  overrides.insert(overrides.end(), v.set.begin(), v.set.end());
  try {
    const YAML::Node config = LoadConfigWithOverrides(v.config, overrides);
    SystemOptions::FromYaml(config, v.config.empty() ? fs::path("(built-in defaults)") : v.config);
    DetectorOptions::FromYaml(config["detector"]);
  } catch (const std::exception& e) {
    r.Fail("variant '" + name + "': " + e.what());
  }
  return v;
}

}  // namespace

Plan LoadPlan(const fs::path& file, const std::string& root_override) {
  const Reader r(file);
  RequireFile(file);
  YAML::Node doc;
  try {
    doc = YAML::LoadFile(file.string());
  } catch (const YAML::Exception& e) {
    r.Fail(std::string("invalid YAML: ") + e.msg);
  }
  if (!doc || !doc.IsMap()) r.Fail("a plan must be a YAML map (datasets:, variants:, seeds:)");
  r.Keys(doc, "(root)", {"name", "root", "datasets", "variants", "seeds", "slurm", "local"});

  Plan plan;
  plan.file = file;
  plan.name = doc["name"] ? r.Name(doc["name"], "name") : file.stem().string();
  if (!root_override.empty()) {
    plan.root = Absolute(root_override);
  } else if (doc["root"]) {
    plan.root = Absolute(r.Scalar(doc["root"], "root"));
  }
  if (!plan.root.empty() && !fs::is_directory(plan.root)) {
    r.Fail("root " + plan.root.string() + " is not a directory" +
           (root_override.empty() ? "" : " (--root)"));
  }

  const YAML::Node datasets = doc["datasets"];
  if (!datasets || !datasets.IsMap() || datasets.size() == 0) {
    r.Fail("'datasets' must be a non-empty map NAME: KIND:PATH");
  }
  for (const auto& item : datasets) {
    const std::string name = r.Name(item.first, "datasets");
    plan.datasets.push_back(ReadDataset(r, name, item.second, plan.root));
  }
  const YAML::Node variants = doc["variants"];
  if (!variants || !variants.IsMap() || variants.size() == 0) {
    r.Fail("'variants' must be a non-empty map NAME: {config, depth, detector, ablation, set}");
  }
  for (const auto& item : variants) {
    const std::string name = r.Name(item.first, "variants");
    plan.variants.push_back(ReadVariant(r, name, item.second));
  }

  if (const YAML::Node seeds = doc["seeds"]) {
    if (!seeds.IsSequence() || seeds.size() == 0) r.Fail("'seeds' must be a non-empty list");
    std::set<uint64_t> seen;
    for (const auto& seed : seeds) {
      const uint64_t value = static_cast<uint64_t>(r.Int(seed, "seeds", 0));
      if (!seen.insert(value).second) r.Fail("'seeds': " + std::to_string(value) + " given twice");
      plan.seeds.push_back(value);
    }
  } else {
    plan.seeds.push_back(std::nullopt);
  }

  if (const YAML::Node slurm = doc["slurm"]) {
    r.Keys(slurm, "slurm",
           {"partition", "time", "mem", "cpus_per_task", "account", "qos", "max_parallel",
            "sbatch_args"});
    SlurmSettings& s = plan.slurm;
    if (slurm["partition"]) s.partition = r.Scalar(slurm["partition"], "slurm.partition");
    if (slurm["time"]) s.time = r.Scalar(slurm["time"], "slurm.time");
    if (slurm["mem"]) s.mem = r.Scalar(slurm["mem"], "slurm.mem");
    if (slurm["account"]) s.account = r.Scalar(slurm["account"], "slurm.account");
    if (slurm["qos"]) s.qos = r.Scalar(slurm["qos"], "slurm.qos");
    if (slurm["cpus_per_task"])
      s.cpus_per_task = r.Int(slurm["cpus_per_task"], "slurm.cpus_per_task", 1);
    if (slurm["max_parallel"])
      s.max_parallel = r.Int(slurm["max_parallel"], "slurm.max_parallel", 1);
    if (const YAML::Node args = slurm["sbatch_args"]) {
      if (!args.IsSequence()) r.Fail("'slurm.sbatch_args' must be a list");
      for (const auto& a : args) s.sbatch_args.push_back(r.Scalar(a, "slurm.sbatch_args"));
    }
  }
  if (const YAML::Node local = doc["local"]) {
    r.Keys(local, "local", {"jobs"});
    if (local["jobs"]) plan.jobs = r.Int(local["jobs"], "local.jobs", 0);
  }
  return plan;
}

}  // namespace ademono::batch
