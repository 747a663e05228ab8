// `ademono info`: what this build has (versions, ONNX Runtime providers are added by depth/detect).
#include <iostream>

#include <opencv2/core/version.hpp>

#include "command.h"

namespace {
const bool kRegistered = ademono::cli::RegisterCommand(
    "info", "Print the build's library versions", [](CLI::App&) -> ademono::cli::Runner {
      return [] {
        std::cout << "ademono 0.1.0\nOpenCV " << CV_VERSION << "\n";
        return 0;
      };
    });
}  // namespace
