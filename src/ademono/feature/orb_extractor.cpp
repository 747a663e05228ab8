#include "ademono/feature/orb_extractor.h"

#include <algorithm>
#include <cmath>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>

#include "ademono/core/options_table.h"
#include "ademono/feature/grid_fast.h"

namespace ademono {
namespace {

constexpr int kPatchSize = 31;
constexpr int kHalfPatchSize = 15;
// Pixels kept clear of the level border: FAST needs 3, the rotated BRIEF pattern ~19.
constexpr int kEdgeThreshold = 19;
constexpr int kCellSize = 30;

// Horizontal half-extent of the circular orientation patch for each row offset 0..15 (the
// circle is made exactly symmetric, as ORB does, so the centroid is unbiased).
std::vector<int> CircleRowExtents() {
  std::vector<int> umax(kHalfPatchSize + 1);
  const int vmax = static_cast<int>(std::floor(kHalfPatchSize * std::sqrt(2.0) / 2 + 1));
  const int vmin = static_cast<int>(std::ceil(kHalfPatchSize * std::sqrt(2.0) / 2));
  const double r2 = kHalfPatchSize * kHalfPatchSize;
  for (int v = 0; v <= vmax; ++v) umax[v] = static_cast<int>(std::lround(std::sqrt(r2 - v * v)));
  for (int v = kHalfPatchSize, v0 = 0; v >= vmin; --v) {
    while (umax[v0] == umax[v0 + 1]) ++v0;
    umax[v] = v0;
    ++v0;
  }
  return umax;
}

// Intensity-centroid orientation in degrees [0, 360) over the circular patch around `pt`.
float IntensityCentroidAngle(const cv::Mat& image, cv::Point2f pt, const std::vector<int>& umax) {
  const int cx = cvRound(pt.x), cy = cvRound(pt.y);
  const uchar* center = image.ptr<uchar>(cy) + cx;
  const int step = static_cast<int>(image.step1());
  int m01 = 0, m10 = 0;
  for (int u = -kHalfPatchSize; u <= kHalfPatchSize; ++u) m10 += u * center[u];
  for (int v = 1; v <= kHalfPatchSize; ++v) {
    int v_sum = 0;
    const int d = umax[v];
    for (int u = -d; u <= d; ++u) {
      const int below = center[u + v * step], above = center[u - v * step];
      v_sum += below - above;
      m10 += u * (below + above);
    }
    m01 += v * v_sum;
  }
  return cv::fastAtan2(static_cast<float>(m01), static_cast<float>(m10));
}

// A quadtree node: an axis-aligned region and the keypoints falling in it.
struct QuadNode {
  float x0, y0, x1, y1;
  std::vector<int> members;  // indices into the level's candidate keypoints
};

// Splits `node` into up to 4 non-empty children (top-left, top-right, bottom-left, bottom-right).
void SplitNode(const QuadNode& node, const std::vector<cv::KeyPoint>& kps,
               std::vector<QuadNode>& out) {
  const float xm = 0.5f * (node.x0 + node.x1), ym = 0.5f * (node.y0 + node.y1);
  QuadNode children[4] = {{node.x0, node.y0, xm, ym, {}},
                          {xm, node.y0, node.x1, ym, {}},
                          {node.x0, ym, xm, node.y1, {}},
                          {xm, ym, node.x1, node.y1, {}}};
  for (int idx : node.members) {
    const cv::Point2f& p = kps[idx].pt;
    const int child = (p.x < xm ? 0 : 1) + (p.y < ym ? 0 : 2);
    children[child].members.push_back(idx);
  }
  for (auto& child : children)
    if (!child.members.empty()) out.push_back(std::move(child));
}

bool Splittable(const QuadNode& node) {
  // Below one pixel the points are effectively the same location: splitting cannot separate them.
  return node.members.size() > 1 && (node.x1 - node.x0) >= 1.f && (node.y1 - node.y0) >= 1.f;
}

// ORB-SLAM's DistributeOctTree idea: split regions into quadrants until there are at least
// `target` regions (or nothing is left to split), then keep the strongest keypoint per region.
// Keypoint coordinates are relative to the region [0, width) x [0, height).
std::vector<cv::KeyPoint> DistributeQuadtree(const std::vector<cv::KeyPoint>& kps, float width,
                                             float height, int target) {
  if (kps.empty() || target <= 0) return {};
  // Initial nodes: roughly square columns over the region (several for wide images like KITTI).
  const int num_initial = std::max(1, static_cast<int>(std::lround(width / height)));
  const float node_width = width / num_initial;
  std::vector<QuadNode> nodes;
  for (int i = 0; i < num_initial; ++i)
    nodes.push_back({node_width * i, 0.f, node_width * (i + 1), height, {}});
  for (int idx = 0; idx < static_cast<int>(kps.size()); ++idx) {
    const int column = std::min(num_initial - 1, static_cast<int>(kps[idx].pt.x / node_width));
    nodes[column].members.push_back(idx);
  }
  std::erase_if(nodes, [](const QuadNode& n) { return n.members.empty(); });

  while (static_cast<int>(nodes.size()) < target) {
    const size_t before = nodes.size();
    int num_splittable = 0;
    for (const auto& n : nodes) num_splittable += Splittable(n) ? 1 : 0;
    if (num_splittable == 0) break;

    if (static_cast<int>(nodes.size()) + 3 * num_splittable < target) {
      // Far from the target: split every splittable node.
      std::vector<QuadNode> next;
      next.reserve(nodes.size() + 3 * num_splittable);
      for (auto& n : nodes) {
        if (Splittable(n))
          SplitNode(n, kps, next);
        else
          next.push_back(std::move(n));
      }
      nodes = std::move(next);
    } else {
      // Close to the target: split the most populated nodes first, one at a time, so the last
      // regions go where keypoints are densest (stable order keeps this deterministic).
      std::vector<int> order(nodes.size());
      for (size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
      std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
        return nodes[a].members.size() > nodes[b].members.size();
      });
      std::vector<QuadNode> added;
      std::vector<char> removed(nodes.size(), 0);
      int count = static_cast<int>(nodes.size());
      for (int i : order) {
        if (count >= target) break;
        if (!Splittable(nodes[i])) continue;
        const size_t size_before = added.size();
        SplitNode(nodes[i], kps, added);
        removed[i] = 1;
        count += static_cast<int>(added.size() - size_before) - 1;
      }
      std::vector<QuadNode> next;
      for (size_t i = 0; i < nodes.size(); ++i)
        if (!removed[i]) next.push_back(std::move(nodes[i]));
      for (auto& n : added) next.push_back(std::move(n));
      nodes = std::move(next);
    }
    if (nodes.size() == before) break;
  }

  std::vector<cv::KeyPoint> result;
  result.reserve(nodes.size());
  for (const auto& n : nodes) {
    int best = n.members.front();
    for (int idx : n.members)
      if (kps[idx].response > kps[best].response) best = idx;
    result.push_back(kps[best]);
  }
  // Region order depends on the split history; sort by position so the output order is canonical.
  std::sort(result.begin(), result.end(), [](const cv::KeyPoint& a, const cv::KeyPoint& b) {
    return a.pt.y != b.pt.y ? a.pt.y < b.pt.y : a.pt.x < b.pt.x;
  });
  return result;
}

cv::Mat ToGrey(const cv::Mat& image) {
  if (image.depth() != CV_8U)
    throw std::invalid_argument("OrbExtractor: image must be 8-bit, got depth " +
                                std::to_string(image.depth()));
  cv::Mat grey;
  switch (image.channels()) {
    case 1:
      return image;
    case 3:
      cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
      return grey;
    case 4:
      cv::cvtColor(image, grey, cv::COLOR_BGRA2GRAY);
      return grey;
    default:
      throw std::invalid_argument("OrbExtractor: image must have 1, 3 or 4 channels, got " +
                                  std::to_string(image.channels()));
  }
}

}  // namespace

const OptionsTable<OrbOptions>& OrbOptions::Table() {
  static const auto table =
      OptionsTable<OrbOptions>("orb")
          .Add("num_features", &OrbOptions::num_features, Range::Above(0))
          .Add("scale_factor", &OrbOptions::scale_factor, Range::Above(1))
          .Add("num_levels", &OrbOptions::num_levels, Range::Closed(1, 32))
          .Add("initial_fast_threshold", &OrbOptions::initial_fast_threshold, Range::Closed(1, 254))
          .Add("min_fast_threshold", &OrbOptions::min_fast_threshold);
  return table;
}

void OrbOptions::Check() const {
  Table().CheckRanges(*this);
  if (min_fast_threshold < 1 || min_fast_threshold > initial_fast_threshold)
    throw std::invalid_argument(
        "orb.min_fast_threshold must be in [1, initial_fast_threshold], got " +
        std::to_string(min_fast_threshold));
}

OrbOptions OrbOptions::FromYaml(const YAML::Node& node) { return ReadOptions<OrbOptions>(node); }

YAML::Node OrbOptions::ToYaml() const { return Table().Write(*this); }

OrbExtractor::OrbExtractor(const OrbOptions& options) : options_(options) {
  options_.Check();
  const int levels = options_.num_levels;
  scale_factors_.resize(levels);
  level_sigma2_.resize(levels);
  inv_level_sigma2_.resize(levels);
  scale_factors_[0] = 1.f;
  for (int i = 1; i < levels; ++i)
    scale_factors_[i] = scale_factors_[i - 1] * options_.scale_factor;
  for (int i = 0; i < levels; ++i) {
    level_sigma2_[i] = scale_factors_[i] * scale_factors_[i];
    inv_level_sigma2_[i] = 1.f / level_sigma2_[i];
  }
  // Features per level form a geometric series with ratio 1/scale_factor (each level has
  // 1/scale^2 the area but keypoints there are larger), summing to num_features.
  features_per_level_.assign(levels, 0);
  const double factor = 1.0 / options_.scale_factor;
  double desired = options_.num_features * (1 - factor) / (1 - std::pow(factor, levels));
  int sum = 0;
  for (int i = 0; i < levels - 1; ++i) {
    features_per_level_[i] = static_cast<int>(std::lround(desired));
    sum += features_per_level_[i];
    desired *= factor;
  }
  features_per_level_[levels - 1] = std::max(options_.num_features - sum, 0);
}

void OrbExtractor::Extract(const cv::Mat& image, std::vector<cv::KeyPoint>& keypoints,
                           cv::Mat& descriptors, const cv::Mat& mask) const {
  keypoints.clear();
  descriptors = cv::Mat(0, 32, CV_8UC1);
  if (image.empty()) return;
  const cv::Mat grey = ToGrey(image);
  if (!mask.empty() && (mask.type() != CV_8UC1 || mask.size() != grey.size()))
    throw std::invalid_argument("OrbExtractor: mask must be CV_8UC1 of the image size");

  static const std::vector<int> umax = CircleRowExtents();
  // Descriptor computation only: OpenCV's ORB uses the same learned 256-pair pattern, steers it
  // by the keypoint angle we provide and blurs the (reflect-padded) image with a 7x7, sigma 2
  // Gaussian, as ORB-SLAM does. edgeThreshold 0 keeps every keypoint we hand it.
  const cv::Ptr<cv::ORB> describer =
      cv::ORB::create(1, 1.2f, 1, /*edgeThreshold=*/0, 0, 2, cv::ORB::HARRIS_SCORE, kPatchSize);

  cv::Mat level_image = grey;
  std::vector<cv::Mat> level_descriptors;
  for (int level = 0; level < options_.num_levels; ++level) {
    if (level > 0) {
      const float inv_scale = 1.f / scale_factors_[level];
      const cv::Size size(cvRound(grey.cols * inv_scale), cvRound(grey.rows * inv_scale));
      if (size.width <= 2 * kEdgeThreshold || size.height <= 2 * kEdgeThreshold) break;
      cv::Mat next;
      cv::resize(level_image, next, size, 0, 0, cv::INTER_LINEAR);
      level_image = next;
    }
    const int min_x = kEdgeThreshold - 3, min_y = kEdgeThreshold - 3;
    const int max_x = level_image.cols - kEdgeThreshold + 3;
    const int max_y = level_image.rows - kEdgeThreshold + 3;
    const int width = max_x - min_x, height = max_y - min_y;
    if (width <= kCellSize / 2 || height <= kCellSize / 2) break;

    cv::Mat level_mask;
    if (!mask.empty()) {
      if (level == 0)
        level_mask = mask;
      else
        cv::resize(mask, level_mask, level_image.size(), 0, 0, cv::INTER_NEAREST);
    }

    // FAST per grid cell (cells overlap by 6 px so corners on cell edges are seen), falling back
    // to the lower threshold in cells where the initial one finds nothing.
    FastGrid grid;
    grid.min_x = min_x, grid.min_y = min_y, grid.max_x = max_x, grid.max_y = max_y;
    grid.num_cols = std::max(1, width / kCellSize);
    grid.num_rows = std::max(1, height / kCellSize);
    grid.cell_w = static_cast<int>(std::ceil(static_cast<double>(width) / grid.num_cols));
    grid.cell_h = static_cast<int>(std::ceil(static_cast<double>(height) / grid.num_rows));
    std::vector<cv::KeyPoint> candidates = DetectGridFast(
        level_image, grid, options_.initial_fast_threshold, options_.min_fast_threshold);
    if (!level_mask.empty()) {
      std::erase_if(candidates, [&](const cv::KeyPoint& kp) {
        return level_mask.at<uchar>(cvRound(kp.pt.y) + min_y, cvRound(kp.pt.x) + min_x) == 0;
      });
    }
    // Overlapping cells report the same corner twice; keep one copy.
    std::sort(candidates.begin(), candidates.end(),
              [](const cv::KeyPoint& a, const cv::KeyPoint& b) {
                return a.pt.y != b.pt.y ? a.pt.y < b.pt.y : a.pt.x < b.pt.x;
              });
    candidates.erase(
        std::unique(candidates.begin(), candidates.end(),
                    [](const cv::KeyPoint& a, const cv::KeyPoint& b) { return a.pt == b.pt; }),
        candidates.end());

    std::vector<cv::KeyPoint> level_kps =
        DistributeQuadtree(candidates, static_cast<float>(width), static_cast<float>(height),
                           features_per_level_[level]);
    if (level_kps.empty()) continue;
    for (auto& kp : level_kps) {
      kp.pt.x += static_cast<float>(min_x);
      kp.pt.y += static_cast<float>(min_y);
      kp.octave = 0;  // for the single-level describer below; set to `level` afterwards
      kp.size = static_cast<float>(kPatchSize) * scale_factors_[level];
      kp.angle = IntensityCentroidAngle(level_image, kp.pt, umax);
      if (kp.angle >= 360.f) kp.angle -= 360.f;
    }

    cv::Mat desc;
    const size_t count = level_kps.size();
    describer->compute(level_image, level_kps, desc);
    if (level_kps.size() != count || desc.rows != static_cast<int>(count))
      throw std::logic_error("OrbExtractor: descriptor computation dropped keypoints");

    const float scale = scale_factors_[level];
    for (auto& kp : level_kps) {
      kp.octave = level;
      kp.pt *= scale;
      keypoints.push_back(kp);
    }
    level_descriptors.push_back(desc);
  }
  if (!level_descriptors.empty()) cv::vconcat(level_descriptors, descriptors);
}

}  // namespace ademono
