#pragma once
// Keypoints bucketed in square cells so that those near a line (an epipolar line) are found
// without testing every keypoint: SearchForTriangulation on a 1241x376 KITTI keyframe tested
// each of ~2,500 free keypoints against every epipolar line of the ~3,000 keypoints of each of
// 20 neighbours; the band of a line holds about a tenth of them. FrameFeatures::grid does not
// serve here: it holds every keypoint (this a subset, the free ones) and leaves out those
// undistorted outside the image, which the brute-force search did test.

#include <Eigen/Core>
#include <cstddef>
#include <opencv2/core/types.hpp>
#include <vector>

namespace ademono {

class LineSearchGrid {
 public:
  // Buckets keypoints[i] for every i in `indices`; cells cover the indices' bounding box.
  LineSearchGrid(const std::vector<cv::KeyPoint>& keypoints, const std::vector<size_t>& indices);

  // Replaces `out` with every bucketed index whose keypoint lies within `radius` pixels of the
  // line l.x() u + l.y() v + l.z() = 0, and more (whole cells): the caller applies its exact
  // test. In cell order, not index order: a caller that breaks ties towards the lower index
  // gets what a scan in index order gives.
  void Near(const Eigen::Vector3d& line, double radius, std::vector<size_t>* out) const;

 private:
  double min_x_ = 0, min_y_ = 0, cell_ = 1;
  int cols_ = 0, rows_ = 0;
  // Cell k (row-major) holds indices_[offsets_[k] .. offsets_[k + 1]).
  std::vector<size_t> offsets_, indices_;
};

}  // namespace ademono
