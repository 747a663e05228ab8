#pragma once
// Shared fixtures of the filter tests.

#include "ademono/core/camera.h"

namespace ademono::filter_test {

// An ideal 640x480 pinhole with f = 500 px and the principal point at the centre.
inline Camera TestCamera() {
  Camera c;
  c.width = 640;
  c.height = 480;
  c.fx = c.fy = 500;
  c.cx = 320;
  c.cy = 240;
  return c;
}

}  // namespace ademono::filter_test
