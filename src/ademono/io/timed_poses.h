#pragma once
// Time lookups shared by the sequence readers: pose interpolation at a query time and TUM-style
// nearest-timestamp association of two sorted time lists.

#include <optional>
#include <utility>
#include <vector>

#include "ademono/io/trajectory.h"

namespace ademono {

struct PoseLookupOptions {
  // Interpolate (linear translation, slerp rotation) between the two poses bracketing the query
  // when they are at most this far apart, so gaps in ground truth are not bridged.
  double max_interpolation_gap = 0.1;
  // Otherwise use the nearest pose if it is within this many seconds.
  double max_nearest_diff = 0.02;
};

// `trajectory` sorted by timestamp. nullopt when no pose is close enough.
std::optional<Rigid3d> LookupPose(const Trajectory& trajectory, double timestamp,
                                  const PoseLookupOptions& options = {});

// Interpolation between two poses, `alpha` in [0, 1] (0 gives `a`).
Rigid3d InterpolatePose(const Rigid3d& a, const Rigid3d& b, double alpha);

// TUM associate.py: every pair (i, j) with |a[i] - b[j]| < max_diff is a candidate; candidates
// are taken greedily by smallest difference, each index used at most once. Returned sorted by i.
// Both inputs must be sorted ascending.
std::vector<std::pair<size_t, size_t>> AssociateTimestamps(const std::vector<double>& a,
                                                           const std::vector<double>& b,
                                                           double max_diff);

}  // namespace ademono
