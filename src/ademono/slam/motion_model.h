#pragma once
// The constant-velocity motion model's velocity, averaged over several frames.

#include "ademono/core/geometry.h"

namespace ademono {

// The per-frame motion (cam_{k+1} from cam_k) that, applied `frames` times, takes
// cam_old_from_world to cam_new_from_world: one `frames`-th of the span's rotation angle about
// its axis, and of its translation. Exact for a pure rotation or a pure translation, and to
// first order in the rotation otherwise (the motions of a few frames are small). frames > 0.
Rigid3d MeanFrameMotion(const Rigid3d& cam_old_from_world, const Rigid3d& cam_new_from_world,
                        double frames);

}  // namespace ademono
