#include "ademono/filter/visualize.h"

#include <array>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>

#include "ademono/filter/dynamic.h"

namespace ademono {
namespace {

// Legend order; the size makes a new label a compile error here until it gets a colour.
constexpr std::array<PointLabel, kNumPointLabels> kAllLabels{
    PointLabel::kKept,          PointLabel::kEnhancementDropped, PointLabel::kDynamicSmallBox,
    PointLabel::kDynamicStage1, PointLabel::kDynamicStage2,      PointLabel::kDynamicBoxVote,
    PointLabel::kDistantDropped};

void DashedLine(cv::Mat& img, cv::Point2f a, cv::Point2f b, const cv::Scalar& color) {
  const double length = std::hypot(b.x - a.x, b.y - a.y);
  constexpr double kDash = 6.0;
  for (double s = 0; s < length; s += 2 * kDash) {
    const double e = std::min(length, s + kDash);
    const cv::Point2f p0 = a + (b - a) * static_cast<float>(s / length);
    const cv::Point2f p1 = a + (b - a) * static_cast<float>(e / length);
    cv::line(img, p0, p1, color, 1, cv::LINE_AA);
  }
}

}  // namespace

cv::Scalar PointLabelColor(PointLabel label) {
  switch (label) {
    case PointLabel::kKept:
      return {0, 200, 0};
    case PointLabel::kEnhancementDropped:
      return {0, 220, 255};
    case PointLabel::kDynamicSmallBox:
      return {255, 0, 255};
    case PointLabel::kDynamicStage1:
      return {0, 0, 255};
    case PointLabel::kDynamicStage2:
      return {0, 0, 128};
    case PointLabel::kDistantDropped:
      return {150, 150, 150};
    case PointLabel::kDynamicBoxVote:
      return {255, 128, 0};
  }
  return {255, 255, 255};
}

cv::Mat DrawFilterResult(const cv::Mat& image, const std::vector<cv::KeyPoint>& keypoints,
                         const std::vector<PointLabel>& labels,
                         const std::vector<Detection>& detections, const FilterOptions& options) {
  if (labels.size() != keypoints.size())
    throw std::invalid_argument("DrawFilterResult: one label per keypoint expected");
  if (image.empty() || image.depth() != CV_8U || (image.channels() != 1 && image.channels() != 3))
    throw std::invalid_argument("DrawFilterResult: image must be CV_8UC1 or CV_8UC3");
  cv::Mat canvas;
  if (image.channels() == 1)
    cv::cvtColor(image, canvas, cv::COLOR_GRAY2BGR);
  else
    canvas = image.clone();

  const cv::Scalar box_color(255, 128, 0);
  for (const GrownBox& b : GrowDynamicBoxes(detections, canvas.size(), options.dynamic)) {
    const cv::Point2f tl(b.box.x, b.box.y), br(b.box.x + b.box.width, b.box.y + b.box.height);
    const cv::Point2f tr(br.x, tl.y), bl(tl.x, br.y);
    if (b.small) {
      DashedLine(canvas, tl, tr, box_color);
      DashedLine(canvas, tr, br, box_color);
      DashedLine(canvas, br, bl, box_color);
      DashedLine(canvas, bl, tl, box_color);
    } else {
      cv::rectangle(canvas, tl, br, box_color, 3, cv::LINE_AA);
    }
    const Detection& det = detections[static_cast<size_t>(b.detection_index)];
    const std::string text =
        (det.class_name.empty() ? std::to_string(det.class_id) : det.class_name) +
        (b.small ? " (small)" : " (large)");
    // White text on a box-coloured tag above the box (inside it when the box touches the top).
    int baseline = 0;
    const cv::Size text_size = cv::getTextSize(text, cv::FONT_HERSHEY_SIMPLEX, 0.45, 1, &baseline);
    const int tag_h = text_size.height + baseline + 4;
    const int tag_y = cvRound(tl.y) - tag_h >= 0 ? cvRound(tl.y) - tag_h : cvRound(tl.y);
    cv::rectangle(canvas, cv::Rect(cvRound(tl.x), tag_y, text_size.width + 4, tag_h), box_color,
                  cv::FILLED);
    cv::putText(canvas, text, cv::Point(cvRound(tl.x) + 2, tag_y + text_size.height + 2),
                cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  }

  std::array<int, kAllLabels.size()> counts{};
  for (size_t i = 0; i < keypoints.size(); ++i) {
    ++counts[static_cast<size_t>(labels[i])];
    // LINE_8 keeps the exact label colour (antialiasing would blend it into the image).
    cv::circle(canvas, keypoints[i].pt, 3, PointLabelColor(labels[i]),
               labels[i] == PointLabel::kKept ? 1 : -1, cv::LINE_8);
  }

  // Legend on a dark panel in the top-left corner.
  const int line_h = 16;
  const cv::Rect panel(4, 4, 230, line_h * static_cast<int>(kAllLabels.size()) + 8);
  cv::Mat roi = canvas(panel & cv::Rect(0, 0, canvas.cols, canvas.rows));
  roi *= 0.35;
  for (size_t k = 0; k < kAllLabels.size(); ++k) {
    const int y = panel.y + 4 + line_h * static_cast<int>(k) + line_h / 2;
    cv::circle(canvas, cv::Point(panel.x + 10, y), 4, PointLabelColor(kAllLabels[k]), -1,
               cv::LINE_AA);
    cv::putText(canvas,
                std::string(PointLabelName(kAllLabels[k])) + ": " +
                    std::to_string(counts[static_cast<size_t>(kAllLabels[k])]),
                cv::Point(panel.x + 20, y + 4), cv::FONT_HERSHEY_SIMPLEX, 0.4,
                cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  }
  return canvas;
}

}  // namespace ademono
