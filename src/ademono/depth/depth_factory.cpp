#include "ademono/depth/depth_factory.h"

#include "ademono/core/error.h"
#include "ademono/depth/cache_depth.h"
#include "ademono/depth/onnx_depth.h"
#include "ademono/depth/sensor_depth.h"
#include "ademono/depth/simulated_depth.h"
#include "ademono/dnn/model_arg.h"

namespace ademono {
std::unique_ptr<DepthProvider> MakeDepthProvider(const std::string& spec,
                                                 const DepthFactoryContext& context) {
  const size_t colon = spec.find(':');
  const std::string kind = spec.substr(0, colon);
  const std::string argument = colon == std::string::npos ? "" : spec.substr(colon + 1);

  if (kind == "none") {
    if (!argument.empty()) throw InputError("depth provider 'none' takes no argument");
    return nullptr;
  }
  if (kind == "sensor") {
    if (!argument.empty()) throw InputError("depth provider 'sensor' takes no argument");
    return std::make_unique<SensorDepthProvider>(context.sequence);
  }
  if (kind == "cache") {
    if (argument.empty()) throw InputError("depth provider 'cache' needs a folder: cache:DIR");
    // ",model=" / ",spec=" only describe where the maps came from (DescribeDepthSource).
    return std::make_unique<CacheDepthProvider>(ParseModelArg(argument, {"model", "spec"}).file);
  }
  // --- simulated[:k=v,...] (engineer "synth" adds this branch) ---
  if (kind == "simulated") return MakeSimulatedDepthProvider(argument, context);
  // --- model:FILE.onnx[,spec=Y.yaml] (engineer "onnx" adds this branch) ---
  if (kind == "model") return MakeOnnxDepthProvider(argument, context);

  throw InputError("unknown depth provider '" + spec +
                   "' (expected none, sensor, cache:DIR, simulated[:k=v,...] or model:FILE.onnx)");
}

DepthSourceInfo DescribeDepthSource(const std::string& spec) {
  if (spec == "none") {
    DepthSourceInfo info;
    info.none = true;
    return info;
  }
  const size_t colon = spec.find(':');
  const std::string kind = spec.substr(0, colon);
  const std::string argument = colon == std::string::npos ? "" : spec.substr(colon + 1);
  if (kind == "cache") {
    // A cache of a network's maps (`ademono infer`) is that network's depth: the same settings
    // family and error model as model:FILE, so that replaying it repeats the run.
    const ModelArg cache = ParseModelArg(argument, {"model", "spec"});
    const auto model = cache.options.find("model");
    if (model == cache.options.end()) return {};
    const auto spec_file = cache.options.find("spec");
    return DescribeModelDepth(
        model->second + (spec_file == cache.options.end() ? "" : ",spec=" + spec_file->second));
  }
  if (kind != "model") return {};
  return DescribeModelDepth(argument);
}

}  // namespace ademono
