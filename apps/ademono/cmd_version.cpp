// `ademono info`: what this build has: library versions and the ONNX Runtime execution providers.
#include <iostream>

#include <Eigen/Core>
#include <ceres/version.h>
#include <opencv2/core/version.hpp>

#include "ademono/dnn/ort_session.h"
#include "command.h"

namespace {
const bool kRegistered = ademono::cli::RegisterCommand(
    "info", "Print the build's library versions and ONNX Runtime providers",
    [](CLI::App&) -> ademono::cli::Runner {
      return [] {
        std::cout << "ademono 0.1.0\n"
                  << "OpenCV " << CV_VERSION << "\n"
                  << "Eigen " << EIGEN_WORLD_VERSION << "." << EIGEN_MAJOR_VERSION << "."
                  << EIGEN_MINOR_VERSION << "\n"
                  << "Ceres " << CERES_VERSION_STRING << "\n"
                  << "ONNX Runtime " << ademono::OrtVersion() << ", providers:";
        for (const auto& provider : ademono::AvailableOrtProviders()) std::cout << " " << provider;
        std::cout << "\n";
        return 0;
      };
    });
}  // namespace
