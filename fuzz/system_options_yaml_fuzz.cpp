// Run config YAML: SystemOptions::FromYaml on a parsed document (a YAML syntax error is the
// caller's InputError, see apps/ademono/run_options.cpp LoadConfig).
#include <yaml-cpp/yaml.h>

#include "ademono/slam/options.h"
#include "fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace ademono;
  YAML::Node root;
  try {
    root = YAML::Load(std::string(reinterpret_cast<const char*>(data), size));
  } catch (const YAML::Exception&) {
    return 0;
  }
  fuzz::ExpectOnlyInputError([&] { SystemOptions::FromYaml(root, "config.yaml"); });
  return 0;
}
