// Inputs found by fuzzing (fuzz/, docs/reliability.md) that escaped the InputError contract,
// kept so they stay fixed.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "ademono/core/error.h"
#include "ademono/io/sequence.h"
#include "io_test_util.h"

namespace ademono {
namespace {

namespace fs = std::filesystem;

// OpenSequence on an EuRoC folder with this sensor.yaml; the InputError message (any other
// exception propagates and fails the test).
std::string EurocSensorError(const std::string& sensor_yaml) {
  const fs::path dir = testing::MakeTempDir() / "MH";
  testing::WriteText(dir / "mav0" / "cam0" / "data.csv",
                     "#timestamp [ns],filename\n1403636579763555584,a.png\n");
  testing::WriteText(dir / "mav0" / "cam0" / "sensor.yaml", sensor_yaml);
  try {
    OpenSequence("euroc:" + dir.string());
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected InputError for:\n" << sensor_yaml;
  return "";
}

const std::string kGood =
    "resolution: [32, 24]\nintrinsics: [458.654, 457.296, 16.0, 12.0]\n";

TEST(EurocSensorYamlFuzzRegression, WrongKindsOfNodesAreInputErrors) {
  // fuzz_sequence_euroc: a document that is one scalar; yaml-cpp threw "operator[] call on a
  // scalar" out of OpenSequence (exit 1 instead of 2).
  EXPECT_THAT(EurocSensorError("%YAML:1.0\ns7, 0.00019359\n"),
              ::testing::HasSubstr("sensor.yaml: sensor.yaml must be a mapping"));
  EXPECT_THAT(EurocSensorError(kGood + "T_BS: 5\n"), ::testing::HasSubstr("sensor.yaml: "));
  EXPECT_THAT(EurocSensorError(kGood + "distortion_model: [a, b]\n"
                                       "distortion_coefficients: [0, 0, 0, 0]\n"),
              ::testing::HasSubstr("malformed sensor.yaml"));
}

TEST(EurocSensorYamlFuzzRegression, OutOfRangeResolutionAndSingularTbs) {
  EXPECT_THAT(EurocSensorError("resolution: [1e300, 24]\nintrinsics: [1, 1, 0, 0]\n"),
              ::testing::HasSubstr("field 'resolution' must hold two sizes"));
  EXPECT_THAT(EurocSensorError(kGood + "T_BS:\n  data: [0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, "
                                       "0, 1]\n"),
              ::testing::HasSubstr("rotation part is singular"));
}

}  // namespace
}  // namespace ademono
