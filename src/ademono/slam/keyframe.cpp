#include "ademono/slam/keyframe.h"

#include <algorithm>

namespace ademono {

KeyFrame::KeyFrame(uint64_t id, const Frame& frame)
    : id(id),
      frame_id(frame.id),
      index(frame.index),
      timestamp(frame.timestamp),
      features(frame.features),
      cam_from_world(*frame.cam_from_world),
      map_points(frame.features->Size()) {}

void KeyFrame::EraseMapPoint(const MapPoint* point) {
  for (auto& p : map_points) {
    if (p.get() == point) p.reset();
  }
}

int KeyFrame::TrackedMapPoints(int min_observations) const {
  int n = 0;
  for (const auto& p : map_points) {
    if (p && !p->bad && p->NumObservations() >= min_observations) ++n;
  }
  return n;
}

void KeyFrame::AddConnection(KeyFrame* other, int weight) {
  connections[other] = weight;
  SortConnections();
}

void KeyFrame::EraseConnection(KeyFrame* other) {
  if (connections.erase(other) > 0) SortConnections();
}

void KeyFrame::SortConnections() {
  std::vector<std::pair<int, KeyFrame*>> sorted;
  for (const auto& [kf, w] : connections) sorted.emplace_back(w, kf);
  std::sort(sorted.begin(), sorted.end(), [](const auto& a, const auto& b) {
    return a.first != b.first ? a.first > b.first : a.second->id < b.second->id;
  });
  ordered_connections.clear();
  for (const auto& [w, kf] : sorted) ordered_connections.push_back(kf);
}

void KeyFrame::UpdateConnections() {
  std::map<KeyFrame*, int, KeyFrameIdLess> counter;
  for (const auto& p : map_points) {
    if (!p || p->bad) continue;
    for (const auto& [kf, idx] : p->observations) {
      if (kf != this && !kf->bad) ++counter[kf];
    }
  }
  if (counter.empty()) return;
  constexpr int kMinWeight = 15;
  KeyFrame* best = nullptr;
  int best_weight = 0;
  std::map<KeyFrame*, int, KeyFrameIdLess> kept;
  for (const auto& [kf, w] : counter) {
    if (w > best_weight) {
      best_weight = w;
      best = kf;
    }
    if (w >= kMinWeight) {
      kept[kf] = w;
      kf->AddConnection(this, w);
    }
  }
  // Without a strong edge, keep the strongest one so the keyframe stays in the graph.
  if (kept.empty() && best != nullptr) {
    kept[best] = best_weight;
    best->AddConnection(this, best_weight);
  }
  connections = kept;
  SortConnections();
  if (parent == nullptr && id != 0 && !ordered_connections.empty()) {
    parent = ordered_connections.front();
    parent->children.insert(this);
  }
}

std::vector<KeyFrame*> KeyFrame::BestCovisibles(size_t n) const {
  std::vector<KeyFrame*> result;
  for (KeyFrame* kf : ordered_connections) {
    if (result.size() >= n) break;
    if (!kf->bad) result.push_back(kf);
  }
  return result;
}

bool AnyGround(const std::vector<std::shared_ptr<KeyFrame>>& keyframes) {
  return std::any_of(keyframes.begin(), keyframes.end(),
                     [](const auto& kf) { return kf && kf->ground.has_value(); });
}

void AppendGroundDistances(const KeyFrame& keyframe, size_t camera,
                           const std::map<uint64_t, size_t>& point_index,
                           std::vector<BaPlaneDistance>& distances) {
  if (!keyframe.ground) return;
  const KeyFrame::Ground& ground = *keyframe.ground;
  for (uint64_t id : ground.point_ids) {
    const auto it = point_index.find(id);
    if (it == point_index.end()) continue;
    distances.push_back({camera, it->second, ground.normal_cam, -ground.height,
                         1.0 / ground.sigma, ground.free_normal ? 0 : -1});
  }
}

}  // namespace ademono
