#pragma once
// Internal to io/: a Sequence backed by per-frame image files (TUM, KITTI, EuRoC, 7-Scenes,
// image folders), and the per-dataset openers OpenSequence dispatches to. Everything is listed
// and checked when the sequence is opened, so Load() only decodes files; Load() on a const
// FileSequence touches no shared state and is safe from several threads.

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "ademono/io/sequence.h"

namespace ademono {

struct FileFrame {
  double timestamp = 0.0;
  std::filesystem::path image;
  std::filesystem::path depth;  // empty: no depth for this frame
  std::optional<Rigid3d> world_from_cam_gt;
};

struct FileSequenceSpec {
  std::string kind;
  std::filesystem::path path;
  Camera camera;
  std::vector<FileFrame> frames;
  double depth_scale = 0.001;  // metres per depth-image unit
  bool has_depth = false;      // every frame has a depth file
  bool has_ground_truth = false;
  std::optional<double> camera_height;  // Sequence::CameraHeight
};

class FileSequence : public Sequence {
 public:
  // Throws InputError "<path>: sequence has no frames" when `spec.frames` is empty.
  explicit FileSequence(FileSequenceSpec spec);

  std::string Kind() const override { return spec_.kind; }
  std::filesystem::path Path() const override { return spec_.path; }
  size_t Size() const override { return spec_.frames.size(); }
  const Camera& GetCamera() const override { return spec_.camera; }
  bool HasDepth() const override { return spec_.has_depth; }
  bool HasGroundTruth() const override { return spec_.has_ground_truth; }
  FrameData Load(size_t i) const override { return LoadFrame(i, true); }
  FrameData LoadWithoutDepth(size_t i) const override { return LoadFrame(i, false); }
  cv::Mat LoadDepth(size_t i) const override;
  double Timestamp(size_t i) const override;
  std::optional<double> CameraHeight() const override { return spec_.camera_height; }

 private:
  FrameData LoadFrame(size_t i, bool with_depth) const;
  FileSequenceSpec spec_;
};

// Image -> BGR CV_8UC3 (grey and BGRA converted; 16-bit scaled down). Names `path` on failure.
cv::Mat ToBgr8(const cv::Mat& image, const std::filesystem::path& path);
// uint16 depth image -> CV_32F metres; 0 and 65535 (no reading) become 0.
cv::Mat DepthToMetres(const cv::Mat& raw, double scale, const std::filesystem::path& path);
// Size of the first image, read from the file; InputError if it does not decode.
cv::Size ImageSizeOf(const std::filesystem::path& path);
// Camera from `camera_yaml` if given, else `fallback` (which may be nullopt: then InputError
// "<where>: <why>").
Camera ResolveCamera(const std::optional<std::filesystem::path>& camera_yaml,
                     const std::optional<Camera>& fallback, const std::filesystem::path& where,
                     const std::string& why);
bool IsImageFile(const std::filesystem::path& path);

std::unique_ptr<Sequence> OpenSevenScenes(const std::filesystem::path& dir,
                                          const std::optional<std::filesystem::path>& camera_yaml);
std::unique_ptr<Sequence> OpenTum(const std::filesystem::path& dir,
                                  const std::optional<std::filesystem::path>& camera_yaml);
std::unique_ptr<Sequence> OpenKitti(const std::filesystem::path& dir,
                                    const std::optional<std::filesystem::path>& camera_yaml);
std::unique_ptr<Sequence> OpenEuroc(const std::filesystem::path& dir,
                                    const std::optional<std::filesystem::path>& camera_yaml);
std::unique_ptr<Sequence> OpenImageFolder(const std::filesystem::path& dir,
                                          const std::optional<std::filesystem::path>& camera_yaml);
std::unique_ptr<Sequence> OpenVideo(const std::filesystem::path& file,
                                    const std::optional<std::filesystem::path>& camera_yaml);
// A live camera through cv::VideoCapture: `device` is a number (camera:0) or a device path
// (camera:/dev/video2). The camera YAML is required and must match the frames' size. Size() is
// unbounded, Kind() "camera"; Load(i) returns the camera's next frame (i only labels it) and
// Timestamp(i) is unknown until then (seconds since open). Read by the real-time feed only.
std::unique_ptr<Sequence> OpenCamera(const std::string& device,
                                     const std::optional<std::filesystem::path>& camera_yaml);

}  // namespace ademono
