#pragma once
// The frames' poses re-estimated under a motion model, after the run (docs/slam.md "Frames
// smoothed"). A frame's pose comes from one image: along the direction where a small sideways
// step and a small turn move the image alike, it scatters by millimetres from frame to frame
// (the synthetic office with exact depth: 2.6 mm sideways, correlated -0.98 with the turn),
// while a hand-held or driven camera accelerates smoothly at 30 frames/s. Each coordinate of
// the camera centre and of the integrated rotation is fitted by a penalised second difference
// (a discrete smoothing spline): minimise |x - y|^2 + lambda |D2 x|^2. Lambda is chosen per run
// and coordinate by generalised cross-validation, from the data alone: where the measured path
// is as smooth as the motion, GCV picks a small lambda and the poses barely move.

#include <cstddef>
#include <vector>

#include "ademono/core/geometry.h"

namespace ademono {

struct SmoothedSeries {
  std::vector<double> values;
  double lambda = 0.0;  // the GCV choice (0 when the series is too short to smooth)
  double gcv = 0.0;     // its score: n |y - x|^2 / (n - trace(H))^2
};

// Candidate lambdas: 10^(k/4) for k = -4 .. 12 (0.1 .. 1000: at 1000 the fit's equivalent
// kernel spans about +-6 samples).
const std::vector<double>& SmoothingLambdas();

// One evenly sampled series; fewer than `kMinSmoothedSamples` samples are returned as they are.
inline constexpr size_t kMinSmoothedSamples = 10;
SmoothedSeries SmoothSeriesGcv(const std::vector<double>& y);
// The same fit at a given lambda, and the trace of its hat matrix (A^-1, A = I + lambda D2'D2).
std::vector<double> SmoothSeries(const std::vector<double>& y, double lambda,
                                 double* hat_trace = nullptr);

struct PoseSmoothingReport {
  size_t segments = 0;        // runs of frames smoothed (split at gaps)
  double max_shift_m = 0.0;   // largest move of a camera centre
  double rms_shift_m = 0.0;
};

// Poses at `timestamps` (seconds, increasing): camera centres and rotations smoothed within
// segments of evenly spaced frames. A segment ends where the time to the next frame is more than
// 1.5x the median step (frames lost or skipped). Deterministic.
std::vector<Rigid3d> SmoothPoses(const std::vector<double>& timestamps,
                                 const std::vector<Rigid3d>& world_from_cam,
                                 PoseSmoothingReport* report = nullptr);

}  // namespace ademono
