#include "ademono/slam/map.h"

#include <algorithm>

namespace ademono {

std::shared_ptr<KeyFrame> Map::CreateKeyFrame(const Frame& frame) {
  auto kf = std::make_shared<KeyFrame>(next_keyframe_id_++, frame);
  keyframes_[kf->id] = kf;
  if (database_ != nullptr) database_->Add(kf->id, kf->F().descriptors);
  return kf;
}

std::shared_ptr<KeyFrame> Map::RestoreKeyFrame(uint64_t id, const Frame& frame) {
  auto kf = std::make_shared<KeyFrame>(id, frame);
  keyframes_[id] = kf;
  next_keyframe_id_ = std::max(next_keyframe_id_, id + 1);
  if (database_ != nullptr) database_->Add(id, kf->F().descriptors);
  return kf;
}

std::shared_ptr<MapPoint> Map::RestoreMapPoint(uint64_t id, const Eigen::Vector3d& position,
                                               KeyFrame* reference, uint64_t frame_id) {
  auto p = std::make_shared<MapPoint>(id, position, reference, frame_id);
  points_[id] = p;
  next_point_id_ = std::max(next_point_id_, id + 1);
  return p;
}

std::shared_ptr<MapPoint> Map::CreateMapPoint(const Eigen::Vector3d& position, KeyFrame* reference,
                                              uint64_t frame_id) {
  auto p = std::make_shared<MapPoint>(next_point_id_++, position, reference, frame_id);
  points_[p->id] = p;
  return p;
}

void Map::ErasePoint(MapPoint* point) {
  if (point == nullptr || point->bad) return;
  point->bad = true;
  const auto observations = point->observations;
  point->observations.clear();
  for (const auto& [kf, idx] : observations) {
    if (idx < kf->map_points.size() && kf->map_points[idx].get() == point)
      kf->map_points[idx].reset();
  }
  points_.erase(point->id);
}

void Map::ReplacePoint(MapPoint* old_point, const std::shared_ptr<MapPoint>& new_point) {
  if (old_point == nullptr || old_point == new_point.get() || old_point->bad) return;
  const auto observations = old_point->observations;
  old_point->observations.clear();
  old_point->bad = true;
  old_point->replaced_by = new_point;
  for (const auto& [kf, idx] : observations) {
    if (!new_point->IsInKeyFrame(kf)) {
      kf->map_points[idx] = new_point;
      new_point->AddObservation(kf, idx);
    } else {
      kf->map_points[idx].reset();
    }
  }
  if (!new_point->frozen) {  // a loaded map's point keeps its statistics (localisation only)
    new_point->found += old_point->found;
    new_point->visible += old_point->visible;
  }
  new_point->ComputeDistinctiveDescriptor();
  points_.erase(old_point->id);
}

void Map::EraseKeyFrame(KeyFrame* keyframe) {
  if (keyframe == nullptr || keyframe->bad || keyframe->id == 0) return;
  // Poses stored relative to it keep the local scale's change until now; its points go below.
  for (size_t s = 0; s < keyframe->scale_snapshots.size(); ++s) {
    KeyFrame::ScaleSnapshot& snapshot = keyframe->scale_snapshots[s];
    snapshot.scale_at_cull = keyframe->LocalScaleSince(static_cast<int>(s));
    std::vector<std::pair<std::weak_ptr<MapPoint>, float>>().swap(snapshot.points);
  }
  for (KeyFrame* other : std::vector<KeyFrame*>(keyframe->ordered_connections)) {
    other->EraseConnection(keyframe);
  }
  for (auto& p : keyframe->map_points) {
    if (!p) continue;
    // Keep the point alive while its observations are updated: the keyframe's pointer may be the
    // last owner (a point already erased from the map), and resetting it first freed the point.
    const std::shared_ptr<MapPoint> point = std::move(p);
    p.reset();
    point->EraseObservation(keyframe);
    if (point->observations.empty()) {
      ErasePoint(point.get());
    } else if (!point->bad) {
      point->UpdateNormalAndDepth();
    }
  }
  keyframe->connections.clear();
  keyframe->ordered_connections.clear();

  // Re-parent the children: each picks its strongest covisible link among the candidates,
  // starting from this keyframe's parent (ORB-SLAM's spanning tree update, simplified).
  std::set<KeyFrame*, KeyFrameIdLess> candidates;
  if (keyframe->parent != nullptr) candidates.insert(keyframe->parent);
  std::set<KeyFrame*, KeyFrameIdLess> children = keyframe->children;
  while (!children.empty()) {
    KeyFrame* best_child = nullptr;
    KeyFrame* best_parent = nullptr;
    int best_weight = -1;
    for (KeyFrame* child : children) {
      for (const auto& [kf, w] : child->connections) {
        if (candidates.count(kf) > 0 && w > best_weight) {
          best_weight = w;
          best_child = child;
          best_parent = kf;
        }
      }
    }
    if (best_child == nullptr) break;
    best_child->parent = best_parent;
    best_parent->children.insert(best_child);
    candidates.insert(best_child);
    children.erase(best_child);
  }
  for (KeyFrame* child : children) {
    child->parent = keyframe->parent;
    if (keyframe->parent != nullptr) keyframe->parent->children.insert(child);
  }
  if (keyframe->parent != nullptr) {
    keyframe->parent->children.erase(keyframe);
    keyframe->cam_from_parent =
        keyframe->cam_from_world * keyframe->parent->cam_from_world.inverse();
    if (!keyframe->scale_snapshots.empty())
      keyframe->parent_snapshot = keyframe->parent->SnapshotScale(structure_version_);
  }
  keyframe->children.clear();
  keyframe->bad = true;
  if (database_ != nullptr) database_->Erase(keyframe->id);
  // Memory grows with the map, not with the frames: a culled keyframe keeps only its pose link
  // (the frames that referenced it still resolve through it), not its keypoints or descriptors.
  // Nor its per-keypoint map point slots (16 bytes a keypoint: most of what a culled keyframe
  // still held; a saturated map culls a keyframe every few frames). Its F().Size() is now 0,
  // so every loop over its keypoints is empty.
  keyframe->features = WithoutKeypoints(keyframe->F());
  std::vector<std::shared_ptr<MapPoint>>().swap(keyframe->map_points);
  std::vector<KeyFrame*>().swap(keyframe->ordered_connections);
  auto it = keyframes_.find(keyframe->id);
  if (it != keyframes_.end()) {
    graveyard_.push_back(it->second);
    keyframes_.erase(it);
  }
}

std::shared_ptr<KeyFrame> Map::GetKeyFrame(uint64_t id) const {
  auto it = keyframes_.find(id);
  return it == keyframes_.end() ? nullptr : it->second;
}

std::shared_ptr<MapPoint> Map::GetMapPoint(uint64_t id) const {
  auto it = points_.find(id);
  return it == points_.end() ? nullptr : it->second;
}

Rigid3d Map::ResolvePose(const KeyFrame* keyframe, const Rigid3d& cam_from_keyframe,
                         int snapshot) {
  Rigid3d cam_from_kf = cam_from_keyframe;
  int s = snapshot;
  int guard = 0;
  while (keyframe->bad && keyframe->parent != nullptr && guard++ < 10000) {
    if (s >= 0) cam_from_kf.translation() *= keyframe->LocalScaleSince(s);
    cam_from_kf = cam_from_kf * keyframe->cam_from_parent;
    s = s >= 0 ? keyframe->parent_snapshot : -1;
    keyframe = keyframe->parent;
  }
  if (s >= 0) cam_from_kf.translation() *= keyframe->LocalScaleSince(s);
  return cam_from_kf * keyframe->cam_from_world;
}

void Map::Rescale(double factor) {
  auto rescale_keyframe = [factor](KeyFrame& kf) {
    kf.cam_from_world.translation() *= factor;
    kf.cam_from_parent.translation() *= factor;
    for (auto& snapshot : kf.scale_snapshots) {
      for (auto& [point, z] : snapshot.points) z *= static_cast<float>(factor);
    }
    // The keyframe's depths too: local BA's depth residuals would pull the map back.
    kf.features = RescaleDepth(kf.F(), static_cast<float>(factor));
    if (kf.network_fit.valid) kf.network_fit.Rescale(factor);
  };
  for (auto& [id, kf] : keyframes_) rescale_keyframe(*kf);
  for (auto& kf : graveyard_) rescale_keyframe(*kf);
  const float f = static_cast<float>(factor);
  for (auto& [id, p] : points_) {
    p->position *= factor;
    p->min_distance *= f;
    p->max_distance *= f;
  }
}

}  // namespace ademono
