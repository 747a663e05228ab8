#include "ademono/slam/tracking.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <stdexcept>
#include <opencv2/calib3d.hpp>

#include "ademono/core/cv_geometry.h"
#include "ademono/core/statistics.h"
#include "ademono/io/timed_poses.h"
#include "ademono/optimize/depth_scale.h"
#include "ademono/optimize/ground_plane.h"
#include "ademono/optimize/pose_optimizer.h"
#include "ademono/slam/keyframe.h"
#include "ademono/slam/matcher.h"
#include "ademono/slam/motion_model.h"
#include "ademono/slam/static_probability.h"

namespace ademono {
namespace {

// Static probability of a point with a history: about four agreeing frames more than against.
constexpr double kTrustedStaticProbability = 0.8;
// Localisation only, and depth odometry off the map: the points a frame's odometry pose needs.
constexpr int kMinOdometryPoints = 20;
// Good frames whose span gives the mean velocity into a gap (five frames of motion).
constexpr size_t kMeanVelocityFrames = 6;

// Matched points (map or odometry) that are not outliers.
int CountInliers(const Frame& frame) {
  int n = 0;
  for (size_t i = 0; i < frame.map_points.size(); ++i)
    n += frame.map_points[i] && !frame.outlier[i];
  return n;
}

}  // namespace

const char* TrackingStateName(TrackingState state) {
  switch (state) {
    case TrackingState::kNotInitialized:
      return "not_initialized";
    case TrackingState::kOk:
      return "ok";
    case TrackingState::kLost:
      return "lost";
  }
  throw std::logic_error("TrackingStateName: unknown state");
}

const char* PoseQualityName(PoseQuality quality) {
  switch (quality) {
    case PoseQuality::kGood:
      return "good";
    case PoseQuality::kFewInliers:
      return "few_static_points";
    case PoseQuality::kMotionModel:
      return "motion_model";
    case PoseQuality::kDepthOdometry:
      return "depth_odometry";
  }
  throw std::logic_error("PoseQualityName: unknown quality");
}

Tracking::Tracking(Map& map, const LocalMapping& local_mapping, const SystemOptions& options)
    : map_(map),
      local_mapping_(local_mapping),
      options_(options),
      monocular_initialization_(options) {}

void Tracking::StartInLoadedMap(bool localize_only, bool metric) {
  map_loaded_ = true;
  loaded_map_metric_ = metric;
  localize_only_ = localize_only;
  odometry_localisation_ = localize_only && !options_.tracking.temporary_map;
  state_ = TrackingState::kLost;
  // Frame ids continue after the loaded map's (recent-point and keyframe-spacing rules compare
  // them).
  uint64_t last = 0;
  for (const auto& [id, kf] : map_.KeyFrames()) last = std::max(last, kf->frame_id);
  for (const auto& [id, p] : map_.MapPoints()) last = std::max(last, p->first_frame_id);
  next_frame_id_ = last + 1;
  last_keyframe_frame_id_ = last;
  last_reloc_frame_id_ = last;
}

std::optional<Rigid3d> Tracking::PredictNext() const {
  if (state_ != TrackingState::kOk || !last_frame_ || !last_frame_->cam_from_world || !velocity_) {
    return std::nullopt;
  }
  return *velocity_ * *last_frame_->cam_from_world;
}

std::optional<Rigid3d> Tracking::MeanRecentVelocity() const {
  if (recent_good_.size() < 2) return std::nullopt;
  const auto& [old_id, cam_old_from_world] = recent_good_.front();
  const auto& [new_id, cam_new_from_world] = recent_good_.back();
  return MeanFrameMotion(cam_old_from_world, cam_new_from_world,
                         static_cast<double>(new_id - old_id));
}

void Tracking::ForgetMotion() {
  velocity_.reset();
  recent_good_.clear();
}

int Tracking::CountDepthPoints(const Frame& frame) const {
  int n = 0;
  for (float d : frame.F().depth) n += d > 0 ? 1 : 0;
  return n;
}

void Tracking::FollowLoopCorrection() {
  if (map_.LoopCorrections() == loop_corrections_seen_) return;
  loop_corrections_seen_ = map_.LoopCorrections();
  if (records_.empty() || !records_.back().tracked || records_.back().reference == nullptr) return;
  // The velocity is relative and stays; absolute poses follow the reference keyframe.
  recent_good_.clear();
  const FrameRecord& last = records_.back();
  const Rigid3d corrected =
      Map::ResolvePose(last.reference, last.cam_from_reference, last.reference_snapshot);
  if (last_frame_ && last_frame_->cam_from_world) last_frame_->cam_from_world = corrected;
  if (last_good_pose_) last_good_pose_ = corrected;
}

TrackingOutput Tracking::Track(std::shared_ptr<const FrameFeatures> features, size_t index,
                               double timestamp, std::vector<uint8_t> in_dynamic_box) {
  FollowLoopCorrection();
  in_dynamic_box_ = std::move(in_dynamic_box);
  // Network depth starts from the last frame's correction (its scale wanders slowly); with a
  // known camera height every frame starts at the ground's scale (RescaleWorld keeps
  // last_depth_scale_ at it).
  if ((features->DepthIsPrior() || options_.depth.GroundScale()) && last_depth_scale_ != 1.0) {
    features = RescaleDepth(*features, static_cast<float>(last_depth_scale_));
  }
  Frame frame(next_frame_id_++, index, timestamp, std::move(features));
  TrackingOutput out;
  bool ok = false;
  bool weak = false;
  judged_dynamic_ = 0;
  geometric_culled_ = 0;

  if (state_ == TrackingState::kNotInitialized) {
    // The monocular core measures the ground on the map's own (triangulated) points only: a
    // network's reading of the road is distorted (PyDNet's rises ahead, docs/kitti.md).
    if (options_.depth.GroundScale() && ground_heights_.empty() && !options_.tracking.monocular) {
      // The first map is made at the ground's scale, measured on the frame's own depths
      // (nothing to rescale yet).
      if (const std::optional<double> height = MeasureGround(frame, false)) {
        const double factor = options_.depth.camera_height / *height;
        frame.features = RescaleDepth(frame.F(), static_cast<float>(factor));
        last_depth_scale_ = frame.F().depth_scale;
        ground_heights_.push_back(*height * factor);
        ground_height_frames_.push_back(index);
      }
    }
    if (options_.tracking.monocular &&
        CountDepthPoints(frame) < options_.tracking.min_init_points) {
      ok = InitialiseMonocular(frame);
    } else {
      ok = Initialise(frame, Rigid3d::Identity());
    }
    if (ok) out.new_keyframe = map_.GetKeyFrame(frame.reference_keyframe->id);
  } else {
    // Fusion in local mapping may have replaced points the last frame still holds.
    if (last_frame_) {
      for (auto& p : last_frame_->map_points) {
        if (p && p->replaced_by) p = MapPoint::Resolve(p);
        if (p && p->bad) p.reset();
      }
    }
    bool by_motion = false;
    // Localisation only: the untouched frame, for the odometry fallback below.
    std::optional<Frame> pristine;
    if (odometry_localisation_ && state_ == TrackingState::kOk && velocity_) pristine = frame;
    if (state_ == TrackingState::kOk && odometry_localisation_ && visual_odometry_) {
      // Off the map: odometry on the last frame's temporary points, unless relocalisation
      // (tried on a copy) finds the map again.
      Frame relocalised = frame;
      if (Relocalise(relocalised)) {
        frame = std::move(relocalised);
        ok = out.relocalised = true;
      } else if (velocity_) {
        ok = by_motion = TrackWithMotionModel(frame);
      }
    } else if (state_ == TrackingState::kOk) {
      if (velocity_ && frame.id >= last_reloc_frame_id_ + 2) {
        ok = by_motion = TrackWithMotionModel(frame);
        if (!ok) ok = TrackReferenceKeyFrame(frame);
      } else {
        ok = TrackReferenceKeyFrame(frame);
      }
    } else {
      ok = Relocalise(frame);
      out.relocalised = ok;
    }
    frame.reference_keyframe = reference_keyframe_;
    if (odometry_localisation_) {
      // Off the map (the motion model found fewer than 10 map points) the odometry pose stands:
      // searching the local map there and mixing the few map points found into the pose was
      // measured worse (seq-a 300-599, FastDepth: ATE 0.136 m instead of 0.051 m; sensor depth
      // 0.039 instead of 0.029), their matches being few and often wrong.
      if (ok && !(by_motion && visual_odometry_)) {
        std::optional<Frame> odometry;
        if (by_motion) odometry = frame;
        if (TrackLocalMap(frame)) {
          visual_odometry_ = false;
        } else if (odometry) {
          // Too few map points to be back on the map: odometry, on the mixed pose when it
          // still rests on enough points, else on the motion model's.
          if (CountInliers(frame) < kMinOdometryPoints) frame = std::move(*odometry);
          ok = visual_odometry_ = true;
        } else {
          ok = false;
        }
      }
      if (!ok && pristine && !by_motion) {
        // E.g. just after a relocalisation, the local map was too thin: odometry from the last
        // frame rather than a lost frame.
        frame = std::move(*pristine);
        ok = TrackWithMotionModel(frame);
        if (ok) visual_odometry_ = true;
        frame.reference_keyframe = reference_keyframe_;
      }
    } else {
      // Crowds: when neither the motion model nor the reference keyframe found enough matches, the
      // predicted pose can still find the static points left in the local map.
      std::optional<Rigid3d> predicted;
      if (state_ == TrackingState::kOk && options_.tracking.weak_pose_max_frames > 0)
        predicted = PredictNext();
      bool coarse = ok;
      if (!ok && predicted) {
        std::fill(frame.map_points.begin(), frame.map_points.end(), nullptr);
        frame.cam_from_world = *predicted;
        coarse = true;
      }
      if (coarse) ok = TrackLocalMap(frame);
      // Degrade instead of dropping the frame (a short gap in the crowd, not a loss).
      if (!ok && predicted && weak_streak_ < options_.tracking.weak_pose_max_frames) {
        ok = weak = true;
        if (weak_streak_ == 0) {
          // Into a gap: the motion of the last good frames on average, not the last frame's
          // step, which a pose on the crowd's last few points can get centimetres wrong.
          if (const std::optional<Rigid3d> mean = MeanRecentVelocity()) {
            velocity_ = *mean;
            predicted = PredictNext();
          }
        }
        const bool on_map =
            frame.cam_from_world && matches_inliers_ >= options_.tracking.weak_pose_min_inliers;
        // Off the map: measured on the last frame's depths rather than extrapolated.
        const int odometry_inliers = on_map ? 0 : TrackLastFrameDepth(frame);
        if (on_map) {
          out.quality = PoseQuality::kFewInliers;
        } else if (odometry_inliers > 0) {
          matches_inliers_ = odometry_inliers;
          out.quality = PoseQuality::kDepthOdometry;
        } else {
          out.quality = PoseQuality::kMotionModel;
          frame.cam_from_world = *predicted;
          std::fill(frame.map_points.begin(), frame.map_points.end(), nullptr);
          matches_inliers_ = 0;
        }
      }
    }

    // A diverged optimisation is a lost frame, never a pose.
    if (ok && (!frame.cam_from_world || !frame.cam_from_world->matrix().allFinite())) ok = false;
    if (ok) {
      if (out.quality == PoseQuality::kMotionModel ||
          (weak && !options_.tracking.weak_pose_sets_velocity)) {
        // velocity_ stays: the prediction is all this frame has, or (network depth) a pose on a
        // few points must not teach the motion model a jump that the next weak frames repeat.
      } else if (last_frame_ && last_frame_->cam_from_world && state_ == TrackingState::kOk) {
        velocity_ = *frame.cam_from_world * last_frame_->cam_from_world->inverse();
      } else {
        velocity_.reset();
      }
      state_ = TrackingState::kOk;
      lost_streak_ = 0;
      weak_streak_ = weak ? weak_streak_ + 1 : 0;
      odometry_streak_ = out.quality == PoseQuality::kDepthOdometry ? odometry_streak_ + 1 : 0;
      if (out.quality != PoseQuality::kMotionModel) CorrectDepthScale(frame, true);
      if (!weak) {
        recent_good_.emplace_back(frame.id, *frame.cam_from_world);
        if (recent_good_.size() > kMeanVelocityFrames) recent_good_.pop_front();
      }
      out.match_state = MatchStates(frame);
      // A loaded map without metric scale is anchored at every frame, not only at keyframes: a
      // run may make none (localisation by odometry, or a stretch the map already covers).
      if (map_loaded_ && !loaded_map_metric_ && !weak) AnchorScale(frame);
      // Localisation only with a temporary map: keyframes too (local mapping keeps the loaded
      // ones fixed; they are never saved).
      if (!odometry_localisation_ && !weak && NeedNewKeyFrame(frame)) {
        std::optional<KeyFrame::Ground> ground;
        if (options_.depth.GroundScale() && !ScaleHeldByLoadedMap()) {
          KeyFrame::Ground measured;
          if (const std::optional<double> height = MeasureGround(frame, true, &measured)) {
            ground_heights_.push_back(*height);
            ground_height_frames_.push_back(index);
            if (options_.depth.ground_in_ba &&
                static_cast<int>(measured.point_ids.size()) >= options_.depth.ground_min_inliers)
              ground = measured;
          }
        }
        AnchorScale(frame);
        out.new_keyframe = CreateNewKeyFrame(frame, &out.created_points);
        if (ground) {
          // The rig's height, in the map's units once AnchorScale made them metres.
          ground->height = options_.depth.camera_height;
          ground->sigma = options_.depth.ground_point_sigma * options_.depth.camera_height;
          ground->free_normal = options_.depth.ground_free_normal;
          out.new_keyframe->ground = std::move(ground);
        }
      }
      if (options_.tracking.reseed_after_odometry_frames > 0 &&
          odometry_streak_ >= options_.tracking.reseed_after_odometry_frames &&
          matches_inliers_ >= options_.tracking.min_inliers_after_reloc) {
        const Rigid3d cam_from_world = *frame.cam_from_world;
        if (RestartAt(frame, cam_from_world, out)) weak_streak_ = odometry_streak_ = 0;
      }
      // Outliers do not carry over to the next frame's motion-model search.
      for (size_t i = 0; i < frame.map_points.size(); ++i) {
        if (frame.map_points[i] && frame.outlier[i]) frame.map_points[i].reset();
      }
      if (odometry_localisation_) AddVisualOdometryPoints(frame);
    } else {
      state_ = TrackingState::kLost;
      ForgetMotion();
      // The frames before a loss are not blended with whatever keyframe comes after it (a new
      // start, or a relocalisation elsewhere): they keep their reference keyframe.
      newest_keyframe_ = nullptr;
      weak_streak_ = odometry_streak_ = 0;
      ++lost_streak_;
      // After a long loss, restart from the last known pose in the same map rather than
      // dropping every following frame (drift instead of a gap).
      if (!odometry_localisation_ && lost_streak_ > options_.tracking.reinit_after_lost_frames &&
          last_good_pose_)
        ok = RestartAt(frame, *last_good_pose_, out);
    }
  }

  FrameRecord record;
  record.index = index;
  record.timestamp = timestamp;
  record.tracked = ok;
  if (ok) {
    if (out.relocalised) ++num_relocalisations_;
    last_good_pose_ = *frame.cam_from_world;
    record.reference = frame.reference_keyframe;
    record.cam_from_reference =
        *frame.cam_from_world * frame.reference_keyframe->cam_from_world.inverse();
    if (options_.tracking.follow_local_scale)
      record.reference_snapshot = frame.reference_keyframe->SnapshotScale(map_.StructureVersion());
    out.tracked = true;
    out.cam_from_world = *frame.cam_from_world;
    out.inliers = matches_inliers_;
    out.geometric_dynamic = judged_dynamic_;
    out.geometric_culled = geometric_culled_;
    out.depth_scale = record.depth_scale = frame.F().depth_scale;
    if (frame.F().DepthIsPrior()) {
      last_depth_scale_ = frame.F().depth_scale;
      const double x = std::log(last_depth_scale_);
      const double mean_before = log_scale_count_ > 0 ? log_scale_sum_ / log_scale_count_ : 0.0;
      log_scale_sum_ += x;
      ++log_scale_count_;
      log_scale_m2_ += (x - mean_before) * (x - log_scale_sum_ / log_scale_count_);
    }
    out.scale_sigma = ScaleSigma();
  } else if (state_ != TrackingState::kNotInitialized) {
    ++num_lost_;
  }
  if (ok && options_.tracking.interpolate_trajectory && !localize_only_) {
    AnchorBetweenKeyFrames(record, *frame.cam_from_world, out.new_keyframe.get());
  }
  records_.push_back(record);
  if (ok) {
    last_frame_ = std::move(frame);
  } else if (state_ != TrackingState::kNotInitialized) {
    last_frame_.reset();
  }
  return out;
}

void Tracking::CreatePointFromDepth(Frame& frame, KeyFrame& keyframe,
                                    const Rigid3d& world_from_cam, size_t i,
                                    double static_probability) {
  auto point = map_.CreateMapPoint(world_from_cam * frame.F().UnprojectCamera(i), &keyframe,
                                   frame.id);
  if (options_.tracking.static_test) point->static_probability = static_probability;
  point->admitted = UsableForPose(*point);
  // The monocular core keeps a depth-made point's depth only as a prior (local mapping).
  point->depth_prior = options_.tracking.monocular;
  point->AddObservation(&keyframe, i);
  keyframe.AddMapPoint(point, i);
  point->ComputeDistinctiveDescriptor();
  point->UpdateNormalAndDepth();
  frame.map_points[i] = point;
}

bool Tracking::Initialise(Frame& frame, const Rigid3d& cam_from_world) {
  const int with_depth = CountDepthPoints(frame);
  if (with_depth < options_.tracking.min_init_points) return false;
  frame.cam_from_world = cam_from_world;
  std::shared_ptr<KeyFrame> kf = map_.CreateKeyFrame(frame);
  const Rigid3d world_from_cam = cam_from_world.inverse();
  const FrameFeatures& f = frame.F();
  auto boxed = [&](size_t i) { return i < in_dynamic_box_.size() && in_dynamic_box_[i]; };
  // The first map has nothing to be judged against: usable from the start. With
  // tracking.first_map_box_prior, points inside a detector's dynamic box start at the box prior,
  // as a keyframe's new points do (a walker in the first frame would otherwise pose the next
  // frames until the test caught up), when the rest can pose a frame on their own: at least
  // min_inliers_after_reloc, what the tracker asks of a pose found with no prior. A view the
  // boxes fill needs their points to track at all.
  int unboxed = 0;
  for (size_t i = 0; i < f.Size(); ++i) unboxed += f.depth[i] > 0 && !boxed(i) ? 1 : 0;
  const bool distrust_boxes = options_.tracking.first_map_box_prior &&
                              unboxed >= options_.tracking.min_inliers_after_reloc;
  spdlog::debug("first map: {} points with depth, {} outside dynamic boxes{}", with_depth, unboxed,
                distrust_boxes ? "" : " (boxes trusted)");
  for (size_t i = 0; i < f.Size(); ++i) {
    if (f.depth[i] <= 0) continue;
    // Without the geometric test nothing would ever judge such a point: it is left out.
    if (distrust_boxes && boxed(i) && !options_.tracking.static_test) continue;
    CreatePointFromDepth(frame, *kf, world_from_cam, i,
                         distrust_boxes && boxed(i)
                             ? options_.tracking.static_params.box_prior
                             : std::max(options_.tracking.static_params.prior,
                                        options_.tracking.static_params.threshold));
  }
  frame.reference_keyframe = kf.get();
  reference_keyframe_ = kf.get();
  last_keyframe_frame_id_ = frame.id;
  local_keyframes_ = {kf.get()};
  local_points_.clear();
  for (const auto& p : kf->map_points) {
    if (p) local_points_.push_back(p);
  }
  ForgetMotion();
  state_ = TrackingState::kOk;
  matches_inliers_ = static_cast<int>(local_points_.size());
  return true;
}

bool Tracking::RestartAt(Frame& frame, const Rigid3d& cam_from_world, TrackingOutput& out) {
  if (CountDepthPoints(frame) < options_.tracking.min_init_points) return false;
  frame.map_points.assign(frame.F().Size(), nullptr);
  if (!Initialise(frame, cam_from_world)) return false;
  // The flags of the failed or replaced tracking would drop the new points from the next
  // frame's search (Matcher::SearchByProjection skips a last-frame outlier).
  frame.outlier.assign(frame.F().Size(), false);
  out.reinitialised = true;
  out.new_keyframe = map_.GetKeyFrame(frame.reference_keyframe->id);
  return true;
}

bool Tracking::InitialiseMonocular(Frame& frame) {
  const std::optional<MonocularInitialization::Keyframes> keyframes =
      monocular_initialization_.Add(frame, map_);
  if (!keyframes) return false;
  frame.reference_keyframe = keyframes->second.get();
  reference_keyframe_ = keyframes->second.get();
  last_keyframe_frame_id_ = frame.id;
  local_keyframes_ = {keyframes->first.get(), keyframes->second.get()};
  local_points_.clear();
  for (const auto& p : keyframes->second->map_points) {
    if (p) local_points_.push_back(p);
  }
  ForgetMotion();
  state_ = TrackingState::kOk;
  matches_inliers_ = static_cast<int>(local_points_.size());
  return true;
}

void Tracking::CorrectDepthScale(Frame& frame, bool inliers_only) {
  if (!frame.F().DepthIsPrior() || !options_.depth.scale_correction || !frame.cam_from_world) {
    return;
  }
  std::vector<double> map_depths, frame_depths;
  DepthPairs(frame, frame.F(), inliers_only, &map_depths, &frame_depths);
  DepthScaleOptions options;
  options.min_points = options_.depth.scale_min_points;
  const DepthScaleEstimate estimate = EstimateDepthScale(map_depths, frame_depths, options);
  if (!estimate.valid) return;
  frame.features = RescaleDepth(frame.F(), static_cast<float>(estimate.scale));
}

void Tracking::DepthPairs(const Frame& frame, const FrameFeatures& features, bool inliers_only,
                          std::vector<double>* map_depths,
                          std::vector<double>* feature_depths) const {
  for (size_t i = 0; i < frame.map_points.size() && i < features.depth.size(); ++i) {
    const auto& p = frame.map_points[i];
    if (!p || p->bad || !UsableForPose(*p) || !(features.depth[i] > 0) ||
        (inliers_only && frame.outlier[i]))
      continue;
    map_depths->push_back((*frame.cam_from_world * p->position).z());
    feature_depths->push_back(features.depth[i]);
  }
}

void Tracking::AnchorScale(Frame& frame) {
  // A loaded metric map's scale is the anchor (this session's network may read differently).
  if (!local_mapping_.Idle() || ScaleHeldByLoadedMap()) return;
  if (options_.depth.GroundScale()) {
    // The camera's height above the ground as the map has it, over the keyframes so far.
    if (ground_heights_.empty()) return;
    const double factor = options_.depth.camera_height / Median(ground_heights_);
    if (std::abs(std::log(factor)) > options_.depth.ground_tolerance) RescaleWorld(frame, factor);
    return;
  }
  if (!frame.F().DepthIsPrior() || !options_.depth.anchor_scale || log_scale_count_ == 0) return;
  // This frame counts too (it is added to the sum after tracking).
  const double mean = (log_scale_sum_ + std::log(frame.F().depth_scale)) / (log_scale_count_ + 1);
  if (std::abs(mean) <= options_.depth.anchor_tolerance) return;
  RescaleWorld(frame, std::exp(-mean));
}

std::optional<double> Tracking::ScaleSigma() {
  // The loaded map's scale: nothing this run estimated.
  if (ScaleHeldByLoadedMap()) return std::nullopt;
  if (options_.depth.GroundScale()) {
    if (ground_heights_.size() < 3) return std::nullopt;
    if (ground_spread_samples_ != ground_heights_.size()) {
      // A rescale multiplies every height alike: the spread of their logs stays.
      std::vector<double> logs;
      for (double h : ground_heights_) logs.push_back(std::log(h));
      ground_log_spread_ = RobustSpread(logs, Median(logs));
      ground_spread_samples_ = ground_heights_.size();
    }
    return ground_log_spread_ / std::sqrt(static_cast<double>(ground_heights_.size()));
  }
  if (!options_.depth.IsPrior() || !options_.depth.anchor_scale || log_scale_count_ < 2)
    return std::nullopt;
  const double spread = std::sqrt(log_scale_m2_ / (log_scale_count_ - 1));
  const size_t views =
      std::clamp<size_t>(map_.NumKeyFrames(), 1, static_cast<size_t>(log_scale_count_));
  return spread / std::sqrt(static_cast<double>(views));
}

std::optional<double> Tracking::MeasureGround(const Frame& frame, bool map_points,
                                              KeyFrame::Ground* ground) const {
  const FrameFeatures& f = frame.F();
  std::vector<Eigen::Vector3d> points;
  std::vector<uint64_t> ids;
  auto add = [&](const Eigen::Vector3d& p, uint64_t id = 0) {
    if (p.y() > 0 && p.z() > 0 && p.z() <= options_.depth.ground_max_depth &&
        std::abs(p.x()) <= options_.depth.ground_max_lateral) {
      points.push_back(p);
      ids.push_back(id);
    }
  };
  if (map_points) {
    // The local map's points ahead (the ones the frame tracks are too few on a road that
    // streams past: 30-50 against 200 keypoints with depth).
    for (const auto& point : local_points_) {
      if (!point || point->bad || !UsableForPose(*point)) continue;
      // A point the network placed counts only once other views have triangulated it: the
      // network's road rises ahead, and the first map is all network (KITTI: 12 m "heights").
      if (point->depth_prior && !Triangulated(*point)) continue;
      add(*frame.cam_from_world * point->position, point->id);
    }
  } else {
    for (size_t i = 0; i < f.Size(); ++i) {
      if (!(f.depth[i] > 0) || (i < in_dynamic_box_.size() && in_dynamic_box_[i])) continue;
      add(f.UnprojectCamera(i) / f.depth_scale);  // the source's own units
    }
  }
  GroundPlaneOptions options;
  options.max_tilt_deg = options_.depth.ground_max_tilt_deg;
  options.inlier_ratio = options_.depth.ground_inlier_ratio;
  options.min_inliers = options_.depth.ground_min_inliers;
  const GroundPlane plane = EstimateGroundPlane(points, options);
  if (!plane.valid) return std::nullopt;
  if (ground != nullptr && map_points) {
    ground->normal_cam = plane.normal;
    ground->point_ids.clear();
    for (int k : plane.inliers) ground->point_ids.push_back(ids[static_cast<size_t>(k)]);
    std::sort(ground->point_ids.begin(), ground->point_ids.end());
  }
  return plane.height;
}

bool Tracking::Triangulated(const MapPoint& point) const {
  const KeyFrame* ref = point.reference;
  if (ref == nullptr || ref->bad) return false;
  const Eigen::Vector3d ray_ref = (point.position - ref->CameraCenter()).normalized();
  const double min_cos = std::cos(options_.depth.ground_min_parallax_deg * M_PI / 180.0);
  for (const auto& [kf, idx] : point.observations) {
    if (kf == ref || kf->bad) continue;
    if ((point.position - kf->CameraCenter()).normalized().dot(ray_ref) < min_cos) return true;
  }
  return false;
}

void Tracking::AnchorBetweenKeyFrames(FrameRecord& record, const Rigid3d& cam_from_world,
                                      KeyFrame* new_keyframe) {
  if (new_keyframe != nullptr) {
    // The frames since the last keyframe now have the keyframe after them.
    if (newest_keyframe_ != nullptr) {
      const int next_snapshot = options_.tracking.follow_local_scale
                                    ? new_keyframe->SnapshotScale(map_.StructureVersion())
                                    : -1;
      for (size_t i = newest_keyframe_record_ + 1; i < records_.size(); ++i) {
        FrameRecord& r = records_[i];
        if (!r.tracked || r.previous_keyframe != newest_keyframe_) continue;
        r.next_keyframe = new_keyframe;
        // In the map's units now (the previous keyframe's may have moved since).
        Rigid3d cam_from_previous = r.cam_from_previous;
        cam_from_previous.translation() *= newest_keyframe_->LocalScaleSince(r.previous_snapshot);
        r.cam_from_next = cam_from_previous * newest_keyframe_->cam_from_world *
                          new_keyframe->cam_from_world.inverse();
        r.next_snapshot = next_snapshot;
      }
    }
    newest_keyframe_ = new_keyframe;
    newest_keyframe_record_ = records_.size();  // this record's index once pushed
  }
  if (newest_keyframe_ == nullptr) return;
  record.previous_keyframe = newest_keyframe_;
  record.cam_from_previous = cam_from_world * newest_keyframe_->cam_from_world.inverse();
  if (options_.tracking.follow_local_scale)
    record.previous_snapshot = newest_keyframe_->SnapshotScale(map_.StructureVersion());
}

Rigid3d ResolveFramePose(const FrameRecord& record) {
  const Rigid3d from_reference =
      Map::ResolvePose(record.reference, record.cam_from_reference, record.reference_snapshot);
  const KeyFrame* previous = record.previous_keyframe;
  const KeyFrame* next = record.next_keyframe;
  if (previous == nullptr || next == nullptr || next->timestamp <= previous->timestamp) {
    return from_reference;
  }
  const double alpha = std::clamp(
      (record.timestamp - previous->timestamp) / (next->timestamp - previous->timestamp), 0.0,
      1.0);
  const Rigid3d world_from_cam_a =
      Map::ResolvePose(previous, record.cam_from_previous, record.previous_snapshot).inverse();
  const Rigid3d world_from_cam_b =
      Map::ResolvePose(next, record.cam_from_next, record.next_snapshot).inverse();
  return InterpolatePose(world_from_cam_a, world_from_cam_b, alpha).inverse();
}

std::optional<double> Tracking::SensorToMapScale(const FrameFeatures& with_depth) const {
  if (!last_frame_ || !last_frame_->cam_from_world) return std::nullopt;
  std::vector<double> map_depths, sensor_depths;
  DepthPairs(*last_frame_, with_depth, false, &map_depths, &sensor_depths);
  // The median ratio (no Huber steps): one frame, tracked without these depths, so nothing in
  // it was fitted to them.
  DepthScaleOptions options;
  options.min_points = static_cast<int>(kMinSensorScaleSamples);
  options.iterations = 0;
  const DepthScaleEstimate estimate = EstimateDepthScale(sensor_depths, map_depths, options);
  if (!estimate.valid) return std::nullopt;
  return estimate.scale;
}

void Tracking::GiveLoadedMapScale(double factor) {
  if (last_frame_) RescaleWorld(*last_frame_, factor);
  loaded_map_metric_ = true;
}

void Tracking::RescaleWorld(Frame& frame, double factor) {
  map_.Rescale(factor);
  auto scale_translation = [factor](Rigid3d& pose) { pose.translation() *= factor; };
  for (FrameRecord& r : records_) {
    scale_translation(r.cam_from_reference);
    scale_translation(r.cam_from_previous);
    scale_translation(r.cam_from_next);
    r.depth_scale *= factor;
  }
  // The frame may be the last one itself (GiveLoadedMapScale): scaled once, below.
  if (last_frame_ && last_frame_->cam_from_world && &*last_frame_ != &frame)
    scale_translation(*last_frame_->cam_from_world);
  if (velocity_) scale_translation(*velocity_);
  for (auto& [id, pose] : recent_good_) scale_translation(pose);
  if (last_good_pose_) scale_translation(*last_good_pose_);
  scale_translation(*frame.cam_from_world);
  frame.features = RescaleDepth(frame.F(), static_cast<float>(factor));
  // The history is now measured against the rescaled map.
  log_scale_sum_ += log_scale_count_ * std::log(factor);
  last_depth_scale_ *= factor;
  for (double& h : ground_heights_) h *= factor;  // lengths in the map
}

int Tracking::OptimizeFramePose(Frame& frame, double min_static, bool map_points_only) {
  CorrectDepthScale(frame, false);
  std::vector<PoseObservation> observations;
  std::vector<size_t> indices;
  const FrameFeatures& f = frame.F();
  for (size_t i = 0; i < frame.map_points.size(); ++i) {
    const auto& p = frame.map_points[i];
    if (!p || p->bad || !UsableForPose(*p)) continue;
    if (options_.tracking.static_test && p->static_probability < min_static) continue;
    if (map_points_only && p->NumObservations() == 0) continue;
    observations.push_back({p->position, f.Observation(i)});
    indices.push_back(i);
  }
  for (size_t i = 0; i < frame.outlier.size(); ++i) frame.outlier[i] = false;
  if (observations.size() < 3) return 0;
  const PoseOptimizationResult result =
      OptimizePose(f.intrinsics, *frame.cam_from_world, observations, options_.pose);
  if (result.num_inliers < 3) return result.num_inliers;  // keep the prediction: too few to trust
  frame.cam_from_world = result.cam_from_world;
  for (size_t k = 0; k < indices.size(); ++k) frame.outlier[indices[k]] = result.outlier[k];
  return result.num_inliers;
}

int Tracking::DiscardOutliers(Frame& frame) {
  int in_map = 0;
  for (size_t i = 0; i < frame.map_points.size(); ++i) {
    auto& p = frame.map_points[i];
    if (!p) continue;
    if (frame.outlier[i] || p->bad) {
      p->last_frame_seen = frame.id;
      p.reset();
      frame.outlier[i] = false;
    } else if (p->NumObservations() > 0 && UsableForPose(*p)) {
      ++in_map;
    }
  }
  return in_map;
}

void Tracking::AddVisualOdometryPoints(Frame& frame) {
  const FrameFeatures& f = frame.F();
  const Rigid3d world_from_cam = frame.cam_from_world->inverse();
  for (size_t i = 0; i < f.Size(); ++i) {
    if (frame.map_points[i] || !(f.depth[i] > 0)) continue;
    // Not in the map (no id, no observation): lives only as long as the frames holding it.
    auto point = std::make_shared<MapPoint>(UINT64_MAX, world_from_cam * f.UnprojectCamera(i),
                                            nullptr, frame.id);
    point->descriptor = f.descriptors.row(static_cast<int>(i)).clone();
    frame.map_points[i] = std::move(point);
    frame.outlier[i] = false;
  }
}

int Tracking::TrackLastFrameDepth(Frame& frame) {
  if (!options_.tracking.depth_odometry || !velocity_ || !last_frame_ ||
      !last_frame_->cam_from_world)
    return 0;
  // The last frame's own depths as points that live only for this search (ORB-SLAM2's visual
  // odometry points): the pose is measured on them, never extrapolated.
  Frame last = *last_frame_;
  AddVisualOdometryPoints(last);
  Frame attempt = frame;
  std::fill(attempt.map_points.begin(), attempt.map_points.end(), nullptr);
  if (!MatchLastFrame(attempt, last)) return 0;
  OptimizeFramePose(attempt);
  DiscardOutliers(attempt);
  const int inliers = CountInliers(attempt);
  if (inliers < kMinOdometryPoints) return 0;
  // Only the pose is kept: the odometry points never reach a keyframe or the next search.
  frame.cam_from_world = attempt.cam_from_world;
  std::fill(frame.map_points.begin(), frame.map_points.end(), nullptr);
  return inliers;
}

bool Tracking::MatchLastFrame(Frame& frame, const Frame& last) const {
  const Matcher matcher(0.9f, true);
  frame.cam_from_world = *velocity_ * *last.cam_from_world;
  const float radius = static_cast<float>(options_.tracking.motion_search_radius);
  int matches = matcher.SearchByProjection(frame, last, radius);
  if (matches < options_.tracking.min_motion_matches) {
    std::fill(frame.map_points.begin(), frame.map_points.end(), nullptr);
    matches = matcher.SearchByProjection(frame, last, 2 * radius);
  }
  return matches >= options_.tracking.min_motion_matches;
}

bool Tracking::TrackWithMotionModel(Frame& frame) {
  if (!MatchLastFrame(frame, *last_frame_)) return false;
  OptimizeFramePose(frame);
  const int in_map = DiscardOutliers(frame);
  if (odometry_localisation_) {
    // ORB-SLAM2's localisation mode: few map points means odometry on the temporary ones.
    int total = 0;
    for (const auto& p : frame.map_points) total += p ? 1 : 0;
    visual_odometry_ = in_map < 10;
    return total >= kMinOdometryPoints;
  }
  return in_map >= 10;
}

bool Tracking::TrackReferenceKeyFrame(Frame& frame) {
  if (reference_keyframe_ == nullptr || reference_keyframe_->bad || !last_frame_) return false;
  const Matcher matcher(0.7f, true);
  std::vector<std::shared_ptr<MapPoint>> matches;
  const int n = matcher.SearchByDescriptor(*reference_keyframe_, frame, matches);
  if (n < 15) return false;
  frame.map_points = matches;
  frame.cam_from_world = *last_frame_->cam_from_world;
  OptimizeFramePose(frame);
  return DiscardOutliers(frame) >= 10;
}

void Tracking::UpdateLocalMap(Frame& frame) {
  // Keyframes that see the frame's points, weighted by how many; the best is the reference.
  // Counted in each keyframe's scratch field, then walked in id order (deterministic).
  std::vector<KeyFrame*> counted;
  // Unique to this call in the whole process (a frame may be counted twice, and another tracker
  // may have stamped the same keyframes); only equality matters, so the value is deterministic in
  // effect.
  static std::atomic<uint64_t> last_stamp{0};
  const uint64_t stamp = last_stamp.fetch_add(1, std::memory_order_relaxed) + 1;
  auto count = [&](KeyFrame* kf) {
    if (kf->counted_for != stamp) {
      kf->counted_for = stamp;
      kf->counted_points = 0;
      counted.push_back(kf);
    }
    ++kf->counted_points;
  };
  for (size_t i = 0; i < frame.map_points.size(); ++i) {
    const auto& p = frame.map_points[i];
    if (!p || p->bad) continue;
    for (const auto& [kf, idx] : p->observations) count(kf);
  }
  local_keyframes_.clear();
  // Localisation only, off the map (odometry points alone): the reference keyframe's
  // neighbourhood is the local map, where the map is most likely to come back into view.
  if (counted.empty() && odometry_localisation_ && reference_keyframe_ != nullptr &&
      !reference_keyframe_->bad) {
    count(reference_keyframe_);
  }
  if (counted.empty()) return;
  std::sort(counted.begin(), counted.end(), KeyFrameIdLess());
  KeyFrame* best = nullptr;
  int best_count = 0;
  for (KeyFrame* kf : counted) {
    if (kf->bad) continue;
    if (kf->counted_points > best_count) {
      best_count = kf->counted_points;
      best = kf;
    }
    kf->local_map_frame = frame.id;
    local_keyframes_.push_back(kf);
  }
  const size_t max_kfs = static_cast<size_t>(options_.tracking.max_local_keyframes);
  const size_t first_ring = local_keyframes_.size();
  for (size_t k = 0; k < first_ring && local_keyframes_.size() < max_kfs; ++k) {
    KeyFrame* kf = local_keyframes_[k];
    auto add = [&](KeyFrame* other) {
      if (other == nullptr || other->bad || other->local_map_frame == frame.id) return;
      other->local_map_frame = frame.id;
      local_keyframes_.push_back(other);
    };
    for (KeyFrame* n : kf->BestCovisibles(10)) add(n);
    for (KeyFrame* c : kf->children) add(c);
    add(kf->parent);
  }
  if (best != nullptr) {
    reference_keyframe_ = best;
    frame.reference_keyframe = best;
  }
  // Local points, in keyframe then keypoint order (deterministic).
  local_points_.clear();
  for (KeyFrame* kf : local_keyframes_) {
    for (const auto& p : kf->map_points) {
      if (!p || p->bad || p->local_map_frame == frame.id) continue;
      p->local_map_frame = frame.id;
      local_points_.push_back(p);
    }
  }
}

bool Tracking::TrackLocalMap(Frame& frame) {
  UpdateLocalMap(frame);
  // Points already matched are not searched again.
  for (auto& p : frame.map_points) {
    if (!p) continue;
    if (p->bad) {
      p.reset();
      continue;
    }
    if (!p->frozen) ++p->visible;  // a loaded map's statistics never change
    p->last_frame_seen = frame.id;
  }
  std::vector<std::shared_ptr<MapPoint>> candidates;
  std::vector<ProjectionPrediction> predictions;
  std::vector<std::shared_ptr<MapPoint>> in_view;
  for (const auto& p : local_points_) {
    if (p->last_frame_seen == frame.id || p->bad) continue;
    ProjectionPrediction prediction;
    if (!frame.InFrustum(*p, 0.5f, &prediction)) continue;
    if (!p->frozen) ++p->visible;  // a loaded map's statistics never change
    candidates.push_back(p);
    predictions.push_back(prediction);
  }
  const bool recently_relocalised = frame.id < last_reloc_frame_id_ + 2;
  // After a weak pose (a crowd hid the scene) the prediction is less sure: a wider window.
  const float radius = static_cast<float>(options_.tracking.local_search_radius) *
                       (recently_relocalised ? 1.7f : 1.f) * (weak_streak_ > 0 ? 2.f : 1.f);
  const Matcher matcher(0.8f, false);
  matcher.SearchByProjection(frame, candidates, predictions, radius);

  // Localisation only by odometry: with enough map points in view the pose rests on them alone,
  // and the odometry points are dropped (remade from this frame's depth at the map's pose):
  // odometry points carry the drift of the frames that made them, and outnumbering the map they
  // would keep it (measured on seq-a frames 300-599: 0.05 m instead of 0.015 m after the map is
  // found again).
  bool map_only = false;
  if (odometry_localisation_) {
    int in_map = 0;
    for (const auto& p : frame.map_points)
      in_map += p && p->NumObservations() > 0 && UsableForPose(*p);
    map_only = in_map >= options_.tracking.min_inliers;
  }
  auto count_inliers = [&frame] {
    int n = 0;
    for (size_t i = 0; i < frame.map_points.size(); ++i) {
      const auto& p = frame.map_points[i];
      if (p && !frame.outlier[i] && p->NumObservations() > 0) ++n;
    }
    return n;
  };
  if (options_.tracking.static_test) {
    // Coarse to fine: the pose first from the points with a long static history alone, when
    // there are enough of them, and every match judged at that pose. A crowd that fills the view
    // then cannot pull the pose along and turn the background's verdicts against it. A frame
    // with dynamic boxes has had its movers removed by them already; there the few trusted
    // points left between the boxes give a pose too weak to judge by (measured on bonn-crowd-a
    // with YOLOX-nano: 20 frames lost instead of none), so all usable points pose it.
    const Rigid3d start = *frame.cam_from_world;
    const int trusted = in_dynamic_box_.empty()
                            ? OptimizeFramePose(frame, kTrustedStaticProbability, map_only)
                            : 0;
    if (trusted >= options_.tracking.min_inliers) {
      judged_dynamic_ = JudgeStaticness(frame);
      OptimizeFramePose(frame, -1, map_only);
    } else {
      frame.cam_from_world = start;
      OptimizeFramePose(frame, -1, map_only);
      // Only a pose that rests on enough points judges the points (a weak one would teach the
      // map its own error).
      if (count_inliers() >= options_.tracking.min_inliers)
        judged_dynamic_ = JudgeStaticness(frame);
    }
    // The final optimisation reset the flags: points judged moving stay out.
    for (size_t i = 0; i < frame.map_points.size(); ++i) {
      const auto& p = frame.map_points[i];
      if (p && !UsableForPose(*p)) frame.outlier[i] = true;
    }
  } else {
    OptimizeFramePose(frame, -1, map_only);
  }
  if (map_only) {
    for (size_t i = 0; i < frame.map_points.size(); ++i) {
      const auto& p = frame.map_points[i];
      if (p && p->NumObservations() == 0) frame.outlier[i] = true;
    }
  }
  matches_inliers_ = count_inliers();
  for (size_t i = 0; i < frame.map_points.size(); ++i) {
    const auto& p = frame.map_points[i];
    if (p && !frame.outlier[i] && !p->frozen) ++p->found;
  }
  const uint64_t reloc_window =
      static_cast<uint64_t>(options_.tracking.max_frames_between_keyframes);
  if (num_relocalisations_ > 0 && frame.id < last_reloc_frame_id_ + reloc_window &&
      matches_inliers_ < options_.tracking.min_inliers_after_reloc) {
    return false;
  }
  return matches_inliers_ >= options_.tracking.min_inliers;
}

std::vector<MatchState> Tracking::MatchStates(const Frame& frame) const {
  const StaticTestParams& params = options_.tracking.static_params;
  std::vector<MatchState> states(frame.map_points.size(), MatchState::kUnmatched);
  for (size_t i = 0; i < frame.map_points.size(); ++i) {
    const auto& p = frame.map_points[i];
    if (!p || p->bad) continue;
    if (!UsableForPose(*p)) {
      // Still at the prior it was created with: never judged decisively.
      const bool unconfirmed = p->static_probability == params.prior ||
                               p->static_probability == params.box_prior;
      states[i] = unconfirmed ? MatchState::kUnconfirmed : MatchState::kJudgedMoving;
    } else {
      states[i] = frame.outlier[i] ? MatchState::kPoseOutlier : MatchState::kPoseInlier;
    }
  }
  return states;
}

bool Tracking::UsableForPose(const MapPoint& point) const {
  return !options_.tracking.static_test ||
         point.static_probability >= options_.tracking.static_params.threshold;
}

int Tracking::JudgeStaticness(Frame& frame) {
  // A point at the floor has been seen moving again and again: out of the map, so that local BA
  // and matching stop meeting it.
  constexpr double kCullProbability = 0.05;
  std::vector<MapPoint*> cull;
  int dynamic = 0;
  for (size_t i = 0; i < frame.map_points.size(); ++i) {
    auto& p = frame.map_points[i];
    if (!p || p->bad) continue;
    const StaticEvidence evidence = JudgeObservationOf(frame, *p, i);
    if (evidence == StaticEvidence::kDynamic) ++p->motion_verdicts;
    p->static_probability = UpdateStaticProbability(p->static_probability, evidence);
    if (UsableForPose(*p)) {
      p->admitted = true;
      continue;
    }
    ++dynamic;
    frame.outlier[i] = true;
    // Never a loaded map's point (localisation only), nor an odometry point (not in the map).
    if ((!localize_only_ || (!odometry_localisation_ && !p->frozen)) &&
        p->static_probability <= kCullProbability) {
      cull.push_back(p.get());
      p.reset();
      frame.outlier[i] = false;
    }
  }
  for (MapPoint* p : cull) map_.ErasePoint(p);
  geometric_culled_ += static_cast<int>(cull.size());
  return dynamic;
}

StaticEvidence Tracking::JudgeObservationOf(const Frame& frame, const MapPoint& point,
                                            size_t i) const {
  const FrameFeatures& f = frame.F();
  const StaticTestParams& params = options_.tracking.static_params;
  const Eigen::Vector3d cam = *frame.cam_from_world * point.position;
  double residual = std::numeric_limits<double>::infinity();
  std::optional<double> depth_error;
  double depth_sigma = 0.0;
  double allowance = 0.0;
  double point_sigma = 0.0;
  if (cam.z() > 0) {
    const cv::KeyPoint& kp = f.keypoints_un[i];
    const double u = f.intrinsics.fx * cam.x() / cam.z() + f.intrinsics.cx;
    const double v = f.intrinsics.fy * cam.y() / cam.z() + f.intrinsics.cy;
    // In level-0 pixels of the keypoint's own level (coarse levels are that much less exact).
    const double level_scale = f.pyramid->scale_factors[static_cast<size_t>(kp.octave)];
    residual = std::hypot(u - kp.pt.x, v - kp.pt.y) / level_scale;
    const KeyFrame* ref = point.reference;
    const bool has_ref = ref != nullptr && !ref->bad;
    const Eigen::Vector3d origin = has_ref ? ref->CameraCenter() : Eigen::Vector3d::Zero();
    const double distance = has_ref ? (point.position - origin).norm() : 0.0;
    if (f.depth[i] > 0) {
      depth_error = RelativeDepthDisagreement(cam.z(), f.depth[i], distance, params);
      point_sigma = PointDepthDisagreementSigma(f.depth[i], distance, params);
      if (f.DepthIsPrior()) depth_sigma = f.depth_error.RelativeSigma(f.depth[i]);
    }
    // The point's own uncertainty along the ray that measured it, seen from here: its depth's
    // sigma as a shift in the image.
    if (params.parallax_sigmas > 0 && has_ref) {
      const double sigma = PointDepthSigma(
          distance, params, f.DepthIsPrior() ? f.depth_error.RelativeSigma(distance) : 0.0);
      if (sigma > 0)
        allowance = params.parallax_sigmas *
                    ParallaxShiftPx(point.position, origin, *frame.cam_from_world,
                                    f.intrinsics.fx, f.intrinsics.fy, sigma) /
                    level_scale;
    }
  }
  return JudgeObservation(residual, depth_error, params, depth_sigma, allowance, point_sigma);
}

void Tracking::JudgeInLastFrame(const std::vector<MapPoint*>& points) {
  const StaticTestParams& params = options_.tracking.static_params;
  if (!options_.tracking.static_test || !params.confirm_in_last_frame || !last_frame_ ||
      !last_frame_->cam_from_world)
    return;
  const Frame& last = *last_frame_;
  const Matcher matcher(0.8f, false);
  for (MapPoint* p : points) {
    ProjectionPrediction prediction;
    if (!last.InFrustum(*p, 0.5f, &prediction)) continue;
    // The window reaches the motion band; only agreement counts: in repetitive texture (road,
    // facades) the best match a few pixels off is often another keypoint, and its "motion" would
    // condemn static points. Motion is left to the frames after the keyframe.
    const int j = matcher.FindByProjection(last, *p, prediction,
                                           static_cast<float>(params.residual_dynamic_px));
    if (j < 0 ||
        JudgeObservationOf(last, *p, static_cast<size_t>(j)) != StaticEvidence::kStatic)
      continue;
    p->static_probability = UpdateStaticProbability(p->static_probability, StaticEvidence::kStatic);
    if (UsableForPose(*p)) p->admitted = true;
  }
}

bool Tracking::NeedNewKeyFrame(const Frame& frame) const {
  const TrackingOptions& t = options_.tracking;
  const uint64_t since_reloc = frame.id - last_reloc_frame_id_;
  if (num_relocalisations_ > 0 &&
      since_reloc < static_cast<uint64_t>(t.max_frames_between_keyframes) &&
      map_.NumKeyFrames() > static_cast<size_t>(t.max_frames_between_keyframes)) {
    return false;
  }
  if (reference_keyframe_ == nullptr) return true;
  // ORB-SLAM's count: the reference's points seen by 3 keyframes (2 in a map of two). Monocular:
  // a point can be seen by no more keyframes than the reference and those sharing points with it.
  // A map of one keyframe (made from depth) or a restart's first keyframe in the same map has
  // single-view points only, and they count, else no keyframe would ever come after it (RGB-D has
  // the close-point rule for that).
  int min_obs = map_.NumKeyFrames() <= 2 ? 2 : 3;
  if (t.monocular) {
    const int covisibles = static_cast<int>(reference_keyframe_->BestCovisibles(2).size());
    min_obs = std::min(min_obs, 1 + covisibles);
  }
  if (t.keyframe_ref_min_observations > 0) min_obs = t.keyframe_ref_min_observations;
  const int ref_matches = reference_keyframe_->TrackedMapPoints(min_obs);
  const bool idle = local_mapping_.Idle();

  // ORB-SLAM's close-point rule: a keyframe when few close keypoints are tracked and many could
  // become new close points, unless the place is already mapped (tracking.mapped_place_ratio):
  // most tracked close points are each seen by `redundant_observers` keyframes, keyframe
  // culling's test (LocalMapping::CullKeyFrames, without its scale-level condition). There the
  // untracked close keypoints are not structure the map lacks (with network depth: points the
  // prior misplaced, a mover, keypoints that do not repeat): a keyframe would re-make them from
  // the same kind of depth. Without it the rule fired on nearly every frame of a revisited
  // place, faster than culling removed keyframes (docs/reliability.md section 6).
  int tracked_close = 0, untracked_close = 0, established_close = 0;
  const FrameFeatures& f = frame.F();
  for (size_t i = 0; i < f.Size(); ++i) {
    if (!f.IsClose(i)) continue;
    const auto& point = frame.map_points[i];
    if (point && !frame.outlier[i]) {
      ++tracked_close;
      if (point->NumObservations() >= options_.mapping.redundant_observers) ++established_close;
    } else {
      ++untracked_close;
    }
  }
  const bool mapped_place = t.mapped_place_ratio > 0 && tracked_close > 0 &&
                            established_close > t.mapped_place_ratio * tracked_close;
  // Monocular: close points are no measurement of structure (ORB-SLAM's monocular rule).
  const bool need_close = !t.monocular && tracked_close < t.close_tracked_min &&
                          untracked_close > t.close_untracked_min && !mapped_place;
  const double ratio = map_.NumKeyFrames() < 2 ? 0.4 : t.keyframe_ref_ratio;
  const uint64_t since_kf = frame.id - last_keyframe_frame_id_;
  const bool c1a = since_kf >= static_cast<uint64_t>(t.max_frames_between_keyframes);
  const bool c1b = since_kf >= static_cast<uint64_t>(t.min_frames_between_keyframes) && idle;
  const bool weak = matches_inliers_ < ref_matches * 0.25;
  if (!weak && since_kf < static_cast<uint64_t>(t.min_keyframe_spacing)) return false;
  // Monocular: a keyframe is for new structure, which needs a baseline to triangulate with.
  if (t.monocular && !weak && !HasTriangulationBaseline(frame)) return false;
  const bool c1c = weak || need_close;
  const bool c2 = (matches_inliers_ < ref_matches * ratio || need_close) && matches_inliers_ > 15;
  spdlog::debug(
      "frame {}: inliers {} ref_matches {} close tracked {} ({} established) untracked {} local "
      "points {} kfs {}",
      frame.index, matches_inliers_, ref_matches, tracked_close, established_close, untracked_close,
      local_points_.size(), local_keyframes_.size());
  if (!((c1a || c1b || c1c) && c2)) return false;
  // Threaded mode: do not flood local mapping (ORB-SLAM's queue limit for RGB-D).
  const bool insert = idle || local_mapping_.QueueSize() < 3;
  if (insert) {
    spdlog::debug("frame {}: keyframe ({}{}{}{}{}; inliers {}, ratio bar {:.0f} of {})",
                  frame.index, c1a ? "max_interval " : "", c1b ? "idle " : "", weak ? "weak " : "",
                  need_close ? "close " : "", matches_inliers_ < ref_matches * ratio ? "ratio" : "",
                  matches_inliers_, ref_matches * ratio, ref_matches);
  }
  return insert;
}

bool Tracking::HasTriangulationBaseline(const Frame& frame) const {
  if (reference_keyframe_ == nullptr || !frame.cam_from_world) return true;
  std::vector<double> depths;
  for (size_t i = 0; i < frame.map_points.size(); ++i) {
    const auto& p = frame.map_points[i];
    if (p && !p->bad && !frame.outlier[i])
      depths.push_back((*frame.cam_from_world * p->position).z());
  }
  const double median_depth = Median(depths);
  if (!(median_depth > 0)) return true;
  const double baseline = (frame.CameraCenter() - reference_keyframe_->CameraCenter()).norm();
  double ratio = options_.mapping.triangulation_min_baseline_ratio;
  if (options_.tracking.keyframe_parallax_baseline)
    ratio = std::max(ratio, std::tan(options_.mapping.triangulation_min_parallax_deg * M_PI / 180));
  return baseline >= ratio * median_depth;
}

std::shared_ptr<KeyFrame> Tracking::CreateNewKeyFrame(
    Frame& frame, std::vector<std::pair<size_t, std::shared_ptr<const MapPoint>>>* created) {
  std::shared_ptr<KeyFrame> kf = map_.CreateKeyFrame(frame);
  for (size_t i = 0; i < frame.map_points.size(); ++i) {
    if (frame.map_points[i] && !frame.outlier[i] && !frame.map_points[i]->bad) {
      kf->map_points[i] = frame.map_points[i];
    }
  }
  // New points from depth: all close ones, and at least the nearest `new_keyframe_min_points`.
  const FrameFeatures& f = frame.F();
  std::vector<std::pair<float, size_t>> by_depth;
  for (size_t i = 0; i < f.Size() && KeyFramePointsFromDepth(); ++i) {
    if (f.depth[i] > 0) by_depth.emplace_back(f.depth[i], i);
  }
  std::sort(by_depth.begin(), by_depth.end());
  const Rigid3d world_from_cam = frame.cam_from_world->inverse();
  int considered = 0;
  std::vector<MapPoint*> new_points;
  for (const auto& [z, i] : by_depth) {
    if (!kf->map_points[i]) {
      // Boxes raise the prior of motion; geometry decides.
      const bool boxed = i < in_dynamic_box_.size() && in_dynamic_box_[i];
      CreatePointFromDepth(frame, *kf, world_from_cam, i,
                           boxed ? options_.tracking.static_params.box_prior
                                 : options_.tracking.static_params.prior);
      frame.outlier[i] = false;
      new_points.push_back(frame.map_points[i].get());
      if (created != nullptr) created->emplace_back(i, frame.map_points[i]);
    }
    ++considered;
    if (z > f.close_depth && considered > options_.tracking.new_keyframe_min_points) break;
  }
  // A new point must agree with one more frame, at a pose computed without it, before it is used.
  // The frame before the keyframe is such a frame, and it is already here.
  JudgeInLastFrame(new_points);
  reference_keyframe_ = kf.get();
  frame.reference_keyframe = kf.get();
  last_keyframe_frame_id_ = frame.id;
  return kf;
}

bool Tracking::Relocalise(Frame& frame) {
  // Global candidates first (the place recognition index: anywhere in the map, e.g. a loaded
  // one), then the most recent keyframes (where a short loss usually resumes).
  std::vector<KeyFrame*> candidates;
  std::set<uint64_t> chosen;
  const size_t per_source = static_cast<size_t>(options_.tracking.relocalisation_keyframes);
  if (const KeyFrameDatabase* database = map_.GetKeyFrameDatabase(); database != nullptr) {
    for (const PlaceCandidate& c : database->Query(frame.F().descriptors, per_source)) {
      std::shared_ptr<KeyFrame> kf = map_.GetKeyFrame(c.keyframe_id);
      if (kf && !kf->bad && chosen.insert(kf->id).second) candidates.push_back(kf.get());
    }
  }
  size_t recent = 0;
  for (auto it = map_.KeyFrames().rbegin(); it != map_.KeyFrames().rend(); ++it) {
    if (recent >= per_source) break;
    if (it->second->bad) continue;
    ++recent;
    if (chosen.insert(it->first).second) candidates.push_back(it->second.get());
  }
  // Network depth: the pose optimisation rescales the frame's depths to the candidate's points
  // (it replaces frame.features). Each candidate starts from the frame's own depths, and `f`
  // stays valid: it used to dangle after a rejected candidate (use after free, a crash on seq-a
  // FastDepth frames 0-299 localised in a map of 300-599).
  const std::shared_ptr<const FrameFeatures> original = frame.features;
  const FrameFeatures& f = *original;
  const Matcher matcher(0.75f, true);
  const cv::Mat K = (cv::Mat_<double>(3, 3) << f.intrinsics.fx, 0, f.intrinsics.cx, 0,
                     f.intrinsics.fy, f.intrinsics.cy, 0, 0, 1);
  for (KeyFrame* kf : candidates) {
    frame.features = original;
    std::vector<std::shared_ptr<MapPoint>> matches;
    if (matcher.SearchByDescriptor(*kf, frame, matches) < 15) continue;
    std::vector<cv::Point3f> object;
    std::vector<cv::Point2f> image;
    std::vector<size_t> indices;
    for (size_t i = 0; i < matches.size(); ++i) {
      if (!matches[i]) continue;
      const Eigen::Vector3d& x = matches[i]->position;
      object.emplace_back(static_cast<float>(x.x()), static_cast<float>(x.y()),
                          static_cast<float>(x.z()));
      image.push_back(f.keypoints_un[i].pt);
      indices.push_back(i);
    }
    cv::Mat rvec, tvec;
    std::vector<int> inliers;
    if (!cv::solvePnPRansac(object, image, K, cv::noArray(), rvec, tvec, false, 200, 3.0f, 0.99,
                            inliers, cv::SOLVEPNP_EPNP) ||
        inliers.size() < 10) {
      continue;
    }
    frame.cam_from_world = RigidFromRodrigues(rvec, tvec);
    std::fill(frame.map_points.begin(), frame.map_points.end(), nullptr);
    for (int k : inliers) frame.map_points[indices[k]] = matches[indices[k]];

    int good = OptimizeFramePose(frame);
    if (good < 10) continue;
    DiscardOutliers(frame);
    const int min_good = options_.tracking.min_inliers_after_reloc;
    if (good < min_good) {
      const int additional = matcher.SearchByProjection(frame, *kf, 10.f, 100);
      if (additional + good >= min_good) {
        good = OptimizeFramePose(frame);
        DiscardOutliers(frame);
      }
    }
    if (good >= min_good) {
      last_reloc_frame_id_ = frame.id;
      reference_keyframe_ = kf;
      frame.reference_keyframe = kf;
      return true;
    }
  }
  std::fill(frame.map_points.begin(), frame.map_points.end(), nullptr);
  frame.cam_from_world.reset();
  frame.features = original;
  return false;
}

}  // namespace ademono
