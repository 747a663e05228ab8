// A folder of images. Order and timestamps come from the file names when every stem is a number:
// decimal stems ("1305031102.175304") are seconds, 19-digit integers are nanoseconds (EuRoC
// style), other integers are frame numbers at 30 fps. Otherwise: sorted by name, index / 30 fps.
#include <algorithm>
#include <cctype>

#include "ademono/core/error.h"
#include "ademono/core/file_util.h"
#include "ademono/io/file_sequence.h"

namespace fs = std::filesystem;

namespace ademono {

namespace {

constexpr double kFolderFps = 30.0;

bool IsDigits(const std::string& s) {
  return !s.empty() &&
         std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::isdigit(c) != 0; });
}

// Seconds encoded by a numeric file stem, or nullopt if the stem is not a number.
std::optional<double> StemSeconds(const std::string& stem) {
  const size_t dot = stem.find('.');
  if (dot == std::string::npos) {
    if (!IsDigits(stem)) return std::nullopt;
    if (stem.size() >= 19) return std::stod(stem) * 1e-9;
    return std::stod(stem) / kFolderFps;
  }
  if (!IsDigits(stem.substr(0, dot)) || !IsDigits(stem.substr(dot + 1))) return std::nullopt;
  return std::stod(stem);
}

}  // namespace

std::unique_ptr<Sequence> OpenImageFolder(const fs::path& dir,
                                          const std::optional<fs::path>& camera_yaml) {
  RequireDirectory(dir);
  std::vector<fs::path> images;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (entry.is_regular_file() && IsImageFile(entry.path())) images.push_back(entry.path());
  }
  if (images.empty()) ThrowInputError(dir, "sequence has no frames");
  std::sort(images.begin(), images.end());

  std::vector<std::pair<double, fs::path>> timed;
  bool numeric = true;
  for (const auto& image : images) {
    const auto seconds = StemSeconds(image.stem().string());
    if (!seconds) {
      numeric = false;
      break;
    }
    timed.emplace_back(*seconds, image);
  }
  if (numeric) {
    std::stable_sort(timed.begin(), timed.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    for (size_t i = 1; i < timed.size(); ++i) {
      if (timed[i].first == timed[i - 1].first) {
        ThrowInputError(timed[i].second,
                        "has the same timestamp as " + timed[i - 1].second.string());
      }
    }
  } else {
    timed.clear();
    for (size_t i = 0; i < images.size(); ++i) {
      timed.emplace_back(static_cast<double>(i) / kFolderFps, images[i]);
    }
  }

  FileSequenceSpec spec;
  spec.kind = "folder";
  spec.path = dir;
  for (auto& [t, image] : timed) spec.frames.push_back({t, image, {}, std::nullopt});
  std::optional<Camera> in_folder;
  if (fs::exists(dir / "camera.yaml")) in_folder = LoadCameraYaml(dir / "camera.yaml");
  spec.camera = ResolveCamera(camera_yaml, in_folder, dir,
                              "no camera.yaml in the folder; pass a camera YAML");
  return std::make_unique<FileSequence>(std::move(spec));
}

}  // namespace ademono
