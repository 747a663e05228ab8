#pragma once
// A thin RAII wrapper over an ONNX Runtime inference session for single-input float models
// (depth networks, YOLO detectors).
//
// Contract:
// - Load errors (missing file, not an ONNX model, unsupported op) throw InputError naming the file.
// - CPU execution provider; the CUDA provider is appended when this ONNX Runtime build has it
//   and `OrtSessionOptions::use_cuda` allows it.
// - Intra-op threads are configurable; inter-op is 1 (sequential graph execution) and
//   deterministic compute is on, so the same input gives bit-identical output.
// - Run() is safe to call from several threads at once (ONNX Runtime sessions are).
// - Shapes use -1 for a dynamic dimension.

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace ademono {

struct OrtSessionOptions {
  // 1 by default: on a 2-core machine the tracker runs on the other core (see docs/models.md
  // for 1 vs 2 measured).
  int intra_op_threads = 1;
  bool use_cuda = true;  // only if the ONNX Runtime library was built with CUDA
  void Check() const;
};

struct TensorInfo {
  std::string name;
  std::vector<int64_t> shape;  // -1 = dynamic
  bool is_float = false;
};

// "1x3x416x416", dynamic dimensions as "?".
std::string ShapeToString(const std::vector<int64_t>& shape);

struct Tensor {
  std::vector<int64_t> shape;
  std::vector<float> data;
};

class OrtSession {
 public:
  OrtSession(const std::filesystem::path& model_path, const OrtSessionOptions& options);
  ~OrtSession();
  OrtSession(const OrtSession&) = delete;
  OrtSession& operator=(const OrtSession&) = delete;

  const std::filesystem::path& Path() const { return path_; }
  const std::vector<TensorInfo>& Inputs() const { return inputs_; }
  const std::vector<TensorInfo>& Outputs() const { return outputs_; }
  // The execution provider the session runs on ("CPUExecutionProvider" or "CUDAExecutionProvider").
  const std::string& Provider() const { return provider_; }

  // Runs the model on one float input (row-major, `shape` fully specified) and returns every
  // output converted to float. Throws InputError naming the model if ONNX Runtime rejects it.
  std::vector<Tensor> Run(const std::vector<float>& input, const std::vector<int64_t>& shape) const;

 private:
  struct Impl;
  std::filesystem::path path_;
  std::vector<TensorInfo> inputs_;
  std::vector<TensorInfo> outputs_;
  std::string provider_;
  std::unique_ptr<Impl> impl_;
};

// Execution providers compiled into the loaded ONNX Runtime library.
std::vector<std::string> AvailableOrtProviders();
std::string OrtVersion();

}  // namespace ademono
