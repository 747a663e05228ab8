#pragma once
// Builds a DepthProvider from its command-line spec:
//   sensor                         the dataset's own depth (TUM, 7-Scenes, synthetic)
//   cache:DIR[,model=F.onnx[,spec=Y.yaml]]
//                                  precomputed maps: 16-bit PNG (mm) or 32-bit float TIFF (m),
//                                  matched to frames by file-name stem or timestamp; model/spec
//                                  say which network made them (`ademono infer`), so the run
//                                  treats them as that network's depth (DescribeDepthSource)
//   simulated[:k=v,...]            network-like errors applied to the dataset's depth (synth)
//   model:FILE.onnx[,spec=Y.yaml]  a metric-depth ONNX model through ONNX Runtime
//   none                           no depth at all: the monocular core (returns null)
// Throws InputError for an unknown kind or a bad argument (naming the file for cache/model).

#include <cstdint>
#include <memory>
#include <string>

#include "ademono/core/depth_error.h"
#include "ademono/io/sequence.h"
#include "ademono/perception/depth_provider.h"

namespace ademono {

struct DepthFactoryContext {
  const Sequence* sequence = nullptr;  // for sensor/simulated checks; may be null
  uint64_t seed = 0;                   // for providers with randomness (simulated)
  int num_threads = 1;                 // inference threads (model)
};

std::unique_ptr<DepthProvider> MakeDepthProvider(const std::string& spec,
                                                 const DepthFactoryContext& context);

// What a depth spec is, before any provider is built: `run` picks its settings family from it
// (network depth gets configs/network_<domain>.yaml) and takes a model's error model.
struct DepthSourceInfo {
  bool none = false;           // `none`: monocular without depth (no metric scale)
  bool network = false;        // a learned network (model:...), a prior rather than a sensor
  std::string domain;          // the model spec's "indoor" / "outdoor", "" if it says nothing
  DepthErrorModel error_model;  // the model spec's uncertainty (disabled if none)
};
DepthSourceInfo DescribeDepthSource(const std::string& spec);

}  // namespace ademono
