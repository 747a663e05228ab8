#include "ademono/synth/detector_recall.h"

#include <algorithm>
#include <fmt/format.h>
#include <tuple>
#include <unordered_map>

namespace ademono::synth {

double BoxIou(const cv::Rect2f& a, const cv::Rect2f& b) {
  const float inter = (a & b).area();
  const float uni = a.area() + b.area() - inter;
  return uni > 0.f ? static_cast<double>(inter) / uni : 0.0;
}

RecallResult DetectorRecall(const std::vector<FrameDetections>& truth,
                            const std::vector<FrameDetections>& detected, double min_iou) {
  std::unordered_map<std::string, const FrameDetections*> by_name;
  for (const FrameDetections& f : detected) by_name.emplace(f.name, &f);
  RecallResult result;
  result.min_iou = min_iou;
  for (const FrameDetections& t : truth) {
    ++result.frames;
    const auto it = by_name.find(t.name);
    const std::vector<Detection> none;
    const std::vector<Detection>& dets = it == by_name.end() ? none : it->second->detections;
    for (const Detection& d : dets) {
      ClassRecall& c = result.classes[d.class_id];
      c.class_name = d.class_name;
      ++c.detected;
    }
    // Candidate pairs of the same class, best IoU first; ties by index for a fixed result.
    std::vector<std::tuple<double, size_t, size_t>> pairs;
    for (size_t i = 0; i < t.detections.size(); ++i) {
      ClassRecall& c = result.classes[t.detections[i].class_id];
      c.class_name = t.detections[i].class_name;
      ++c.truth;
      for (size_t j = 0; j < dets.size(); ++j) {
        if (dets[j].class_id != t.detections[i].class_id) continue;
        const double iou = BoxIou(t.detections[i].box, dets[j].box);
        if (iou >= min_iou) pairs.emplace_back(-iou, i, j);
      }
    }
    std::sort(pairs.begin(), pairs.end());
    std::vector<bool> truth_used(t.detections.size(), false), det_used(dets.size(), false);
    for (const auto& [neg_iou, i, j] : pairs) {
      if (truth_used[i] || det_used[j]) continue;
      truth_used[i] = det_used[j] = true;
      ++result.classes[t.detections[i].class_id].found;
    }
  }
  return result;
}

nlohmann::ordered_json RecallResult::ToJson() const {
  nlohmann::ordered_json j;
  j["frames"] = frames;
  j["min_iou"] = min_iou;
  nlohmann::ordered_json classes_json = nlohmann::ordered_json::array();
  long long truth = 0, found = 0;
  for (const auto& [id, c] : classes) {
    classes_json.push_back({{"class_id", id},
                            {"class", c.class_name},
                            {"truth_boxes", c.truth},
                            {"found", c.found},
                            {"detections", c.detected},
                            {"recall", c.truth > 0 ? nlohmann::ordered_json(c.Recall())
                                                   : nlohmann::ordered_json(nullptr)}});
    truth += c.truth;
    found += c.found;
  }
  j["classes"] = classes_json;
  j["truth_boxes"] = truth;
  j["found"] = found;
  j["recall"] = truth > 0 ? nlohmann::ordered_json(static_cast<double>(found) / truth)
                          : nlohmann::ordered_json(nullptr);
  return j;
}

std::string RecallResult::Markdown() const {
  std::string out = fmt::format(
      "| class | true boxes | found (IoU >= {:g}) | recall | detections |\n", min_iou);
  out += "|---|---|---|---|---|\n";
  long long truth = 0, found = 0, detected = 0;
  for (const auto& [id, c] : classes) {
    out += fmt::format("| {} | {} | {} | {} | {} |\n", c.class_name, c.truth, c.found,
                       c.truth > 0 ? fmt::format("{:.3f}", c.Recall()) : "-", c.detected);
    truth += c.truth, found += c.found, detected += c.detected;
  }
  out += fmt::format("| all | {} | {} | {} | {} |\n", truth, found,
                     truth > 0 ? fmt::format("{:.3f}", static_cast<double>(found) / truth) : "-",
                     detected);
  return out;
}

}  // namespace ademono::synth
