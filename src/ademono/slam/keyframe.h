#pragma once
// A keyframe (ORB-SLAM's KeyFrame): the frame's features, its pose, its map points and the
// covisibility graph with a spanning tree. Guarded by the owning Map's mutex.

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <vector>

#include "ademono/optimize/bundle_adjustment.h"
#include "ademono/optimize/network_depth_model.h"
#include "ademono/slam/frame.h"
#include "ademono/slam/map_point.h"

namespace ademono {

class KeyFrame {
 public:
  KeyFrame(uint64_t id, const Frame& frame);

  const uint64_t id;
  const uint64_t frame_id;
  const size_t index;
  const double timestamp;
  std::shared_ptr<const FrameFeatures> features;
  Rigid3d cam_from_world;
  std::vector<std::shared_ptr<MapPoint>> map_points;

  // Covisibility: shared map point counts with other keyframes.
  std::map<KeyFrame*, int, KeyFrameIdLess> connections;
  std::vector<KeyFrame*> ordered_connections;  // by weight, descending (ties by id)
  KeyFrame* parent = nullptr;
  std::set<KeyFrame*, KeyFrameIdLess> children;
  Rigid3d cam_from_parent = Rigid3d::Identity();  // set when the keyframe is culled
  // The map's local scale around the keyframe at the moments a pose was stored relative to it
  // (tracking.follow_local_scale): a sample of its points with their depths in its camera then.
  // A pose measured in the map's units of then follows a later change of them (local BA moves a
  // young monocular map by several percent; a loop's Sim(3) rescales it): LocalScaleSince.
  struct ScaleSnapshot {
    uint64_t version = 0;  // Map::StructureVersion() when taken
    std::vector<std::pair<std::weak_ptr<MapPoint>, float>> points;
    double scale_at_cull = 1.0;  // culled: LocalScaleSince(this) at the cull (points dropped)
  };
  std::vector<ScaleSnapshot> scale_snapshots;
  int parent_snapshot = -1;  // culled: the parent's snapshot taken at the cull
  bool bad = false;
  // Part of a map loaded for localisation only: its pose and its map points never change, it is
  // never culled (temporary keyframes may connect to it in the covisibility graph).
  bool frozen = false;
  // Monocular core with a network: the network's error in this view against the triangulated
  // points (local mapping refits it after each local BA that moves the keyframe).
  InverseDepthAffine network_fit;
  // The road under the camera as measured at this keyframe with a known camera height
  // (depth.ground_in_ba): its normal in the camera's frame, the map points on it, and the
  // height they lie below the camera, which local BA holds (a scale observation per keyframe).
  struct Ground {
    Eigen::Vector3d normal_cam = Eigen::Vector3d(0, -1, 0);
    double height = 0.0;
    double sigma = 1.0;               // per point, in the map's units
    bool free_normal = false;         // local BA solves for the normal (depth.ground_free_normal)
    std::vector<uint64_t> point_ids;  // ascending
  };
  std::optional<Ground> ground;

  // Scratch of the tracker and local mapping.
  uint64_t local_map_frame = UINT64_MAX;
  // Tracking's count of a frame's points this keyframe sees (valid while counted_for is the
  // count's stamp): a scratch field, so the count needs no map per frame.
  uint64_t counted_for = UINT64_MAX;
  int counted_points = 0;
  uint64_t ba_local_for = UINT64_MAX;
  uint64_t fuse_target_for = UINT64_MAX;

  const FrameFeatures& F() const { return *features; }
  Eigen::Vector3d CameraCenter() const { return cam_from_world.inverse().translation(); }
  void AddMapPoint(const std::shared_ptr<MapPoint>& point, size_t index) {
    map_points[index] = point;
  }
  void EraseMapPoint(size_t index) { map_points[index].reset(); }
  void EraseMapPoint(const MapPoint* point);
  // A snapshot of the local scale now (the last one when nothing has moved since `version`);
  // its index, -1 for a culled keyframe.
  int SnapshotScale(uint64_t version);
  // The local scale now over snapshot `s`'s: the median of its points' depths now over then,
  // among those still in the map. 1 when unknown (s < 0, too few points left); a culled
  // keyframe's is fixed at its cull.
  double LocalScaleSince(int s) const;
  // Map points observed by at least `min_observations` keyframes.
  int TrackedMapPoints(int min_observations) const;
  // Recomputes the covisibility edges from the map points (ORB-SLAM's UpdateConnections).
  void UpdateConnections();
  std::vector<KeyFrame*> BestCovisibles(size_t n) const;
  void AddConnection(KeyFrame* other, int weight);
  void EraseConnection(KeyFrame* other);
  void SortConnections();
};

// depth.ground_in_ba: the keyframe's road points that a bundle adjustment solves (`point_index`:
// map point id -> the problem's point) held at its ground's height below it, as the problem's
// camera `camera`. Local BA and the global BA after a loop hold the same road.
void AppendGroundDistances(const KeyFrame& keyframe, size_t camera,
                           const std::map<uint64_t, size_t>& point_index,
                           std::vector<BaPlaneDistance>& distances);
// Whether any of `keyframes` (null entries allowed) has a road: only then does a bundle
// adjustment need the point index AppendGroundDistances reads.
bool AnyGround(const std::vector<std::shared_ptr<KeyFrame>>& keyframes);

}  // namespace ademono
