#pragma once
// Robust scale between two sets of depths of the same points: how much one depth source (a
// network's map for one frame) must be multiplied by to agree with another (the depths of the map
// points the frame tracks). Works on log ratios: the median, then an M-estimator (Huber, IRLS)
// around it with the spread taken from the median absolute deviation, so a tenth of wrong matches
// or depth edges does not move it.

#include <vector>

namespace ademono {

struct DepthScaleOptions {
  int min_points = 20;       // fewer valid pairs: no estimate
  double huber_k = 1.345;    // Huber threshold in robust standard deviations
  int iterations = 10;       // IRLS iterations (stops earlier when converged)
  double min_sigma = 0.005;  // floor of the log-ratio spread (identical inputs give MAD 0)
  void Check() const;        // throws std::invalid_argument
};

struct DepthScaleEstimate {
  bool valid = false;
  double scale = 1.0;       // reference ~= scale * source
  double log_sigma = 0.0;   // robust spread of the log ratios (1.4826 * MAD)
  double log_stderr = 0.0;  // standard error of log(scale): the estimate's confidence
  int num_points = 0;       // pairs used (both depths finite and > 0)
};

// `reference[i]` and `source[i]` are two depths of point i; pairs where either is not a finite
// positive number are skipped. Deterministic (no randomness, order-independent up to rounding).
DepthScaleEstimate EstimateDepthScale(const std::vector<double>& reference,
                                      const std::vector<double>& source,
                                      const DepthScaleOptions& options = {});

}  // namespace ademono
