#include "ademono/dnn/ort_session.h"

#include <onnxruntime_cxx_api.h>

#include <algorithm>
#include <stdexcept>

#include "ademono/core/error.h"

namespace ademono {
namespace {

// One environment per process: ONNX Runtime allows only one and it owns the logging.
Ort::Env& Environment() {
  static Ort::Env env(ORT_LOGGING_LEVEL_ERROR, "ademono");
  return env;
}

// ONNX Runtime messages can span lines; the CLI prints errors as one line.
std::string OneLine(std::string text) {
  std::replace(text.begin(), text.end(), '\n', ' ');
  while (!text.empty() && text.back() == ' ') text.pop_back();
  return text;
}

TensorInfo DescribeTensor(const std::string& name, const Ort::TypeInfo& type_info) {
  TensorInfo info;
  info.name = name;
  if (type_info.GetONNXType() != ONNX_TYPE_TENSOR) return info;
  auto tensor_info = type_info.GetTensorTypeAndShapeInfo();
  info.shape = tensor_info.GetShape();
  info.is_float = tensor_info.GetElementType() == ONNX_TENSOR_ELEMENT_DATA_TYPE_FLOAT;
  return info;
}

}  // namespace

void OrtSessionOptions::Check() const {
  if (intra_op_threads < 1 || intra_op_threads > 64) {
    throw std::invalid_argument("intra_op_threads must be in [1, 64], got " +
                                std::to_string(intra_op_threads));
  }
}

std::string ShapeToString(const std::vector<int64_t>& shape) {
  std::string text;
  for (size_t i = 0; i < shape.size(); ++i) {
    if (i > 0) text += "x";
    text += shape[i] < 0 ? "?" : std::to_string(shape[i]);
  }
  return text.empty() ? "scalar" : text;
}

std::vector<std::string> AvailableOrtProviders() { return Ort::GetAvailableProviders(); }

std::string OrtVersion() { return Ort::GetVersionString(); }

struct OrtSession::Impl {
  std::unique_ptr<Ort::Session> session;
  std::vector<std::string> input_names;
  std::vector<std::string> output_names;
};

OrtSession::OrtSession(const std::filesystem::path& model_path, const OrtSessionOptions& options)
    : path_(model_path), impl_(std::make_unique<Impl>()) {
  options.Check();
  RequireFile(model_path);
  Ort::SessionOptions session_options;
  session_options.SetIntraOpNumThreads(options.intra_op_threads);
  session_options.SetInterOpNumThreads(1);
  session_options.SetExecutionMode(ORT_SEQUENTIAL);
  session_options.SetGraphOptimizationLevel(GraphOptimizationLevel::ORT_ENABLE_ALL);
  session_options.SetDeterministicCompute(true);
  provider_ = "CPUExecutionProvider";
  const auto providers = AvailableOrtProviders();
  if (options.use_cuda &&
      std::find(providers.begin(), providers.end(), "CUDAExecutionProvider") != providers.end()) {
    try {
      OrtCUDAProviderOptions cuda_options{};
      session_options.AppendExecutionProvider_CUDA(cuda_options);
      provider_ = "CUDAExecutionProvider";
    } catch (const Ort::Exception&) {
      // Listed but unusable (no driver / device): stay on the CPU.
    }
  }
  try {
    impl_->session =
        std::make_unique<Ort::Session>(Environment(), model_path.c_str(), session_options);
  } catch (const Ort::Exception& e) {
    ThrowInputError(model_path, "cannot load ONNX model: " + OneLine(e.what()));
  }
  Ort::AllocatorWithDefaultOptions allocator;
  for (size_t i = 0; i < impl_->session->GetInputCount(); ++i) {
    std::string name = impl_->session->GetInputNameAllocated(i, allocator).get();
    inputs_.push_back(DescribeTensor(name, impl_->session->GetInputTypeInfo(i)));
    impl_->input_names.push_back(name);
  }
  for (size_t i = 0; i < impl_->session->GetOutputCount(); ++i) {
    std::string name = impl_->session->GetOutputNameAllocated(i, allocator).get();
    outputs_.push_back(DescribeTensor(name, impl_->session->GetOutputTypeInfo(i)));
    impl_->output_names.push_back(name);
  }
  if (inputs_.size() != 1) {
    ThrowInputError(model_path,
                    "expected a model with one input, it has " + std::to_string(inputs_.size()));
  }
  if (!inputs_[0].is_float) {
    ThrowInputError(model_path, "input '" + inputs_[0].name + "' is not a float tensor");
  }
  if (outputs_.empty()) ThrowInputError(model_path, "model has no outputs");
  for (const auto& output : outputs_) {
    if (!output.is_float) {
      ThrowInputError(model_path, "output '" + output.name + "' is not a float tensor");
    }
  }
}

OrtSession::~OrtSession() = default;

std::vector<Tensor> OrtSession::Run(const std::vector<float>& input,
                                    const std::vector<int64_t>& shape) const {
  int64_t count = 1;
  for (int64_t dim : shape) count *= dim;
  if (count != static_cast<int64_t>(input.size())) {
    throw std::invalid_argument("OrtSession::Run: input size does not match shape " +
                                ShapeToString(shape));
  }
  auto memory = Ort::MemoryInfo::CreateCpu(OrtArenaAllocator, OrtMemTypeDefault);
  // ONNX Runtime does not write into inputs; the API just lacks a const overload.
  Ort::Value input_tensor = Ort::Value::CreateTensor<float>(
      memory, const_cast<float*>(input.data()), input.size(), shape.data(), shape.size());
  std::vector<const char*> input_names{impl_->input_names[0].c_str()};
  std::vector<const char*> output_names;
  for (const auto& name : impl_->output_names) output_names.push_back(name.c_str());
  std::vector<Ort::Value> values;
  try {
    values = impl_->session->Run(Ort::RunOptions{nullptr}, input_names.data(), &input_tensor, 1,
                                 output_names.data(), output_names.size());
  } catch (const Ort::Exception& e) {
    ThrowInputError(
        path_, "inference failed for input " + ShapeToString(shape) + ": " + OneLine(e.what()));
  }
  std::vector<Tensor> outputs;
  for (auto& value : values) {
    auto info = value.GetTensorTypeAndShapeInfo();
    Tensor tensor;
    tensor.shape = info.GetShape();
    const float* data = value.GetTensorData<float>();
    tensor.data.assign(data, data + info.GetElementCount());
    outputs.push_back(std::move(tensor));
  }
  return outputs;
}

}  // namespace ademono
