#pragma once
// CPU ray caster for box scenes. One ray per pixel through the pixel centre of an ideal pinhole
// camera (core/camera.h conventions: (0, 0) is the centre of the top-left pixel, z forward), so
// depth is exact: the z of the first surface hit. Boxes are culled per row by their projected
// bounds and tested in order of their nearest possible depth. Rows are rendered in parallel;
// every pixel is computed independently, so the result does not depend on the thread count.

#include <opencv2/core.hpp>
#include <vector>

#include "ademono/core/camera.h"
#include "ademono/core/geometry.h"
#include "ademono/synth/scene.h"

namespace ademono::synth {

struct RenderedFrame {
  cv::Mat image;      // CV_8UC3 BGR
  cv::Mat depth;      // CV_32FC1 metres (z in the camera frame), 0 where no surface (sky)
  cv::Mat object_id;  // CV_32SC1 Box::object_id of the visible surface, -1 where none
};

// Renders `boxes` with the scene's textures seen from `world_from_cam`. The camera must have no
// distortion (std::invalid_argument otherwise). Boxes with `sprite >= 0` are photo quads drawn
// from `sprites` (unshaded: the photo carries its own light).
RenderedFrame RenderBoxes(const Camera& camera, const std::vector<Texture>& textures,
                          const std::vector<Box>& boxes, const Rigid3d& world_from_cam,
                          const cv::Vec3f& sky_bgr, const std::vector<Sprite>& sprites = {});

}  // namespace ademono::synth
