#include "ademono/synth/detector_recall.h"

#include <algorithm>
#include <fmt/format.h>
#include <stdexcept>
#include <tuple>
#include <unordered_map>

namespace ademono::synth {

int RecallClass(int class_id) { return class_id == 5 || class_id == 7 ? 2 : class_id; }

double BoxIou(const cv::Rect2f& a, const cv::Rect2f& b) {
  const float inter = (a & b).area();
  const float uni = a.area() + b.area() - inter;
  return uni > 0.f ? static_cast<double>(inter) / uni : 0.0;
}

RecallResult DetectorRecall(const std::vector<FrameDetections>& truth,
                            const std::vector<FrameDetections>& detected, double min_iou,
                            const std::vector<std::vector<std::string>>* labels) {
  if (labels && labels->size() != truth.size())
    throw std::invalid_argument("recall: one label list per ground-truth frame expected");
  std::unordered_map<std::string, const FrameDetections*> by_name;
  for (const FrameDetections& f : detected) by_name.emplace(f.name, &f);
  RecallResult result;
  result.min_iou = min_iou;
  for (size_t f = 0; f < truth.size(); ++f) {
    const FrameDetections& t = truth[f];
    ++result.frames;
    if (labels && (*labels)[f].size() != t.detections.size())
      throw std::invalid_argument("recall: one label per ground-truth box expected");
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
      if (labels) {
        ClassRecall& g = result.groups[(*labels)[f][i]];
        g.class_name = c.class_name;
        ++g.truth;
      }
      for (size_t j = 0; j < dets.size(); ++j) {
        if (RecallClass(dets[j].class_id) != RecallClass(t.detections[i].class_id)) continue;
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
      if (labels) ++result.groups[(*labels)[f][i]].found;
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
  if (!groups.empty()) {
    nlohmann::ordered_json groups_json = nlohmann::ordered_json::array();
    for (const auto& [label, g] : groups) {
      groups_json.push_back({{"label", label},
                             {"class", g.class_name},
                             {"truth_boxes", g.truth},
                             {"found", g.found},
                             {"recall", g.Recall()}});
    }
    j["groups"] = groups_json;
  }
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
  if (!groups.empty()) {
    out += "\n| object | class | true boxes | found | recall |\n|---|---|---|---|---|\n";
    for (const auto& [label, g] : groups)
      out += fmt::format("| {} | {} | {} | {} | {:.3f} |\n", label, g.class_name, g.truth,
                         g.found, g.Recall());
  }
  return out;
}

}  // namespace ademono::synth
