#include "ademono/batch/tasks.h"

#include <charconv>
#include <cstdio>
#include <map>

#include "ademono/core/error.h"
#include "ademono/core/file_util.h"
#include "ademono/dnn/model_arg.h"
#include "ademono/perception/detector_options.h"
#include "ademono/runner/ablation.h"
#include "ademono/runner/config_file.h"

namespace fs = std::filesystem;

namespace ademono::batch {
namespace {

constexpr const char* kSchema = "ademono.batch/1";

// A short stable tag of a network spec, so that two specs of one model get two caches.
std::string Tag(const std::string& text) {
  uint64_t h = 1469598103934665603ull;  // FNV-1a
  for (unsigned char c : text) {
    h ^= c;
    h *= 1099511628211ull;
  }
  char buf[17];
  std::snprintf(buf, sizeof(buf), "%08x", static_cast<unsigned>(h ^ (h >> 32)));
  return buf;
}

std::string Number(float value) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof(buf), value);
  return std::string(buf, r.ptr);
}

std::vector<std::string> SequenceArgs(const PlanDataset& d) {
  std::vector<std::string> args = {"--dataset", d.Spec()};
  if (!d.camera.empty()) args.insert(args.end(), {"--camera", d.camera.string()});
  if (!d.frames.empty()) args.insert(args.end(), {"--frames", d.frames});
  return args;
}

nlohmann::json TaskJson(const Task& t) {
  return {{"kind", t.kind == Task::Kind::kCache ? "cache" : "run"},
          {"id", t.id},
          {"argv", t.argv},
          {"out", t.out.string()},
          {"log", t.log.string()},
          {"needs", t.needs},
          {"dataset", t.dataset},
          {"variant", t.variant},
          {"seed", t.seed},
          {"product", t.product.string()}};
}

Task TaskFromJson(const nlohmann::json& j) {
  Task t;
  t.kind = j.at("kind").get<std::string>() == "cache" ? Task::Kind::kCache : Task::Kind::kRun;
  t.id = j.at("id").get<std::string>();
  t.argv = j.at("argv").get<std::vector<std::string>>();
  t.out = j.at("out").get<std::string>();
  t.log = j.at("log").get<std::string>();
  t.needs = j.at("needs").get<std::vector<std::string>>();
  t.dataset = j.at("dataset").get<std::string>();
  t.variant = j.at("variant").get<std::string>();
  t.seed = j.at("seed").get<std::string>();
  t.product = j.at("product").get<std::string>();
  return t;
}

}  // namespace

const Task* Batch::Find(const std::string& id) const {
  for (const auto* list : {&caches, &runs}) {
    for (const Task& t : *list) {
      if (t.id == id) return &t;
    }
  }
  return nullptr;
}

nlohmann::json Batch::ToJson() const {
  nlohmann::json j;
  j["schema"] = kSchema;
  j["plan"] = plan_name;
  j["plan_file"] = plan_file.string();
  j["dir"] = dir.string();
  j["caches"] = nlohmann::json::array();
  for (const Task& t : caches) j["caches"].push_back(TaskJson(t));
  j["runs"] = nlohmann::json::array();
  for (const Task& t : runs) j["runs"].push_back(TaskJson(t));
  return j;
}

Batch Batch::FromJson(const nlohmann::json& j) {
  if (j.value("schema", "") != kSchema) {
    throw std::invalid_argument(std::string("schema is not ") + kSchema);
  }
  Batch b;
  b.plan_name = j.at("plan").get<std::string>();
  b.plan_file = j.at("plan_file").get<std::string>();
  b.dir = j.at("dir").get<std::string>();
  for (const auto& t : j.at("caches")) b.caches.push_back(TaskFromJson(t));
  for (const auto& t : j.at("runs")) b.runs.push_back(TaskFromJson(t));
  return b;
}

Batch ExpandPlan(const Plan& plan, const fs::path& dir_arg, const fs::path& ademono_binary) {
  Batch batch;
  batch.plan_name = plan.name;
  batch.plan_file = fs::absolute(plan.file).lexically_normal();
  batch.dir = fs::absolute(dir_arg).lexically_normal();
  const fs::path& dir = batch.dir;
  const std::string bin = ademono_binary.string();
  std::map<std::string, size_t> cache_index;  // id -> position in batch.caches

  // The cache task of `network` on `d` (made once), returning its id.
  auto cache = [&](const PlanDataset& d, const std::string& network, const std::string& key,
                   const std::vector<std::string>& infer_args, const std::string& product) {
    const ModelArg model = ParseModelArg(network.substr(6), {"spec", "arch"});
    const std::string name = model.file.stem().string() + "-" + Tag(key);
    const std::string id = "cache__" + d.name + "__" + name;
    if (cache_index.count(id) == 0) {
      Task t;
      t.kind = Task::Kind::kCache;
      t.id = id;
      t.out = dir / "cache" / d.name / name;
      t.log = dir / "logs" / (id + ".log");
      t.dataset = d.name;
      t.product = t.out / product;
      t.argv = {bin, "infer"};
      for (const std::string& a : SequenceArgs(d)) t.argv.push_back(a);
      t.argv.insert(t.argv.end(), infer_args.begin(), infer_args.end());
      t.argv.insert(t.argv.end(), {"--out", t.out.string()});
      cache_index[id] = batch.caches.size();
      batch.caches.push_back(std::move(t));
    }
    return batch.caches[cache_index[id]];
  };

  for (const PlanDataset& d : plan.datasets) {
    for (const PlanVariant& v : plan.variants) {
      std::vector<std::string> overrides;
      bool use_detector = true;
      if (!v.ablation.empty()) {
        const AblationVariant* a = FindAblationVariant(v.ablation);
        overrides = AblationSetOverrides(*a);
        use_detector = a->use_detector;
      }
      overrides.insert(overrides.end(), v.set.begin(), v.set.end());

      std::vector<std::string> needs;
      std::string depth = v.depth;
      if (v.depth.rfind("model:", 0) == 0) {
        const Task& c = cache(d, v.depth, v.depth, {"--depth-model", v.depth}, "depth");
        needs.push_back(c.id);
        // The cache is still this network's depth for `run` (settings family, error model).
        const ModelArg model = ParseModelArg(v.depth.substr(6), {"spec"});
        depth = "cache:" + c.product.string() + ",model=" + model.file.string();
        if (auto it = model.options.find("spec"); it != model.options.end())
          depth += ",spec=" + it->second;
      }
      std::string detector = use_detector ? v.detector : "none";
      if (detector.rfind("model:", 0) == 0) {
        // Every class is cached; the run keeps its config's classes. Score and NMS are the
        // variant config's (`infer`'s defaults are the configs' defaults).
        const DetectorOptions o =
            DetectorOptions::FromYaml(LoadConfigWithOverrides(v.config, overrides)["detector"]);
        const std::string score = Number(o.score_threshold), nms = Number(o.nms_iou);
        const Task& c = cache(d, detector, detector + ";" + score + ";" + nms,
                              {"--detector", detector, "--classes", "all", "--score", score,
                               "--nms", nms},
                              "detections.jsonl");
        needs.push_back(c.id);
        detector = "cache:" + c.product.string();
      }

      for (const auto& seed : plan.seeds) {
        Task t;
        t.kind = Task::Kind::kRun;
        t.dataset = d.name;
        t.variant = v.name;
        t.seed = seed ? std::to_string(*seed) : "config";
        t.id = d.name + "__" + v.name + "__s" + t.seed;
        t.out = dir / "runs" / t.id;
        t.log = dir / "logs" / (t.id + ".log");
        t.needs = needs;
        t.argv = {bin, "run"};
        for (const std::string& a : SequenceArgs(d)) t.argv.push_back(a);
        if (!v.config.empty()) t.argv.insert(t.argv.end(), {"--config", v.config.string()});
        t.argv.insert(t.argv.end(), {"--depth", depth, "--detector", detector});
        if (seed) t.argv.insert(t.argv.end(), {"--seed", std::to_string(*seed)});
        for (const std::string& s : overrides) t.argv.insert(t.argv.end(), {"--set", s});
        // A run killed half-way leaves some files: the next attempt replaces them.
        t.argv.insert(t.argv.end(), {"--overwrite", "--out", t.out.string()});
        batch.runs.push_back(std::move(t));
      }
    }
  }
  return batch;
}

Batch ReadBatch(const fs::path& dir) {
  const fs::path file = dir / "batch.json";
  if (!fs::exists(file)) {
    ThrowInputError(file, "not found (is " + dir.string() + " a folder `ademono batch` wrote?)");
  }
  try {
    return Batch::FromJson(nlohmann::json::parse(ReadTextFile(file)));
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    ThrowInputError(file, std::string("malformed: ") + e.what());
  }
}

void WriteBatch(const Batch& batch) {
  WriteTextFileAtomic(batch.dir / "batch.json", batch.ToJson().dump(1) + "\n");
}

void CheckCompatible(const Batch& before, const Batch& now) {
  for (const auto* list : {&now.caches, &now.runs}) {
    for (const Task& t : *list) {
      const Task* old = before.Find(t.id);
      if (old != nullptr && old->argv != t.argv && IsComplete(*old)) {
        ThrowInputError(now.dir, "'" + t.id + "' was done with another command (" +
                                     ShellCommand(old->argv) +
                                     "); give a new --out or remove " + old->out.string());
      }
    }
  }
}

bool IsComplete(const Task& task) {
  std::error_code ec;
  if (task.kind == Task::Kind::kCache) return fs::exists(task.product, ec);
  const fs::path summary = task.out / "summary.json";
  if (!fs::is_regular_file(summary, ec) || !fs::is_regular_file(task.out / "trajectory.tum", ec))
    return false;
  try {
    const nlohmann::json j = nlohmann::json::parse(ReadTextFile(summary));
    return j.value("schema", "") == "ademono.run/1" && !j.value("partial", false);
  } catch (const std::exception&) {
    return false;
  }
}

std::string ShellQuote(const std::string& word) {
  const bool plain = !word.empty() && word.find_first_not_of(
                                          "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz"
                                          "0123456789_-.,/:=+@%") == std::string::npos;
  if (plain) return word;
  std::string out = "'";
  for (char c : word) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

std::string ShellCommand(const std::vector<std::string>& argv) {
  std::string out;
  for (const std::string& a : argv) {
    if (!out.empty()) out += ' ';
    out += ShellQuote(a);
  }
  return out;
}

fs::path SelfBinary() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (ec) throw std::runtime_error("cannot read /proc/self/exe: " + ec.message());
  return exe;
}

}  // namespace ademono::batch
