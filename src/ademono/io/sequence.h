#pragma once
// A dataset sequence: frames in time order, each with an image and, when the dataset has them,
// metric depth and a ground-truth pose. Readers for TUM RGB-D, KITTI odometry, EuRoC, 7-Scenes,
// image folders and videos implement it; OpenSequence("kind:path") picks one.

#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include <opencv2/core.hpp>

#include "ademono/core/camera.h"
#include "ademono/core/geometry.h"

namespace ademono {

struct FrameData {
  size_t index = 0;          // position in the sequence, 0-based
  double timestamp = 0.0;    // seconds
  std::string name;          // file stem of the image (or "frame-N" for videos), for caches
  cv::Mat image;             // CV_8UC3 BGR (CV_8UC1 is accepted by consumers and converted)
  cv::Mat depth;             // CV_32FC1 metres, 0 = invalid; empty when the dataset has none
  std::optional<Rigid3d> world_from_cam_gt;
};

class Sequence {
 public:
  virtual ~Sequence() = default;
  virtual std::string Kind() const = 0;   // "tum", "kitti", ...
  virtual std::filesystem::path Path() const = 0;
  virtual size_t Size() const = 0;
  virtual const Camera& GetCamera() const = 0;
  virtual bool HasDepth() const = 0;
  virtual bool HasGroundTruth() const = 0;
  // Loads frame i (0 <= i < Size()). Throws InputError naming the file if it fails to decode.
  virtual FrameData Load(size_t i) const = 0;
  // Frame i without the dataset's depth image (FrameData::depth stays empty), for runs whose
  // depth comes from elsewhere (a network, --depth none): 7-Scenes' 16-bit PNG costs about as
  // much to decode as its colour JPEG. Sequences without depth files load as Load does.
  virtual FrameData LoadWithoutDepth(size_t i) const { return Load(i); }
  // Only frame i's depth image (empty when the dataset has none), for evaluations that read the
  // sensor after the run (eval/map_scale.h). Same errors as Load.
  virtual cv::Mat LoadDepth(size_t i) const { return Load(i).depth; }
  // Timestamp of frame i without decoding images.
  virtual double Timestamp(size_t i) const = 0;
  // The camera's height above the road in metres when the dataset knows its rig (KITTI: 1.65 m),
  // for the ground-plane scale (depth.camera_height, which overrides it).
  virtual std::optional<double> CameraHeight() const { return std::nullopt; }
};

// "tum:DIR", "kitti:DIR", "euroc:DIR", "7scenes:DIR", "folder:DIR", "video:FILE", "camera:N" or
// "camera:/dev/videoN" (a live camera, file_sequence.h OpenCamera).
// `camera_yaml` overrides/supplies the camera (required for folder: and video: unless DIR holds
// camera.yaml). Throws InputError for an unknown kind, a missing path or an empty sequence.
std::unique_ptr<Sequence> OpenSequence(
    const std::string& spec, const std::optional<std::filesystem::path>& camera_yaml = {});

}  // namespace ademono
