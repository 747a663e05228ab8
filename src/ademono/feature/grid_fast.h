#pragma once
// FAST-9 corners on a grid of overlapping cells with a per-cell fallback threshold (the ORB
// extractor's detector). Calling cv::FAST once per small cell leaves its SIMD loop mostly idle on
// 36-pixel rows; DetectGridFast instead runs one vectorised cv::FAST pass over the whole image,
// scores each corner once, and then reproduces per cell what cv::FAST on that cell (with non-max
// suppression) would return: the same keypoints, bit for bit (tests/feature/grid_fast_test.cpp
// checks it against DetectGridFastReference).

#include <opencv2/core.hpp>
#include <vector>

namespace ademono {

struct FastGrid {
  int min_x = 0, min_y = 0, max_x = 0, max_y = 0;  // the detection region
  int num_cols = 1, num_rows = 1, cell_w = 0, cell_h = 0;
};

// Keypoints of every cell, cell by cell (rows, then columns), each cell's keypoints in the order
// cv::FAST returns them, with coordinates relative to (min_x, min_y). A cell spans
// [x0, min(x0 + cell_w + 6, max_x)) x [y0, min(y0 + cell_h + 6, max_y)); it is searched with
// `initial_threshold`, and again with `min_threshold` if that found nothing.
std::vector<cv::KeyPoint> DetectGridFast(const cv::Mat& image, const FastGrid& grid,
                                         int initial_threshold, int min_threshold);

// The same with one cv::FAST call per cell (the reference; slower).
std::vector<cv::KeyPoint> DetectGridFastReference(const cv::Mat& image, const FastGrid& grid,
                                                  int initial_threshold, int min_threshold);

}  // namespace ademono
