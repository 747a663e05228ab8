#pragma once
// Depth-weighted feature enhancement (filter 1): the image is split by a quadtree into equal
// blocks; inside each leaf block a greedy walk picks a fraction of the points, preferring points
// far (in the image) from the last pick and deep within the block's depth range. See
// docs/filters.md for the exact reading of the method.

#include <opencv2/core.hpp>
#include <vector>

namespace ademono {

struct EnhancementParams {
  double keep_ratio = 0.75;  // fraction of each leaf block's points kept (rounded up)
  int levels = 2;            // 0: one block; 1: 4 blocks; 2: 16 blocks; ...
  double p_percent = -1;     // < 0: DefaultPPercent(image size)
  double q_percent = -1;     // < 0: kDefaultQPercent
};

inline constexpr double kDefaultQPercent = 100.0;
// P = 100 / (w^2 + h^2): P% turns the squared pixel distance into a fraction of the squared
// image diagonal, so W lies in [0, e] * Q%.
double DefaultPPercent(cv::Size image_size);

// W = ||x1 - x2||^2 * P% * exp((D - Min) / (Max - Min)) * Q%, with D the candidate's depth and
// [Min, Max] the block's known-depth range. An unknown depth (<= 0 or not finite) or an empty range
// (Max == Min) contributes exp(0) = 1: the candidate is ranked by image distance alone.
double EnhancementWeight(const cv::Point2f& current, const cv::Point2f& candidate,
                         float candidate_depth, float min_depth, float max_depth, double p_percent,
                         double q_percent);

// Greedy selection inside one block. `members` index `points`/`depths`. Starts at the member of
// smallest known depth (the first member when none is known), then repeatedly moves to the
// unchosen member of largest weight from the current point (lowest index on ties) until
// ceil(keep_ratio * n) members are chosen. Returns the chosen indices in selection order.
std::vector<int> SelectInBlock(const std::vector<int>& members,
                               const std::vector<cv::Point2f>& points,
                               const std::vector<float>& depths, double keep_ratio,
                               double p_percent, double q_percent);

// Leaf block of each point: blocks are numbered in quadtree order, children of a block in the
// order top-left, top-right, bottom-right, bottom-left. Points outside the image are clamped to the
// nearest block.
std::vector<int> QuadtreeLeafBlocks(const std::vector<cv::Point2f>& points, cv::Size image_size,
                                    int levels);

// Filter 1 over a frame: true for points kept. Only points with `active[i]` take part (pass an
// empty vector for all); inactive points are reported false. `depths` may be empty (all unknown).
std::vector<bool> SelectEnhancedFeatures(const std::vector<cv::Point2f>& points,
                                         const std::vector<float>& depths,
                                         const std::vector<bool>& active, cv::Size image_size,
                                         const EnhancementParams& params);

}  // namespace ademono
