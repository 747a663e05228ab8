#pragma once
// Shared by the libFuzzer targets. Most parsers take a path, so each input is written to files in
// one scratch directory per fuzzer process (removed at exit). The contract under test: bad input
// raises InputError and nothing else; any other exception, a crash, UB or a leak is a bug.

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "ademono/core/error.h"

namespace ademono::fuzz {

// Results are stored here so the optimiser cannot drop the calls that compute them.
inline volatile double g_sink = 0;

class ScratchDir {
 public:
  ScratchDir() {
    std::string pattern = (std::filesystem::temp_directory_path() / "ademono_fuzz_XXXXXX").string();
    if (::mkdtemp(pattern.data()) == nullptr) std::abort();
    dir_ = pattern;
  }
  ~ScratchDir() {
    std::error_code ignored;
    std::filesystem::remove_all(dir_, ignored);
  }
  const std::filesystem::path& path() const { return dir_; }

 private:
  std::filesystem::path dir_;
};

// The process-wide scratch directory.
inline const std::filesystem::path& Scratch() {
  static ScratchDir dir;
  return dir.path();
}

inline void WriteFile(const std::filesystem::path& path, std::string_view bytes) {
  std::filesystem::create_directories(path.parent_path());
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out) std::abort();
}

// The input split at NUL bytes into exactly `parts` pieces (missing ones empty), so one input
// can drive several files of a dataset folder.
inline std::vector<std::string_view> SplitParts(const uint8_t* data, size_t size, size_t parts) {
  std::vector<std::string_view> out;
  std::string_view rest(reinterpret_cast<const char*>(data), size);
  while (out.size() + 1 < parts) {
    const size_t nul = rest.find('\0');
    if (nul == std::string_view::npos) break;
    out.push_back(rest.substr(0, nul));
    rest.remove_prefix(nul + 1);
  }
  out.push_back(rest);
  out.resize(parts);
  return out;
}

// Runs `parse`; InputError is the expected answer to bad input, anything else escaping is a bug.
template <typename F>
void ExpectOnlyInputError(F&& parse) {
  try {
    parse();
  } catch (const InputError&) {
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fuzz: unexpected exception (not InputError): %s\n", e.what());
    std::abort();
  } catch (...) {
    std::fprintf(stderr, "fuzz: unexpected non-std exception\n");
    std::abort();
  }
}

}  // namespace ademono::fuzz

namespace ademono::fuzz {

// A fresh, empty dataset folder `name` under the scratch directory.
inline std::filesystem::path FreshDir(const std::string& name) {
  const auto dir = Scratch() / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

// Writes `bytes` to `path` unless empty, so that an empty part means "file absent".
inline void WriteIfAny(const std::filesystem::path& path, std::string_view bytes) {
  if (!bytes.empty()) WriteFile(path, bytes);
}

}  // namespace ademono::fuzz

namespace ademono::fuzz {

// Places a small textured 64x48 8-bit PNG at `path` (the sequence openers read the first image's
// size); encoded once per process. Written through WriteFile, whose stream retries writes cut by
// libFuzzer's timer signal (std::filesystem::copy_file threw EINTR there).
inline void WriteSmallImage(const std::filesystem::path& path, int channels) {
  static const auto encode = [](int c) {
    cv::Mat image(48, 64, c == 1 ? CV_8UC1 : CV_8UC3);
    cv::randu(image, 0, 255);
    std::vector<uchar> png;
    if (!cv::imencode(".png", image, png)) std::abort();
    return std::string(png.begin(), png.end());
  };
  static const std::string grey = encode(1), colour = encode(3);
  WriteFile(path, channels == 1 ? grey : colour);
}

// Calls Timestamp() on every frame and reads the camera: what a run does before decoding.
template <typename SequencePtr>
void TouchSequence(const SequencePtr& sequence) {
  double sum = 0.0;
  for (size_t i = 0; i < sequence->Size(); ++i) sum += sequence->Timestamp(i);
  sum += sequence->GetCamera().fx;
  g_sink = sum;
}

}  // namespace ademono::fuzz
