#include "ademono/eval/map_scale.h"

#include <algorithm>
#include <cmath>

#include "ademono/eval/trajectory_eval.h"

namespace ademono {

std::optional<KeyFrameMapScale> MeasureKeyFrameScale(
    size_t frame, const std::vector<MapDepthObservation>& observations, const cv::Mat& sensor_depth,
    size_t min_samples) {
  if (sensor_depth.empty() || sensor_depth.type() != CV_32FC1) return std::nullopt;
  std::vector<double> ratios;
  ratios.reserve(observations.size());
  for (const MapDepthObservation& o : observations) {
    if (!(o.map_depth > 0) || !o.pixel.allFinite()) continue;
    const long u = std::lround(o.pixel.x()), v = std::lround(o.pixel.y());
    if (u < 0 || v < 0 || u >= sensor_depth.cols || v >= sensor_depth.rows) continue;
    const float z = sensor_depth.at<float>(static_cast<int>(v), static_cast<int>(u));
    if (z > 0 && std::isfinite(z)) ratios.push_back(z / o.map_depth);
  }
  if (ratios.size() < std::max<size_t>(min_samples, 1)) return std::nullopt;
  return KeyFrameMapScale{frame, ratios.size(), ComputeStats(ratios).median};
}

std::optional<MapScaleReport> SummarizeMapScale(std::vector<KeyFrameMapScale> per_keyframe) {
  if (per_keyframe.empty()) return std::nullopt;
  std::sort(per_keyframe.begin(), per_keyframe.end(),
            [](const KeyFrameMapScale& a, const KeyFrameMapScale& b) { return a.frame < b.frame; });
  std::vector<double> scales;
  for (const KeyFrameMapScale& k : per_keyframe) scales.push_back(k.scale);
  MapScaleReport report;
  report.median = ComputeStats(scales).median;
  report.p10 = Percentile(scales, 0.1);
  report.p90 = Percentile(scales, 0.9);
  report.per_keyframe = std::move(per_keyframe);
  return report;
}

nlohmann::json MapScaleReport::ToJson() const {
  nlohmann::json list = nlohmann::json::array();
  for (const KeyFrameMapScale& k : per_keyframe)
    list.push_back({{"frame", k.frame}, {"samples", k.samples}, {"scale", k.scale}});
  return {{"keyframes", per_keyframe.size()},
          {"median", median},
          {"p10", p10},
          {"p90", p90},
          {"per_keyframe", std::move(list)}};
}

}  // namespace ademono
