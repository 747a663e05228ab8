#pragma once
// What a depth network gets wrong in one view, measured against geometry: an affine map in
// inverse depth,
//     1 / z_map = a / z_net + b,
// fitted to the view's well-triangulated map points. A network's errors are not independent per
// pixel: its scale wanders from frame to frame with the content, and its depth range is often
// compressed or stretched (a shift in inverse depth). Both are one pair of numbers per view; what
// is left after them is the network's per-point error, whose spread (in log depth) this fit also
// measures. The map's units are whatever the map has: `a` carries the map's scale against the
// network's, b / a does not depend on it.
//
// The fit is iteratively reweighted least squares of the relative residual
//     r_i = 1 - z_map_i * (a / z_net_i + b)
// (linear in a and b), Huber weights for three rounds and then Tukey's biweight, started from the
// median ratio (b = 0). When the view's
// depths span too small a range the shift is not observable and only the scale is fitted.

#include <vector>

namespace ademono {

struct InverseDepthAffine {
  bool valid = false;
  double a = 1.0;  // 1 / z_map = a / z_net + b
  double b = 0.0;
  bool scale_only = false;  // the depths' range did not constrain b (held at 0)
  int num_points = 0;       // pairs used
  int num_inliers = 0;      // within 3 robust sigmas of the fit at the end
  // Robust spread (1.4826 MAD) of log(z_map / Map(z_net)) over the inliers: the network's
  // per-point error left after the affine map.
  double sigma_log = 0.0;
  // What of that spread the view's points share: the rms over depth bins (equal counts, by the
  // network's depth) of each bin's median log residual, less what the medians' own sampling
  // noise explains. The affine map leaves it where the network's error depends on depth in a way
  // the map cannot follow (a road read ever shorter with distance); it is 0 for independent
  // per-point noise. n priors in one view then hold the shared part as one observation, not n.
  double shared_sigma_log = 0.0;
  // Robust scale of the network against the map: the median of z_net / z_map.
  double median_ratio = 1.0;

  // The same model after the map's lengths were multiplied by `factor`.
  void Rescale(double factor) {
    a /= factor;
    b /= factor;
    median_ratio /= factor;
  }
  // The network's depth `z_net` in map units (0 if the map sends it behind the camera).
  double Map(double z_net) const {
    const double inv = a / z_net + b;
    return inv > 0 ? 1.0 / inv : 0.0;
  }
};

struct InverseDepthAffineOptions {
  int min_points = 20;
  int iterations = 15;
  double huber_sigmas = 1.345;  // Huber threshold in robust sigmas of the residual (first rounds)
  // b is fitted only when the inverse depths span at least this ratio (max / min over the 10th
  // to 90th percentile); else scale only.
  double min_inverse_depth_span = 1.5;
  int depth_bins = 3;            // for shared_sigma_log
  int min_points_per_bin = 10;   // fewer: shared_sigma_log stays 0
};

// `map_depths[i]` and `network_depths[i]` are one point's depth in the view as the map has it and
// as the network reads it (both > 0; other pairs are skipped).
InverseDepthAffine FitInverseDepthAffine(const std::vector<double>& map_depths,
                                         const std::vector<double>& network_depths,
                                         const InverseDepthAffineOptions& options = {});

}  // namespace ademono
