#pragma once
// Per-frame picture of what the filters did: dynamic boxes (grown, as the filter used them) with
// their class name, small boxes thin and dashed, large boxes thick; keypoints coloured by label;
// a legend with the count per label.

#include <opencv2/core.hpp>
#include <vector>

#include "ademono/filter/feature_filter.h"
#include "ademono/perception/detection.h"

namespace ademono {

// BGR colour of each label: kept green, stage-1 red, stage-2 dark red, small-box magenta,
// distant grey, enhancement-dropped yellow.
cv::Scalar PointLabelColor(PointLabel label);

// Returns a BGR copy of `image` (CV_8UC1 or CV_8UC3) with the annotations. `labels` has one entry
// per keypoint (throws std::invalid_argument otherwise). Boxes are grown and classified with the
// same options the filter used, so the picture shows exactly what the filter saw.
cv::Mat DrawFilterResult(const cv::Mat& image, const std::vector<cv::KeyPoint>& keypoints,
                         const std::vector<PointLabel>& labels,
                         const std::vector<Detection>& detections, const FilterOptions& options);

}  // namespace ademono
