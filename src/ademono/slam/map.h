#pragma once
// The map database: keyframes and map points, owned here by shared_ptr. Culled keyframes move
// to a graveyard so raw KeyFrame* links (observations, spanning tree) never dangle and culled
// keyframes can still resolve the poses of frames that referenced them.
//
// Locking: `mutex` guards every KeyFrame and MapPoint. Tracking holds it for a whole frame;
// local mapping holds it for each step and releases it while Ceres solves a local BA on copies.
// The contract is annotated (core/thread_annotations.h) and checked by tools/thread_safety.sh:
// the map's own members are ADEMONO_GUARDED_BY(mutex), its methods ADEMONO_REQUIRES(mutex), and
// so are the methods of tracking, local mapping, loop closing and map_io that reach them.
// KeyFrame and MapPoint fields are not annotated (they do not know their map); every path to
// them goes through the map, or through functions that require its mutex.

#include <cstdint>
#include <map>
#include <memory>
#include <vector>

#include "ademono/core/thread_annotations.h"
#include "ademono/place/keyframe_database.h"
#include "ademono/slam/keyframe.h"
#include "ademono/slam/map_point.h"

namespace ademono {

class Map {
 public:
  Mutex mutex;

  // Keyframes created and erased here are added to and erased from `database` (place
  // recognition; not owned, may be null). Set before the first keyframe.
  void SetKeyFrameDatabase(KeyFrameDatabase* database) { database_ = database; }
  KeyFrameDatabase* GetKeyFrameDatabase() const { return database_; }

  std::shared_ptr<KeyFrame> CreateKeyFrame(const Frame& frame) ADEMONO_REQUIRES(mutex);
  std::shared_ptr<MapPoint> CreateMapPoint(const Eigen::Vector3d& position, KeyFrame* reference,
                                           uint64_t frame_id) ADEMONO_REQUIRES(mutex);
  void AddMapPoint(const std::shared_ptr<MapPoint>& point) ADEMONO_REQUIRES(mutex) {
    points_[point->id] = point;
  }
  // Loading a saved map (map_io): a keyframe / point with its saved id, and the next ids.
  std::shared_ptr<KeyFrame> RestoreKeyFrame(uint64_t id, const Frame& frame)
      ADEMONO_REQUIRES(mutex);
  std::shared_ptr<MapPoint> RestoreMapPoint(uint64_t id, const Eigen::Vector3d& position,
                                            KeyFrame* reference, uint64_t frame_id)
      ADEMONO_REQUIRES(mutex);
  void SetNextIds(uint64_t next_keyframe_id, uint64_t next_point_id) ADEMONO_REQUIRES(mutex) {
    next_keyframe_id_ = next_keyframe_id;
    next_point_id_ = next_point_id;
  }
  uint64_t NextMapPointId() const ADEMONO_REQUIRES(mutex) { return next_point_id_; }

  // Marks the point bad, removes its observations and drops it from the map.
  void ErasePoint(MapPoint* point) ADEMONO_REQUIRES(mutex);
  // ORB-SLAM's MapPoint::Replace: `old_point`'s observations move to `new_point`.
  void ReplacePoint(MapPoint* old_point, const std::shared_ptr<MapPoint>& new_point)
      ADEMONO_REQUIRES(mutex);
  // ORB-SLAM's KeyFrame::SetBadFlag: removes the keyframe, its observations and edges and
  // re-parents its children in the spanning tree. The first keyframe is never removed.
  void EraseKeyFrame(KeyFrame* keyframe) ADEMONO_REQUIRES(mutex);

  // Scales the world about its origin: point positions, keyframe translations (culled ones
  // too) and keyframe depths (network depth priors) are multiplied by `factor`.
  void Rescale(double factor) ADEMONO_REQUIRES(mutex);
  std::shared_ptr<KeyFrame> GetKeyFrame(uint64_t id) const ADEMONO_REQUIRES(mutex);
  std::shared_ptr<MapPoint> GetMapPoint(uint64_t id) const ADEMONO_REQUIRES(mutex);
  const std::map<uint64_t, std::shared_ptr<KeyFrame>>& KeyFrames() const ADEMONO_REQUIRES(mutex) {
    return keyframes_;
  }
  const std::map<uint64_t, std::shared_ptr<MapPoint>>& MapPoints() const ADEMONO_REQUIRES(mutex) {
    return points_;
  }
  size_t NumKeyFrames() const ADEMONO_REQUIRES(mutex) { return keyframes_.size(); }
  size_t NumMapPoints() const ADEMONO_REQUIRES(mutex) { return points_.size(); }
  uint64_t NextKeyFrameId() const ADEMONO_REQUIRES(mutex) { return next_keyframe_id_; }
  // Loop closing moved keyframes and points: the tracker re-derives its last pose when this
  // count changes.
  void NoteLoopCorrection() ADEMONO_REQUIRES(mutex) {
    ++loop_corrections_;
    ++structure_version_;
  }
  // Counts the changes that move map points (local BA, loop corrections): a keyframe's scale
  // snapshot of one version stands for all of it.
  void NoteStructureChange() ADEMONO_REQUIRES(mutex) { ++structure_version_; }
  uint64_t StructureVersion() const ADEMONO_REQUIRES(mutex) { return structure_version_; }
  uint64_t LoopCorrections() const ADEMONO_REQUIRES(mutex) { return loop_corrections_; }
  // Pose of a (possibly culled) keyframe resolved through the spanning tree: cam_from_world.
  // With `snapshot` (the keyframe's SnapshotScale when `cam_from_keyframe` was measured; -1:
  // rigid), each link's translation follows the local scale's change since.
  static Rigid3d ResolvePose(const KeyFrame* keyframe, const Rigid3d& cam_from_keyframe,
                             int snapshot = -1);

 private:
  std::map<uint64_t, std::shared_ptr<KeyFrame>> keyframes_ ADEMONO_GUARDED_BY(mutex);
  std::map<uint64_t, std::shared_ptr<MapPoint>> points_ ADEMONO_GUARDED_BY(mutex);
  std::vector<std::shared_ptr<KeyFrame>> graveyard_ ADEMONO_GUARDED_BY(mutex);
  uint64_t next_keyframe_id_ ADEMONO_GUARDED_BY(mutex) = 0;
  uint64_t next_point_id_ ADEMONO_GUARDED_BY(mutex) = 0;
  KeyFrameDatabase* database_ = nullptr;  // set once before the first keyframe
  uint64_t loop_corrections_ ADEMONO_GUARDED_BY(mutex) = 0;
  uint64_t structure_version_ ADEMONO_GUARDED_BY(mutex) = 0;
};

}  // namespace ademono
