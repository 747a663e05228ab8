#pragma once
// Writes a synthetic sequence in TUM RGB-D layout (what OpenSequence("tum:DIR") reads) plus
// ground truth for the dynamic-object filter:
//   rgb/<t>.png, rgb.txt            colour images (8-bit BGR PNG); t = timestamp "%.6f" seconds
//   depth/<t>.png, depth.txt        16-bit depth, metres * 5000, 0 = no surface or beyond 13.107 m
//   depth_full/<t>.tiff             32-bit float depth in metres without the PNG range limit
//                                   (street only, where most of the scene is beyond 13 m);
//                                   usable as `--depth cache:DIR/depth_full`
//   masks/<t>.png                   8-bit, 255 where a MOVING object is the visible surface
//   groundtruth.txt                 TUM trajectory (world_from_cam) at the image timestamps
//   camera.yaml                     pinhole camera, no distortion
//   detections.jsonl                per frame, a box (score 1) per visible object of a dynamic
//                                   COCO class (moving or not): tight bounds of its visible
//                                   pixels; objects with fewer than `min_box_pixels` visible
//                                   pixels get no box
//   scene.json                      options, camera, objects (id, name, class, moving)
//   objects.jsonl                   with actor photos only: per frame, the visible pixels' box
//                                   and pixel count of every object (any class), by id
// Everything is written into a temporary folder beside DIR and renamed onto DIR at the end, so a
// failed run leaves nothing. Same options give byte-identical files (no global random state;
// independent of the thread count).

#include <cstdint>
#include <filesystem>
#include <functional>
#include <opencv2/core.hpp>
#include <vector>

#include "ademono/perception/detection_io.h"
#include "ademono/synth/renderer.h"
#include "ademono/synth/scenes.h"

namespace ademono::synth {

constexpr double kDepthPngScale = 5000.0;  // TUM: 5000 units per metre

struct GeneratorOptions {
  SceneOptions scene;
  double noise_sigma = 0.0;  // Gaussian image noise, grey levels
  double blur_px = 0.0;      // motion blur length in pixels along the image motion
  int min_box_pixels = 16;
  // Throws std::invalid_argument naming the first bad field (scene options included).
  void Check() const;
};

struct GeneratorSummary {
  size_t frames = 0;
  double seconds_rendering = 0.0;  // rendering + post-processing, without file writing
  double seconds_total = 0.0;
  size_t detections = 0;
  double moving_pixel_fraction = 0.0;  // mean over frames
};

// Renders frame `index` of `scene` with the generator's post-processing (blur, noise).
RenderedFrame RenderSceneFrame(const Scene& scene, size_t index, const GeneratorOptions& options);

// Ground-truth boxes of the dynamic-class objects visible in `object_id` (CV_32SC1).
std::vector<Detection> BoxesFromObjectIds(const Scene& scene, const cv::Mat& object_id,
                                          int min_box_pixels);
// Per object (index id - 1): the tight pixel extent of its visible pixels and their count.
struct ObjectExtent {
  int umin = INT32_MAX, vmin = INT32_MAX, umax = -1, vmax = -1;
  int pixels = 0;
};
std::vector<ObjectExtent> ObjectExtents(const Scene& scene, const cv::Mat& object_id);
// One objects.jsonl line (written with actor photos): every object with >= 1 visible pixel,
// {"frame", "name", "objects": [{"id", "box_xywh", "pixels"}]}, in id order.
std::string ObjectsJsonLine(const Scene& scene, size_t index, const cv::Mat& object_id);
// 255 where a moving object is visible.
cv::Mat MovingMask(const Scene& scene, const cv::Mat& object_id);
// Depth in metres to TUM 16-bit PNG units (0 beyond the range).
cv::Mat DepthToPng(const cv::Mat& depth_m);

// The "%.6f" timestamp of frame `index` (the image is rendered at exactly this time).
std::string FrameStamp(const Scene& scene, size_t index);

// Writes the sequence into `out_dir`, which must not exist or be an empty folder (InputError
// otherwise). `progress(done, total)` is called after each frame when given.
GeneratorSummary GenerateSequence(const GeneratorOptions& options,
                                  const std::filesystem::path& out_dir,
                                  const std::function<void(size_t, size_t)>& progress = {});

}  // namespace ademono::synth
