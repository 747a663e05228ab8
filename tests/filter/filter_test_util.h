#pragma once
// Shared fixtures of the filter tests.

#include "ademono/core/camera.h"

namespace ademono::filter_test {

// An ideal 640x480 pinhole with f = 500 px and the principal point at the centre.
inline Camera TestCamera() { return Camera::Pinhole(640, 480, 500, 320, 240); }

}  // namespace ademono::filter_test
