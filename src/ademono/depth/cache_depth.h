#pragma once
// Precomputed depth maps in a folder (`cache:DIR`): 16-bit PNG in millimetres (0 and 65535 =
// invalid) or 32-bit float TIFF in metres (0, negative or non-finite = invalid). A frame's map is
// found by its file-name stem (`<stem>.png`, `<stem>.tiff`, `<stem>.tif`, also `<stem>.depth.*`),
// else by a timestamp in the file name (a number within 1 ms of the frame's timestamp).
// Maps at another resolution than the image are resized (nearest neighbour).

#include <filesystem>
#include <map>
#include <string>

#include "ademono/perception/depth_provider.h"

namespace ademono {

class CacheDepthProvider : public DepthProvider {
 public:
  // Indexes `dir`; InputError if it is missing or holds no .png/.tif/.tiff file.
  explicit CacheDepthProvider(const std::filesystem::path& dir);
  std::string Name() const override { return "cache:" + dir_.string(); }
  // InputError naming the frame and the folder when no map matches, or naming the file when it
  // does not decode or has an unsupported type.
  cv::Mat Depth(const FrameData& frame, const Camera& camera) override;

  // The file matched to a frame (empty path if none); exposed for tests.
  std::filesystem::path FindFile(const FrameData& frame) const;

 private:
  std::filesystem::path dir_;
  std::map<std::string, std::filesystem::path> by_stem_;
  std::map<double, std::filesystem::path> by_time_;
};

// Reads one depth map file as CV_32FC1 metres (0 = invalid).
cv::Mat ReadDepthMap(const std::filesystem::path& path);

}  // namespace ademono
