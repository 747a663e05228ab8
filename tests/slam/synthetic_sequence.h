#pragma once
// A short synthetic office sequence for SLAM tests that need no ../shared: rendered in memory by
// synth (the scene `ademono synth --scene office` writes), with exact depth, ground-truth poses
// and ground-truth boxes of the walking persons. Frames are rendered once, on first Load.

#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "ademono/detect/detection.h"
#include "ademono/io/sequence.h"
#include "ademono/synth/generator.h"
#include "ademono/synth/scenes.h"

namespace ademono::testing_util {

class SyntheticOffice : public Sequence {
 public:
  // `frames` at `width` x `height` (intrinsics scale with the size), camera motion `xyz`.
  explicit SyntheticOffice(size_t frames = 80, int width = 320, int height = 240, uint64_t seed = 7,
                           int persons = 2) {
    options_.scene.scene = "office";
    options_.scene.frames = frames;
    options_.scene.seed = seed;
    options_.scene.width = width;
    options_.scene.height = height;
    options_.scene.persons = persons;
    options_.Check();
    scene_ = synth::BuildScene(options_.scene);
    frames_.resize(frames);
  }

  std::string Kind() const override { return "synthetic"; }
  std::filesystem::path Path() const override { return "synthetic:office"; }
  size_t Size() const override { return frames_.size(); }
  const Camera& GetCamera() const override { return scene_.camera; }
  bool HasDepth() const override { return true; }
  bool HasGroundTruth() const override { return true; }
  double Timestamp(size_t i) const override { return scene_.TimeOf(i); }

  FrameData Load(size_t i) const override {
    const Rendered& r = Render(i);
    FrameData frame;
    frame.index = i;
    frame.timestamp = Timestamp(i);
    frame.name = synth::FrameStamp(scene_, i);
    frame.image = r.image.clone();
    frame.depth = r.depth.clone();
    frame.world_from_cam_gt = WorldFromCam(i);
    return frame;
  }

  // Ground-truth boxes of the dynamic-class objects visible in frame i (what the detector cache
  // of `ademono synth` holds).
  std::vector<Detection> Detections(size_t i) const { return Render(i).detections; }
  // 255 where a moving object is the visible surface of frame i (synth's masks/), else 0.
  cv::Mat MovingMask(size_t i) const { return Render(i).moving.clone(); }
  Rigid3d WorldFromCam(size_t i) const { return scene_.world_from_cam(Timestamp(i)); }

 private:
  struct Rendered {
    cv::Mat image, depth, moving;
    std::vector<Detection> detections;
  };
  const Rendered& Render(size_t i) const {
    std::lock_guard<std::mutex> lock(mutex_);
    std::optional<Rendered>& slot = frames_.at(i);
    if (!slot) {
      const synth::RenderedFrame f = synth::RenderSceneFrame(scene_, i, options_);
      slot = Rendered{f.image, f.depth, synth::MovingMask(scene_, f.object_id),
                      synth::BoxesFromObjectIds(scene_, f.object_id, options_.min_box_pixels)};
    }
    return *slot;
  }

  synth::GeneratorOptions options_;
  synth::Scene scene_;
  mutable std::mutex mutex_;
  mutable std::vector<std::optional<Rendered>> frames_;
};

}  // namespace ademono::testing_util
