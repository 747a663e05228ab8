#pragma once
// Tracking for RGB-D input (ORB-SLAM2's Tracking with per-frame depth, no monocular
// initialisation): map initialisation from the first frame with enough depth, constant-velocity
// tracking by projection (window widened once), reference-keyframe tracking by descriptor
// matching as fallback, local-map tracking, the keyframe decision, relocalisation (PnP RANSAC
// against the keyframe database's candidates, then recent keyframes) and a restart from the last
// pose after a long loss.
// Every call runs with the map mutex held by the caller.

#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <vector>

#include "ademono/detect/detection.h"
#include "ademono/slam/frame.h"
#include "ademono/slam/local_mapping.h"
#include "ademono/slam/map.h"
#include "ademono/slam/monocular_initialization.h"
#include "ademono/slam/options.h"

namespace ademono {

enum class TrackingState { kNotInitialized, kOk, kLost };
// "not_initialized" | "ok" | "lost" (summary.json, the Python API).
const char* TrackingStateName(TrackingState state);

// How much a tracked frame's pose rests on: kGood (enough static inliers against the local map),
// kFewInliers (tracking failed its inlier bar but the pose is optimised on what is left, e.g.
// when people fill the view), kMotionModel (nothing left to optimise on: the constant-velocity
// prediction), kDepthOdometry (off the map, the pose optimised on points made of the last frame's
// depths; tracking.depth_odometry). Weak poses (all but kGood) are reported, never made keyframes.
enum class PoseQuality { kGood, kFewInliers, kMotionModel, kDepthOdometry };
// "good" | "few_static_points" | "motion_model" | "depth_odometry" (summary.json per_frame,
// report.html).
const char* PoseQualityName(PoseQuality quality);

// What became of one keypoint of a tracked frame in the pose (for scoring against synthetic
// truth; TrackingOutput::match_state): no map point matched it; it matched one and was a pose
// inlier, or rejected by the pose's robust test; or the geometric test kept its map point out of
// the pose, either still unconfirmed (a new point at its creation prior, no decisive verdict yet)
// or judged moving (motion evidence brought it below the threshold).
enum class MatchState : uint8_t {
  kUnmatched = 0,
  kPoseInlier = 1,
  kPoseOutlier = 2,
  kUnconfirmed = 3,
  kJudgedMoving = 4
};

// What the trajectory needs of each input frame: its pose relative to a keyframe, so that later
// keyframe corrections (local BA, culling) move it along.
struct FrameRecord {
  size_t index = 0;
  double timestamp = 0;
  bool tracked = false;
  KeyFrame* reference = nullptr;  // owned by the map (never freed while the map lives)
  Rigid3d cam_from_reference = Rigid3d::Identity();
  // tracking.interpolate_trajectory: the newest keyframe when the frame was tracked and the
  // next one made after it, each with the frame's pose relative to it then (null until made).
  KeyFrame* previous_keyframe = nullptr;
  Rigid3d cam_from_previous = Rigid3d::Identity();
  KeyFrame* next_keyframe = nullptr;
  Rigid3d cam_from_next = Rigid3d::Identity();
  double depth_scale = 1.0;  // network depth: the factor its depths were corrected by
  // tracking.follow_local_scale: each keyframe's scale snapshot when the pose relative to it was
  // taken (-1: the pose is rigid to the keyframe).
  int reference_snapshot = -1;
  int previous_snapshot = -1;
  int next_snapshot = -1;
};

// A tracked frame's pose in the map as it is now. With both keyframes around it (between a
// keyframe and the next), the two keyframes' poses relative to it blended by time: the frame
// follows what local BA has since learnt about the keyframes on either side, not only about
// its reference. Otherwise it follows its reference keyframe (ORB-SLAM's).
Rigid3d ResolveFramePose(const FrameRecord& record);

struct TrackingOutput {
  bool tracked = false;
  Rigid3d cam_from_world = Rigid3d::Identity();
  std::shared_ptr<KeyFrame> new_keyframe;  // to hand to local mapping (outside the lock)
  int inliers = 0;
  bool relocalised = false;
  bool reinitialised = false;
  int dynamic_points_culled = 0;
  PoseQuality quality = PoseQuality::kGood;
  // Geometric test: matched map points judged moving (not used for the pose) this frame, and
  // map points culled for falling to the floor probability.
  int geometric_dynamic = 0;
  int geometric_culled = 0;
  // Per keypoint of the frame's features (tracked frames; else empty): what the tracking made of
  // it, taken before a new keyframe adds this frame's own points (those were not matched).
  std::vector<MatchState> match_state;
  // The map points a new keyframe made from this frame's unmatched keypoints (index into the
  // features, point): whether they are ever admitted (MapPoint::admitted) tells, at the end of
  // a run, whether those keypoints entered the map. Empty unless the frame became a keyframe.
  std::vector<std::pair<size_t, std::shared_ptr<const MapPoint>>> created_points;
  double depth_scale = 1.0;  // network depth: this frame's scale correction (1 for sensor depth)
  // The relative standard error of the run's metric scale as this frame leaves it (ScaleSigma).
  std::optional<double> scale_sigma;
};

class Tracking {
 public:
  Tracking(Map& map, const LocalMapping& local_mapping, const SystemOptions& options);

  // `in_dynamic_box`: per keypoint of `features`, 1 when it lies in a detector's dynamic box
  // (the geometric test gives the map points made from it the lower static_box_prior); empty:
  // no boxes.
  TrackingOutput Track(std::shared_ptr<const FrameFeatures> features, size_t index,
                       double timestamp, std::vector<uint8_t> in_dynamic_box = {})
      ADEMONO_REQUIRES(map_.mutex);

  // After a loop correction moved the keyframes (Map::LoopCorrections changed): the last frame's
  // pose is re-derived from its reference keyframe. Called at every Track() and by System right
  // after a keyframe was mapped; a no-op otherwise.
  void FollowLoopCorrection() ADEMONO_REQUIRES(map_.mutex);

  TrackingState State() const { return state_; }
  const std::vector<FrameRecord>& Records() const { return records_; }
  // Constant-velocity prediction of the next frame's pose (if tracking is OK).
  std::optional<Rigid3d> PredictNext() const;
  const std::optional<Frame>& LastFrame() const { return last_frame_; }
  int NumLost() const { return num_lost_; }
  int NumRelocalisations() const { return num_relocalisations_; }
  // After a saved map was restored into the (otherwise empty) map: the first frames relocalise
  // in it (global relocalisation through the keyframe database) instead of initialising a new
  // map. A `metric` map keeps its scale (no anchoring to this session's network or road); a map
  // without one (built with --depth none) takes it from them as a new map would, by the same
  // anchor. With `localize_only` the map never changes otherwise: no keyframe, no point, no point
  // statistics.
  void StartInLoadedMap(bool localize_only, bool metric) ADEMONO_REQUIRES(map_.mutex);
  // A loaded map without metric scale and a depth sensor (BackEnd::Track tracks the sensor's
  // frames without their depths until then): the ratio of the sensor's depths to the map's over
  // the map points of the frame just tracked, the median of at least kMinSensorScaleSamples, or
  // nothing. `with_depth`: that frame's features with the sensor's depths.
  std::optional<double> SensorToMapScale(const FrameFeatures& with_depth) const
      ADEMONO_REQUIRES(map_.mutex);
  static constexpr size_t kMinSensorScaleSamples = 30;
  // Multiplies the world (map, trajectory, motion, the frame just tracked) by `factor`, and holds
  // the loaded map's scale from then on.
  void GiveLoadedMapScale(double factor) ADEMONO_REQUIRES(map_.mutex);
  bool LocalizeOnly() const { return localize_only_; }
  // depth.camera_height: the camera's height above the ground plane, measured at initialisation
  // and at every keyframe, in the map's current units (the map is rescaled whenever their
  // median strays from camera_height by more than depth.anchor_tolerance).
  const std::vector<double>& GroundHeights() const { return ground_heights_; }
  // The input frame index of each GroundHeights() entry.
  const std::vector<size_t>& GroundHeightFrames() const { return ground_height_frames_; }
  // For the analysis (core/thread_annotations.h): the caller holds the map's mutex under another
  // name (its own reference to the map). Checked at run time.
  void AssertMapHeld() const ADEMONO_ASSERT_CAPABILITY(map_.mutex) { map_.mutex.AssertHeld(); }

 private:
  bool Initialise(Frame& frame, const Rigid3d& cam_from_world) ADEMONO_REQUIRES(map_.mutex);
  // A restart in the same map at `cam_from_world` from the frame's depths (after a long loss, or
  // a re-seed): its first map's keyframe becomes `out`'s new keyframe. False, and the frame
  // untouched, when it has too few depths.
  bool RestartAt(Frame& frame, const Rigid3d& cam_from_world, TrackingOutput& out)
      ADEMONO_REQUIRES(map_.mutex);
  // Monocular without depth: the two-view initialisation (MonocularInitialization).
  bool InitialiseMonocular(Frame& frame) ADEMONO_REQUIRES(map_.mutex);
  // Whether a new keyframe makes map points from its own depths: always with sensor-like depth;
  // in the monocular core never (its points come from triangulation in local mapping).
  bool KeyFramePointsFromDepth() const { return !options_.tracking.monocular; }
  bool TrackWithMotionModel(Frame& frame) ADEMONO_REQUIRES(map_.mutex);
  // The mean per-frame motion over the last good frames (recent_good_); nullopt with fewer than 2.
  std::optional<Rigid3d> MeanRecentVelocity() const;
  // Projection search of `last`'s points from the constant-velocity prediction (radius, then
  // twice it); true with at least tracking.min_motion_matches matches.
  bool MatchLastFrame(Frame& frame, const Frame& last) const ADEMONO_REQUIRES(map_.mutex);
  // Off the map: the pose optimised on the last frame's depths made points (a copy; nothing
  // reaches the map). Its inliers, 0 (pose untouched) below kMinOdometryPoints.
  int TrackLastFrameDepth(Frame& frame) ADEMONO_REQUIRES(map_.mutex);
  bool TrackReferenceKeyFrame(Frame& frame) ADEMONO_REQUIRES(map_.mutex);
  bool TrackLocalMap(Frame& frame) ADEMONO_REQUIRES(map_.mutex);
  bool Relocalise(Frame& frame) ADEMONO_REQUIRES(map_.mutex);
  bool NeedNewKeyFrame(const Frame& frame) const ADEMONO_REQUIRES(map_.mutex);
  // Monocular: the frame is far enough from its reference keyframe for new points to be
  // triangulated: mapping.triangulation_min_baseline_ratio of its median scene depth, and with
  // tracking.keyframe_parallax_baseline the baseline of mapping.triangulation_min_parallax_deg.
  bool HasTriangulationBaseline(const Frame& frame) const ADEMONO_REQUIRES(map_.mutex);
  // `created`: the points made from the frame's own depth (TrackingOutput::created_points).
  std::shared_ptr<KeyFrame> CreateNewKeyFrame(
      Frame& frame, std::vector<std::pair<size_t, std::shared_ptr<const MapPoint>>>* created)
      ADEMONO_REQUIRES(map_.mutex);
  // Motion-only pose optimisation on the matched points with static probability >= min_static
  // (< 0: the geometric test's threshold); `map_points_only`: without localisation-only mode's
  // odometry points.
  int OptimizeFramePose(Frame& frame, double min_static = -1, bool map_points_only = false)
      ADEMONO_REQUIRES(map_.mutex);
  int DiscardOutliers(Frame& frame) ADEMONO_REQUIRES(map_.mutex);
  void UpdateLocalMap(Frame& frame) ADEMONO_REQUIRES(map_.mutex);
  int CountDepthPoints(const Frame& frame) const;
  // Geometric test: whether a map point's static probability lets it into the pose.
  bool UsableForPose(const MapPoint& point) const;
  // Per keypoint of the frame: what tracking made of it (TrackingOutput::match_state).
  std::vector<MatchState> MatchStates(const Frame& frame) const ADEMONO_REQUIRES(map_.mutex);
  // Judges every matched map point at the frame's pose, updates its static probability, marks
  // the ones below the threshold as outliers and culls the ones at the floor. Returns how many
  // are below the threshold.
  int JudgeStaticness(Frame& frame) ADEMONO_REQUIRES(map_.mutex);
  // The geometric test's verdict on `point` seen as keypoint i of `frame`, at the frame's pose.
  StaticEvidence JudgeObservationOf(const Frame& frame, const MapPoint& point, size_t i) const
      ADEMONO_REQUIRES(map_.mutex);
  // New keyframe points judged in the frame before the keyframe (static_confirm_in_last_frame).
  void JudgeInLastFrame(const std::vector<MapPoint*>& points) ADEMONO_REQUIRES(map_.mutex);
  // A map point from keypoint i's depth, observed by `keyframe` (made from `frame`).
  void CreatePointFromDepth(Frame& frame, KeyFrame& keyframe, const Rigid3d& world_from_cam,
                            size_t i, double static_probability) ADEMONO_REQUIRES(map_.mutex);
  // Network depth: rescales the frame's depths to agree with the map points it tracks (robust
  // median of ratios); `inliers_only` after the pose is final.
  void CorrectDepthScale(Frame& frame, bool inliers_only) ADEMONO_REQUIRES(map_.mutex);
  // The depths of `frame`'s map points in its camera (map units) beside `features`' depths of the
  // same keypoints, where both are known (`inliers_only`: the frame's outliers left out).
  void DepthPairs(const Frame& frame, const FrameFeatures& features, bool inliers_only,
                  std::vector<double>* map_depths, std::vector<double>* feature_depths) const
      ADEMONO_REQUIRES(map_.mutex);
  // Keeps the map at the network's long-run mean scale, or with depth.camera_height at the scale
  // that puts the camera camera_height above the ground (rescales the world when it drifted).
  void AnchorScale(Frame& frame) ADEMONO_REQUIRES(map_.mutex);
  // The relative standard error of the metric scale the run holds now. Ground scale: the robust
  // spread of the keyframes' camera heights over sqrt(their count). Network depth (anchored to
  // its long-run mean): the spread of the frames' log corrections over sqrt(the keyframes), the
  // map's independent views (the frames between two keyframes see one view, and the network errs
  // alike on it). Neither holds the source's own bias (a network reading a room short, a wrong
  // rig height): it says how well the run pinned its scale source down, not how right that is.
  std::optional<double> ScaleSigma() ADEMONO_REQUIRES(map_.mutex);
  // depth.camera_height: the camera's height above the ground plane fitted to the frame's
  // keypoints below the horizon, off dynamic boxes and in the corridor ahead: on the map points
  // they track (`map_points`, map units: the map's own scale, whatever biased it) or on their
  // own depths (the source's units, before any correction; for the first map).
  // With `ground` (map points only), also the plane's normal and the ids of the points on it.
  std::optional<double> MeasureGround(const Frame& frame, bool map_points,
                                      KeyFrame::Ground* ground = nullptr) const
      ADEMONO_REQUIRES(map_.mutex);
  // Whether two of the point's views are at least depth.ground_min_parallax_deg apart.
  bool Triangulated(const MapPoint& point) const ADEMONO_REQUIRES(map_.mutex);
  // Multiplies every length of the map and of the tracker's state by `factor`.
  void RescaleWorld(Frame& frame, double factor) ADEMONO_REQUIRES(map_.mutex);
  // No motion to predict from (a new map, a loss): the velocity and the recent good frames go.
  void ForgetMotion();

  Map& map_;
  const LocalMapping& local_mapping_;
  SystemOptions options_;
  TrackingState state_ = TrackingState::kNotInitialized;
  uint64_t next_frame_id_ = 0;
  uint64_t loop_corrections_seen_ = 0;
  std::optional<Frame> last_frame_;
  // The last good frames' (id, cam_from_world), oldest first, for MeanRecentVelocity.
  std::deque<std::pair<uint64_t, Rigid3d>> recent_good_;
  std::optional<Rigid3d> velocity_;        // current_from_last
  std::optional<Rigid3d> last_good_pose_;  // cam_from_world of the last tracked frame
  KeyFrame* reference_keyframe_ = nullptr;
  uint64_t last_keyframe_frame_id_ = 0;
  uint64_t last_reloc_frame_id_ = 0;
  int matches_inliers_ = 0;
  int lost_streak_ = 0;
  int weak_streak_ = 0;        // consecutive weak poses (PoseQuality)
  int odometry_streak_ = 0;    // consecutive poses on the last frame's depths (kDepthOdometry)
  int judged_dynamic_ = 0;     // JudgeStaticness of the current frame
  std::vector<uint8_t> in_dynamic_box_;  // the current frame's (Track's argument)
  int geometric_culled_ = 0;
  int num_lost_ = 0;
  int num_relocalisations_ = 0;
  double last_depth_scale_ = 1.0;  // the last tracked frame's network scale correction
  double log_scale_sum_ = 0.0;     // sum of log(depth_scale) over tracked frames
  int log_scale_count_ = 0;
  double log_scale_m2_ = 0.0;  // their sum of squared deviations from the mean (Welford)
  // ScaleSigma's robust spread of log ground_heights_, and how many heights it was read from.
  double ground_log_spread_ = 0.0;
  size_t ground_spread_samples_ = 0;
  std::vector<double> ground_heights_;  // depth.camera_height: GroundHeights()
  std::vector<size_t> ground_height_frames_;
  bool map_loaded_ = false;
  bool loaded_map_metric_ = false;
  // A loaded metric map holds the scale: this run's network or road does not move it.
  bool ScaleHeldByLoadedMap() const { return map_loaded_ && loaded_map_metric_; }
  bool localize_only_ = false;
  // Localisation only without a temporary map (tracking.temporary_map false): frame-to-frame
  // odometry where the loaded map is out of view.
  bool odometry_localisation_ = false;
  // Localisation-only mode (ORB-SLAM2's mbVO): the last frame tracked mostly on temporary
  // visual-odometry points (its own depth readings, never added to the map) because the map was
  // out of view; each such frame also tries relocalisation to get back onto the map.
  bool visual_odometry_ = false;
  // Localisation-only mode: temporary points from the frame's own depth for the keypoints that
  // matched no map point, so the next frame can track by odometry where the map does not reach.
  void AddVisualOdometryPoints(Frame& frame);
  std::vector<KeyFrame*> local_keyframes_;
  std::vector<std::shared_ptr<MapPoint>> local_points_;
  // tracking.interpolate_trajectory: `record` (about to be pushed) is anchored to the newest
  // keyframe, and the records since the previous keyframe to `new_keyframe` when one was made.
  void AnchorBetweenKeyFrames(FrameRecord& record, const Rigid3d& cam_from_world,
                              KeyFrame* new_keyframe) ADEMONO_REQUIRES(map_.mutex);
  std::vector<FrameRecord> records_;
  // The newest keyframe tracking made and the index of its frame's record
  // (tracking.interpolate_trajectory).
  KeyFrame* newest_keyframe_ = nullptr;
  size_t newest_keyframe_record_ = 0;
  MonocularInitialization monocular_initialization_;
};

}  // namespace ademono
