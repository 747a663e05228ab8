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

namespace {
constexpr size_t kScaleSamples = 40;  // a median of 40 ratios: robust to a few moved points
constexpr size_t kMinScaleSamples = 8;
}  // namespace

int KeyFrame::SnapshotScale(uint64_t version) {
  if (bad) return -1;  // no points left to measure with: the pose stays rigid to it
  if (!scale_snapshots.empty() && scale_snapshots.back().version == version)
    return static_cast<int>(scale_snapshots.size()) - 1;
  ScaleSnapshot snapshot;
  snapshot.version = version;
  size_t count = 0;
  for (const auto& p : map_points) count += p && !p->bad;
  // Evenly over the keyframe's points (deterministic).
  const size_t stride = std::max<size_t>(1, count / kScaleSamples);
  size_t k = 0;
  for (const auto& p : map_points) {
    if (!p || p->bad) continue;
    if (k++ % stride != 0) continue;
    const double z = (cam_from_world * p->position).z();
    if (z > 0) snapshot.points.emplace_back(p, static_cast<float>(z));
  }
  scale_snapshots.push_back(std::move(snapshot));
  return static_cast<int>(scale_snapshots.size()) - 1;
}

double KeyFrame::LocalScaleSince(int s) const {
  if (s < 0 || static_cast<size_t>(s) >= scale_snapshots.size()) return 1.0;
  const ScaleSnapshot& snapshot = scale_snapshots[static_cast<size_t>(s)];
  if (bad) return snapshot.scale_at_cull;
  std::vector<double> ratios;
  ratios.reserve(snapshot.points.size());
  for (const auto& [weak, z_then] : snapshot.points) {
    std::shared_ptr<MapPoint> p = weak.lock();
    if (p && p->replaced_by) p = MapPoint::Resolve(p);
    if (!p || p->bad) continue;
    const double z = (cam_from_world * p->position).z();
    if (z > 0 && z_then > 0) ratios.push_back(z / z_then);
  }
  if (ratios.size() < kMinScaleSamples) return 1.0;
  auto mid = ratios.begin() + static_cast<long>(ratios.size() / 2);
  std::nth_element(ratios.begin(), mid, ratios.end());
  return *mid;
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
