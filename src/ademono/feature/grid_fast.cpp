#include "ademono/feature/grid_fast.h"

#include <algorithm>
#include <cstdint>
#include <opencv2/features2d.hpp>

namespace ademono {
namespace {

// Calls f(x0, y0, x1, y1) for every cell of the grid, in row-major order, as the extractor
// always laid them out.
template <typename F>
void ForEachCell(const FastGrid& g, F&& f) {
  for (int r = 0; r < g.num_rows; ++r) {
    const int y0 = g.min_y + r * g.cell_h;
    if (y0 >= g.max_y - 3) continue;
    const int y1 = std::min(y0 + g.cell_h + 6, g.max_y);
    for (int c = 0; c < g.num_cols; ++c) {
      const int x0 = g.min_x + c * g.cell_w;
      if (x0 >= g.max_x - 6) continue;
      const int x1 = std::min(x0 + g.cell_w + 6, g.max_x);
      f(x0, y0, x1, y1);
    }
  }
}

// cv::FAST's score of a FAST-9 corner (features2d's cornerScore<16>): the largest threshold at
// which it is still a corner, i.e. max over the 16 arcs of 9 contiguous circle pixels of the
// smallest |difference| of one sign, minus one. Independent of the detection threshold for any
// pixel that is a corner at it.
int CornerScore(const uchar* p, const int offsets[16]) {
  const int center = p[0];
  // d around the circle, twice, so every arc is a contiguous run; minima of runs of 2, 4, 8, 9 by
  // doubling (fixed-size loops the compiler vectorises).
  int16_t dark[32], bright[32];
  for (int k = 0; k < 16; ++k) {
    const int d = center - p[offsets[k]];
    dark[k] = dark[k + 16] = static_cast<int16_t>(d);
    bright[k] = bright[k + 16] = static_cast<int16_t>(-d);
  }
  int16_t m2d[31], m2b[31], m4d[29], m4b[29], m8d[25], m8b[25];
  for (int k = 0; k < 31; ++k) {
    m2d[k] = std::min(dark[k], dark[k + 1]);
    m2b[k] = std::min(bright[k], bright[k + 1]);
  }
  for (int k = 0; k < 29; ++k) {
    m4d[k] = std::min(m2d[k], m2d[k + 2]);
    m4b[k] = std::min(m2b[k], m2b[k + 2]);
  }
  for (int k = 0; k < 25; ++k) {
    m8d[k] = std::min(m4d[k], m4d[k + 4]);
    m8b[k] = std::min(m4b[k], m4b[k + 4]);
  }
  int best = 0;
  for (int k = 0; k < 16; ++k) {
    best = std::max(best, static_cast<int>(std::min(m8d[k], dark[k + 8])));
    best = std::max(best, static_cast<int>(std::min(m8b[k], bright[k + 8])));
  }
  return best - 1;
}

}  // namespace

std::vector<cv::KeyPoint> DetectGridFastReference(const cv::Mat& image, const FastGrid& grid,
                                                  int initial_threshold, int min_threshold) {
  std::vector<cv::KeyPoint> out, cell_kps;
  ForEachCell(grid, [&](int x0, int y0, int x1, int y1) {
    const cv::Mat cell = image(cv::Range(y0, y1), cv::Range(x0, x1));
    cell_kps.clear();
    cv::FAST(cell, cell_kps, initial_threshold, true);
    if (cell_kps.empty()) cv::FAST(cell, cell_kps, min_threshold, true);
    for (auto& kp : cell_kps) {
      kp.pt.x += static_cast<float>(x0 - grid.min_x);
      kp.pt.y += static_cast<float>(y0 - grid.min_y);
      out.push_back(kp);
    }
  });
  return out;
}

std::vector<cv::KeyPoint> DetectGridFast(const cv::Mat& image, const FastGrid& grid,
                                         int initial_threshold, int min_threshold) {
  CV_Assert(image.type() == CV_8UC1);
  // Every corner at the initial threshold, in one pass (the cells lie inside [3, size - 3)). The
  // few cells that need the fallback threshold run cv::FAST themselves: scoring every corner at
  // the low threshold costs more than it saves.
  std::vector<cv::KeyPoint> corners;
  cv::FAST(image, corners, initial_threshold, false);
  const int step = static_cast<int>(image.step1());
  const int offsets[16] = {3 * step,  3 * step + 1,  2 * step + 2,  step + 3,
                           3,         -step + 3,     -2 * step + 2, -3 * step + 1,
                           -3 * step, -3 * step - 1, -2 * step - 2, -step - 3,
                           -3,        step - 3,      2 * step - 2,  3 * step - 1};
  // Scores (0: no corner at the initial threshold) and, per row, the range of corners on it
  // (cv::FAST returns them row by row, left to right).
  cv::Mat1b scores(image.size(), uchar{0});
  std::vector<int> row_start(image.rows + 1, 0);
  std::vector<int> xs(corners.size());
  for (size_t i = 0; i < corners.size(); ++i) {
    const int x = cvRound(corners[i].pt.x), y = cvRound(corners[i].pt.y);
    xs[i] = x;
    scores(y, x) = static_cast<uchar>(CornerScore(image.ptr<uchar>(y) + x, offsets));
    ++row_start[y + 1];
  }
  for (int y = 0; y < image.rows; ++y) row_start[y + 1] += row_start[y];

  std::vector<cv::KeyPoint> out, cell_kps;
  ForEachCell(grid, [&](int x0, int y0, int x1, int y1) {
    // cv::FAST on the cell looks at [3, size - 3) of it; suppression compares a corner with its
    // 8 neighbours' scores at the same threshold, 0 outside that zone.
    const int zx0 = x0 + 3, zx1 = x1 - 3, zy0 = y0 + 3, zy1 = y1 - 3;
    const int threshold = initial_threshold;
    const size_t before = out.size();
    auto score = [&](int x, int y) -> int {
      if (x < zx0 || x >= zx1 || y < zy0 || y >= zy1) return 0;
      const int s = scores(y, x);
      return s >= threshold ? s : 0;
    };
    for (int y = zy0; y < zy1; ++y) {
      for (int i = row_start[y]; i < row_start[y + 1]; ++i) {
        const int x = xs[i];
        if (x < zx0) continue;
        if (x >= zx1) break;
        const int s = scores(y, x);
        if (s < threshold) continue;  // a corner is one at `threshold` iff its score >= it
        if (s > score(x - 1, y) && s > score(x + 1, y) && s > score(x - 1, y - 1) &&
            s > score(x, y - 1) && s > score(x + 1, y - 1) && s > score(x - 1, y + 1) &&
            s > score(x, y + 1) && s > score(x + 1, y + 1)) {
          out.emplace_back(static_cast<float>(x - grid.min_x), static_cast<float>(y - grid.min_y),
                           7.f, -1.f, static_cast<float>(s));
        }
      }
    }
    if (out.size() > before) return;
    // Nothing at the initial threshold: the fallback, as the reference does it.
    cell_kps.clear();
    cv::FAST(image(cv::Range(y0, y1), cv::Range(x0, x1)), cell_kps, min_threshold, true);
    for (auto& kp : cell_kps) {
      kp.pt.x += static_cast<float>(x0 - grid.min_x);
      kp.pt.y += static_cast<float>(y0 - grid.min_y);
      out.push_back(kp);
    }
  });
  return out;
}

}  // namespace ademono
