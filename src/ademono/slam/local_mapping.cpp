#include "ademono/slam/local_mapping.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>

#include "ademono/core/statistics.h"
#include "ademono/core/thread_name.h"
#include "ademono/optimize/bundle_adjustment.h"
#include "ademono/optimize/network_depth_model.h"
#include "ademono/optimize/residuals.h"
#include "ademono/optimize/triangulation.h"
#include "ademono/slam/matcher.h"

namespace ademono {

LocalMapping::LocalMapping(Map& map, const MappingOptions& options, bool monocular,
                           double configured_sigma_log)
    : map_(map),
      options_(options),
      monocular_(monocular),
      configured_sigma_log_(configured_sigma_log) {
  options_.Check();
  if (options_.threaded) {
    worker_ = std::thread([this] {
      SetCurrentThreadName("ademono-mapping");
      Run();
    });
    search_helper_.emplace(1, "ademono-search");
  }
}

LocalMapping::~LocalMapping() {
  try {
    Shutdown();
  } catch (const std::exception& e) {
    spdlog::error("local mapping: {}", e.what());  // a destructor must not throw
  }
}

namespace {

// The median of the last fits' values (the network's error depends on the scene it sees).
double RecentMedian(const std::vector<double>& per_fit) {
  constexpr size_t kRecent = 20;
  const size_t start = per_fit.size() > kRecent ? per_fit.size() - kRecent : 0;
  return Median(std::vector<double>(per_fit.begin() + static_cast<long>(start), per_fit.end()));
}

int InViewCount(const std::map<const KeyFrame*, int>& counts, const KeyFrame* kf) {
  const auto it = counts.find(kf);
  return it == counts.end() ? 1 : it->second;
}

double MsSinceStart(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

// CPU time of the calling thread (ms), for the debug log: unlike wall time, other jobs on the
// machine barely change it.
double ThreadCpuMs() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) * 1e3 + static_cast<double>(t.tv_nsec) * 1e-6;
}
}  // namespace

bool LocalMapping::Idle() const { return pending_ == nullptr; }

double LocalMapping::TakeFinishedMilliseconds() {
  const double ms = finished_ms_;
  finished_ms_ = 0;
  return ms;
}

void LocalMapping::HandOff() {
  ++frames_;
  if (pending_ && frames_ >= pending_->handoff_frame) Merge();
}

void LocalMapping::InsertKeyFrame(const std::shared_ptr<KeyFrame>& keyframe) {
  if (pending_) Merge();  // one keyframe in flight: the next one maps on the merged map
  const auto start = std::chrono::steady_clock::now();
  const double start_cpu = ThreadCpuMs();
  auto pending = std::make_unique<Pending>();
  pending->keyframe = keyframe;
  pending->handoff_frame = frames_ + static_cast<size_t>(options_.handoff_frames);
  {
    MutexLock lock(map_.mutex);
    ProcessNewKeyFrame(*keyframe);
    CullMapPoints(*keyframe);
    if (options_.triangulation) {
      const int created = CreateNewMapPoints(*keyframe);
      spdlog::debug("keyframe {}: {} map points triangulated", keyframe->id, created);
    }
    const double structure_ms = MsSinceStart(start);
    FuseNeighbours(*keyframe);
    const double fuse_ms = MsSinceStart(start) - structure_ms;
    pending->has_ba = options_.local_ba && GatherBundleAdjustment(*keyframe, *pending);
    spdlog::debug(
        "keyframe {}: structure {:.1f} ms, fuse {:.1f} ms, gather {:.1f} ms, cpu {:.1f} ms",
        keyframe->id, structure_ms, fuse_ms, MsSinceStart(start) - structure_ms - fuse_ms,
        ThreadCpuMs() - start_cpu);
  }
  pending->ms = MsSinceStart(start);
  pending_ = std::move(pending);
  if (pending_->has_ba && options_.threaded) {
    std::lock_guard<std::mutex> lock(job_mutex_);
    job_ = pending_.get();
    job_done_ = false;
    job_cv_.notify_all();
  } else if (pending_->has_ba) {
    Solve(*pending_);  // same result as the thread's, on this thread
  }
  if (options_.handoff_frames == 0) Merge();
}

void LocalMapping::Solve(Pending& pending) const {
  const auto start = std::chrono::steady_clock::now();
  const double start_cpu = ThreadCpuMs();
  try {
    pending.result = SolveBundleAdjustment(pending.problem, options_.ba);
  } catch (...) {
    pending.failure = std::current_exception();  // rethrown to tracking at the hand-off
  }
  pending.ms += MsSinceStart(start);
  spdlog::debug(
      "keyframe {}: BA {} cameras ({} fixed), {} points, {} observations: {:.1f} ms, cpu {:.1f} ms",
      pending.keyframe->id, pending.problem.cameras.size(),
      std::count_if(pending.problem.cameras.begin(), pending.problem.cameras.end(),
                    [](const BaCamera& c) { return c.fixed; }),
      pending.problem.points.size(), pending.problem.observations.size(), MsSinceStart(start),
      ThreadCpuMs() - start_cpu);
}

void LocalMapping::Merge() {
  if (!pending_) return;
  const auto wait_start = std::chrono::steady_clock::now();
  if (pending_->has_ba && options_.threaded) {
    std::unique_lock<std::mutex> lock(job_mutex_);
    job_cv_.wait(lock, [this] { return job_done_; });
    job_ = nullptr;
  }
  std::unique_ptr<Pending> pending = std::move(pending_);
  if (pending->failure) std::rethrow_exception(pending->failure);
  const double wait_ms = MsSinceStart(wait_start);  // tracking held up by the BA solve
  const auto start = std::chrono::steady_clock::now();
  const double start_cpu = ThreadCpuMs();
  {
    MutexLock lock(map_.mutex);
    if (pending->has_ba) {
      ApplyBundleAdjustment(*pending);
      if (monocular_ && configured_sigma_log_ > 0 && options_.network_error_model)
        MeasureNetworkErrors(*pending);
    }
    CullKeyFrames(*pending->keyframe);
    const double cull_ms = MsSinceStart(start);
    if (loop_closing_ != nullptr && !pending->keyframe->bad) {
      loop_closing_->AssertMapHeld();  // the same map, under loop closing's name
      loop_closing_->Process(*pending->keyframe);
    }
    spdlog::debug(
        "keyframe {}: waited {:.1f} ms, apply + cull {:.1f} ms, loop {:.1f} ms, "
        "cpu {:.1f} ms",
        pending->keyframe->id, wait_ms, cull_ms, MsSinceStart(start) - cull_ms,
        ThreadCpuMs() - start_cpu);
  }
  finished_ms_ += pending->ms + MsSinceStart(start);
}

void LocalMapping::Shutdown() {
  if (shut_down_) return;
  shut_down_ = true;
  std::exception_ptr failure;
  try {
    Merge();
  } catch (...) {
    failure = std::current_exception();
  }
  {
    std::lock_guard<std::mutex> lock(job_mutex_);
    stop_ = true;
  }
  job_cv_.notify_all();
  if (worker_.joinable()) worker_.join();
  if (failure) std::rethrow_exception(failure);
}

void LocalMapping::Run() {
  std::unique_lock<std::mutex> lock(job_mutex_);
  while (true) {
    job_cv_.wait(lock, [this] { return stop_ || (job_ != nullptr && !job_done_); });
    if (stop_) return;
    Pending* job = job_;
    lock.unlock();
    Solve(*job);  // touches only the snapshot in *job, never the map
    lock.lock();
    job_done_ = true;
    job_cv_.notify_all();
  }
}

void LocalMapping::ProcessNewKeyFrame(KeyFrame& keyframe) {
  if (keyframe.bad) return;
  for (size_t i = 0; i < keyframe.map_points.size(); ++i) {
    const auto& point = keyframe.map_points[i];
    if (!point) continue;
    if (point->bad) {
      keyframe.map_points[i].reset();
      continue;
    }
    if (!point->IsInKeyFrame(&keyframe)) {
      // A tracked point: this keyframe is a new view of it.
      point->AddObservation(&keyframe, i);
      point->UpdateNormalAndDepth();
      point->ComputeDistinctiveDescriptor();
    } else if (point->first_keyframe_id == keyframe.id) {
      recent_points_.push_back(point);  // created from this keyframe's depth
    }
  }
  keyframe.UpdateConnections();
}

void LocalMapping::CullMapPoints(const KeyFrame& keyframe) {
  std::vector<std::shared_ptr<MapPoint>> kept;
  kept.reserve(recent_points_.size());
  for (const auto& point : recent_points_) {
    if (point->bad) continue;
    const uint64_t age = keyframe.id - point->first_keyframe_id;
    if (point->FoundRatio() < options_.cull_found_ratio) {
      map_.ErasePoint(point.get());
    } else if (age >= 2 && point->NumObservations() < options_.cull_min_observations) {
      map_.ErasePoint(point.get());
    } else if (age < 3) {
      kept.push_back(point);
    }
  }
  recent_points_ = std::move(kept);
}

int LocalMapping::CreateNewMapPoints(KeyFrame& keyframe) {
  if (keyframe.bad) return 0;
  const FrameFeatures& f1 = keyframe.F();
  const PinholeIntrinsics& in = f1.intrinsics;
  const double min_parallax_cos =
      std::cos(options_.triangulation_min_parallax_deg * 3.14159265358979323846 / 180.0);
  const float ratio_factor = 1.5f * f1.pyramid->scale_factors.at(
                                        std::min<size_t>(1, f1.pyramid->scale_factors.size() - 1));
  const Eigen::Vector3d center1 = keyframe.CameraCenter();
  const Matcher matcher(static_cast<float>(options_.triangulation_match_ratio), false);
  int created = 0;
  for (KeyFrame* k2 : keyframe.BestCovisibles(options_.triangulation_neighbours)) {
    // A loaded map's keyframe (localisation only) takes no new point.
    if (k2->bad || k2->frozen) continue;
    // Too short a baseline for the scene's depth: triangulation would be noise.
    std::vector<double> depths;
    for (const auto& p : k2->map_points) {
      if (p && !p->bad) depths.push_back((k2->cam_from_world * p->position).z());
    }
    if (depths.empty()) continue;
    std::nth_element(depths.begin(), depths.begin() + depths.size() / 2, depths.end());
    const double median_depth = depths[depths.size() / 2];
    const double baseline = (k2->CameraCenter() - center1).norm();
    if (!(median_depth > 0) || baseline / median_depth < options_.triangulation_min_baseline_ratio)
      continue;

    std::vector<std::pair<size_t, size_t>> matches;
    matcher.SearchForTriangulation(keyframe, *k2, options_.triangulation_depth_sigmas, matches,
                                   search_helper_ ? &*search_helper_ : nullptr);
    const FrameFeatures& f2 = k2->F();
    const Eigen::Vector3d center2 = k2->CameraCenter();
    for (const auto& [i1, i2] : matches) {
      if (keyframe.map_points[i1] || k2->map_points[i2]) continue;
      const cv::KeyPoint& kp1 = f1.keypoints_un[i1];
      const cv::KeyPoint& kp2 = f2.keypoints_un[i2];
      const Eigen::Vector2d n1((kp1.pt.x - in.cx) / in.fx, (kp1.pt.y - in.cy) / in.fy);
      const Eigen::Vector2d n2((kp2.pt.x - f2.intrinsics.cx) / f2.intrinsics.fx,
                               (kp2.pt.y - f2.intrinsics.cy) / f2.intrinsics.fy);
      const auto x = TriangulatePoint(keyframe.cam_from_world, k2->cam_from_world, n1, n2);
      if (!x) continue;
      if (ParallaxCosine(keyframe.cam_from_world, k2->cam_from_world, *x) > min_parallax_cos)
        continue;
      // In front of both cameras and reprojecting within chi2 (2 dof) at each keypoint's level.
      ImageObservation o1, o2;
      o1.pixel = Eigen::Vector2d(kp1.pt.x, kp1.pt.y);
      o1.inv_sigma2 = f1.pyramid->inv_level_sigma2[kp1.octave];
      o2.pixel = Eigen::Vector2d(kp2.pt.x, kp2.pt.y);
      o2.inv_sigma2 = f2.pyramid->inv_level_sigma2[kp2.octave];
      double z1 = 0, z2 = 0;
      if (internal::ObservationChi2(in, o1, keyframe.cam_from_world, *x, &z1) > kChi2Mono ||
          internal::ObservationChi2(f2.intrinsics, o2, k2->cam_from_world, *x, &z2) > kChi2Mono ||
          z1 <= 0 || z2 <= 0)
        continue;
      // Scale consistency: the distances must agree with the keypoints' pyramid levels.
      const double dist1 = (*x - center1).norm(), dist2 = (*x - center2).norm();
      if (dist1 <= 0 || dist2 <= 0) continue;
      const float ratio_dist = static_cast<float>(dist2 / dist1);
      const float ratio_octave =
          f1.pyramid->scale_factors[kp1.octave] / f2.pyramid->scale_factors[kp2.octave];
      if (ratio_dist * ratio_factor < ratio_octave || ratio_dist > ratio_octave * ratio_factor)
        continue;
      // A depth prior that disagrees by more than its own uncertainty: a wrong match.
      const double sigmas = options_.triangulation_depth_sigmas;
      if (sigmas > 0 && f1.DepthIsPrior() && f1.depth[i1] > 0 &&
          std::abs(z1 - f1.depth[i1]) > sigmas * f1.depth_error.Sigma(f1.depth[i1]))
        continue;
      auto point = map_.CreateMapPoint(*x, &keyframe, keyframe.frame_id);
      point->AddObservation(&keyframe, i1);
      point->AddObservation(k2, i2);
      keyframe.AddMapPoint(point, i1);
      k2->AddMapPoint(point, i2);
      point->ComputeDistinctiveDescriptor();
      point->UpdateNormalAndDepth();
      recent_points_.push_back(point);
      ++created;
    }
  }
  return created;
}

void LocalMapping::FuseNeighbours(KeyFrame& keyframe) {
  if (keyframe.bad || options_.fuse_neighbours == 0) return;
  std::vector<KeyFrame*> targets;
  for (KeyFrame* kf : keyframe.BestCovisibles(options_.fuse_neighbours)) {
    if (kf->fuse_target_for == keyframe.id) continue;
    kf->fuse_target_for = keyframe.id;
    targets.push_back(kf);
  }
  const size_t first_ring = targets.size();
  for (size_t k = 0; k < first_ring; ++k) {
    for (KeyFrame* kf2 : targets[k]->BestCovisibles(5)) {
      if (kf2->bad || kf2->fuse_target_for == keyframe.id || kf2 == &keyframe) continue;
      kf2->fuse_target_for = keyframe.id;
      targets.push_back(kf2);
    }
  }
  const Matcher matcher(0.6f, true);
  // This keyframe's points into the neighbours (a loaded map's keyframes in localisation only
  // take none: they never change; their points still come into this keyframe below).
  for (KeyFrame* kf : targets) {
    if (kf->frozen) continue;
    std::vector<std::shared_ptr<MapPoint>> points;
    for (const auto& p : keyframe.map_points) {
      if (p && !p->bad) points.push_back(p);
    }
    matcher.Fuse(map_, *kf, points, static_cast<float>(options_.fuse_radius));
  }
  // The neighbours' points into this keyframe.
  std::vector<std::shared_ptr<MapPoint>> candidates;
  for (KeyFrame* kf : targets) {
    for (const auto& p : kf->map_points) {
      if (!p || p->bad || p->fuse_target_keyframe == keyframe.id) continue;
      p->fuse_target_keyframe = keyframe.id;
      candidates.push_back(p);
    }
  }
  matcher.Fuse(map_, keyframe, candidates, static_cast<float>(options_.fuse_radius));
  for (const auto& p : keyframe.map_points) {
    if (p && !p->bad) {
      p->ComputeDistinctiveDescriptor();
      p->UpdateNormalAndDepth();
    }
  }
  keyframe.UpdateConnections();
}

bool LocalMapping::GatherBundleAdjustment(KeyFrame& keyframe, Pending& pending) {
  // Keyframe + covisibles are free, keyframes that see the local points but are not local are
  // fixed (the first keyframe is always fixed).
  BundleAdjustmentProblem& problem = pending.problem;
  std::vector<std::shared_ptr<KeyFrame>>& cameras = pending.cameras;
  std::vector<std::shared_ptr<MapPoint>>& points = pending.points;
  std::vector<std::pair<KeyFrame*, size_t>>& observation_refs = pending.observation_refs;
  {
    if (keyframe.bad) return false;
    std::vector<KeyFrame*> local{&keyframe};
    keyframe.ba_local_for = keyframe.id;
    for (KeyFrame* kf : keyframe.ordered_connections) {
      if (options_.ba_max_keyframes > 0 &&
          static_cast<int>(local.size()) >= options_.ba_max_keyframes)
        break;
      if (kf->bad || kf->ba_local_for == keyframe.id) continue;
      kf->ba_local_for = keyframe.id;
      local.push_back(kf);
    }
    std::sort(local.begin(), local.end(), KeyFrameIdLess());
    std::vector<MapPoint*> local_points;
    for (KeyFrame* kf : local) {
      for (const auto& p : kf->map_points) {
        if (!p || p->bad || p->ba_local_for == keyframe.id) continue;
        // A new point awaiting its confirming view (the geometric test) stays out, as it stays
        // out of the pose: a mover seen in one keyframe never shapes the keyframes.
        if (!p->admitted) continue;
        p->ba_local_for = keyframe.id;
        local_points.push_back(p.get());
      }
    }
    std::sort(local_points.begin(), local_points.end(),
              [](const MapPoint* a, const MapPoint* b) { return a->id < b->id; });
    // Fixed keyframes and how many local points each sees.
    std::map<KeyFrame*, int, KeyFrameIdLess> fixed_views;
    for (MapPoint* p : local_points) {
      for (const auto& [kf, idx] : p->observations) {
        if (kf->bad || kf->ba_local_for == keyframe.id) continue;
        ++fixed_views[kf];
      }
    }
    std::vector<KeyFrame*> fixed;
    for (const auto& [kf, views] : fixed_views) fixed.push_back(kf);
    if (options_.ba_max_fixed_keyframes > 0 &&
        fixed.size() > static_cast<size_t>(options_.ba_max_fixed_keyframes)) {
      // Most of the cost is the fixed keyframes' residuals: keep the ones that see the most
      // local points (ties: older first), which anchor the window as well as all of them.
      std::stable_sort(fixed.begin(), fixed.end(),
                       [&](KeyFrame* a, KeyFrame* b) { return fixed_views[a] > fixed_views[b]; });
      fixed.resize(static_cast<size_t>(options_.ba_max_fixed_keyframes));
      std::sort(fixed.begin(), fixed.end(), KeyFrameIdLess());
    }

    std::map<const KeyFrame*, size_t> camera_index;
    auto add_camera = [&](KeyFrame* kf, bool is_fixed) {
      map_.mutex.AssertHeld();  // the analysis does not carry the lock into a lambda
      camera_index[kf] = problem.cameras.size();
      // A loaded map's keyframe (localisation only) is an anchor, never moved.
      problem.cameras.push_back({kf->cam_from_world, is_fixed || kf->id == 0 || kf->frozen});
      cameras.push_back(map_.GetKeyFrame(kf->id));
    };
    for (KeyFrame* kf : local) add_camera(kf, false);
    for (KeyFrame* kf : fixed) add_camera(kf, true);
    bool any_free = false;
    for (const BaCamera& c : problem.cameras) any_free = any_free || !c.fixed;
    if (!any_free || local_points.empty()) return false;
    // The first keyframe alone fixed leaves the gauge free when nothing else is fixed; ORB-SLAM
    // accepts that, but a fixed frame keeps repeated runs anchored.
    problem.intrinsics = keyframe.F().intrinsics;
    // Point ids to problem indices, only for the road residuals below (depth.ground_in_ba).
    const bool any_ground = AnyGround(cameras);
    std::map<uint64_t, size_t> point_index_of;
    // mapping.network_scale_prior: the relative sigma of each network depth of a free keyframe.
    std::map<const KeyFrame*, double> scale_prior_sigma;
    if (monocular_ && options_.network_scale_prior) {
      if (const std::optional<double> spread = KeyFrameScaleSpread()) {
        std::map<const KeyFrame*, int> depths;
        for (MapPoint* p : local_points) {
          for (const auto& [kf, idx] : p->observations) {
            if (kf->ba_local_for == keyframe.id && kf->id != 0 && !kf->frozen &&
                kf->F().DepthIsPrior() && kf->F().depth[idx] > 0)
              ++depths[kf];
          }
        }
        for (const auto& [kf, n] : depths) scale_prior_sigma[kf] = *spread * std::sqrt(n);
      }
    }
    // How many of each keyframe's network priors enter this solve (their shared error counts once).
    std::map<const KeyFrame*, int> priors_in_view;
    if (NetworkSharedSigmaLog() > 0) {
      for (MapPoint* p : local_points) {
        if (!p->depth_prior || p->reference == nullptr) continue;
        const auto obs = p->observations.find(p->reference);
        if (obs != p->observations.end() && camera_index.count(obs->first) != 0 &&
            IsNetworkPrior(*p, *obs->first, obs->second))
          ++priors_in_view[obs->first];
      }
    }
    for (MapPoint* p : local_points) {
      const size_t point_index = problem.points.size();
      if (any_ground) point_index_of[p->id] = point_index;
      problem.points.push_back(p->position);
      problem.point_fixed.push_back(p->frozen ? 1 : 0);
      points.push_back(map_.GetMapPoint(p->id));
      for (const auto& [kf, idx] : p->observations) {
        auto it = camera_index.find(kf);
        if (it == camera_index.end()) continue;
        const bool prior = IsNetworkPrior(*p, *kf, idx);
        ImageObservation observation =
            prior ? NetworkPrior(*kf, idx, InViewCount(priors_in_view, kf))
                  : kf->F().Observation(idx);
        const auto scale_prior = scale_prior_sigma.find(kf);
        if (!prior && scale_prior != scale_prior_sigma.end() && kf->F().depth[idx] > 0) {
          // The network's own reading: the anchor holds the map at its long-run scale.
          const FrameFeatures& f = kf->F();
          const double z = f.depth[idx] / f.depth_scale;
          observation = f.PriorObservation(idx, z, scale_prior->second * z);
        }
        problem.observations.push_back({it->second, point_index, observation});
        observation_refs.emplace_back(kf, idx);
      }
    }
    // Each keyframe's road points at the rig's height below it (depth.ground_in_ba).
    for (size_t c = 0; any_ground && c < cameras.size(); ++c)  // in camera order: deterministic
      AppendGroundDistances(*cameras[c], c, point_index_of, problem.plane_distances);
  }
  for (const auto& c : cameras) {
    if (!c) return false;  // not in the map (cannot happen: gathered under the lock)
  }
  return true;
}

void LocalMapping::ApplyBundleAdjustment(const Pending& pending) {
  // Points culled or fused since the gather are bad and skipped; keyframes are only culled here.
  const BundleAdjustmentProblem& problem = pending.problem;
  const BundleAdjustmentResult& result = *pending.result;
  const auto& cameras = pending.cameras;
  const auto& points = pending.points;
  const auto& observation_refs = pending.observation_refs;
  for (size_t i = 0; i < problem.observations.size(); ++i) {
    if (!result.outlier[i]) continue;
    auto [kf, idx] = observation_refs[i];
    const std::shared_ptr<MapPoint>& point = points[problem.observations[i].point];
    // A loaded map's own observations stay (localisation only: it never changes).
    if (!point || point->bad || kf->bad || kf->frozen) continue;
    if (kf->map_points[idx] == point) kf->map_points[idx].reset();
    point->EraseObservation(kf);
    if (point->observations.empty()) map_.ErasePoint(point.get());
  }
  for (size_t c = 0; c < cameras.size(); ++c) {
    if (!problem.cameras[c].fixed && !cameras[c]->bad)
      cameras[c]->cam_from_world = result.cam_from_world[c];
  }
  for (size_t p = 0; p < points.size(); ++p) {
    if (!points[p] || points[p]->bad || points[p]->frozen) continue;
    points[p]->position = result.points[p];
    points[p]->UpdateNormalAndDepth();
  }
  map_.NoteStructureChange();
}

void LocalMapping::CullKeyFrames(KeyFrame& keyframe) {
  if (keyframe.bad) return;
  for (KeyFrame* kf : std::vector<KeyFrame*>(keyframe.ordered_connections)) {
    if (kf->id == 0 || kf->bad || kf->frozen) continue;
    int num_points = 0, num_redundant = 0;
    for (size_t i = 0; i < kf->map_points.size(); ++i) {
      const auto& p = kf->map_points[i];
      if (!p || p->bad) continue;
      // RGB-D: only close points count (far ones are not reliable enough to decide);
      // monocular: every point (ORB-SLAM).
      if (!monocular_ && !kf->F().IsClose(i)) continue;
      ++num_points;
      if (p->NumObservations() <= options_.redundant_observers) continue;
      const int level = kf->F().keypoints_un[i].octave;
      int observers = 0;
      for (const auto& [other, idx] : p->observations) {
        if (other == kf) continue;
        if (other->F().keypoints_un[idx].octave <= level + 1 &&
            ++observers >= options_.redundant_observers)
          break;
      }
      if (observers >= options_.redundant_observers) ++num_redundant;
    }
    if (num_points > 0 && num_redundant > options_.redundant_ratio * num_points)
      map_.EraseKeyFrame(kf);
  }
}

ImageObservation LocalMapping::NetworkPrior(const KeyFrame& kf, size_t i,
                                            int priors_in_view) const {
  const FrameFeatures& f = kf.F();
  double z = f.depth[i];
  // The keyframe's own error model once it has one: the network's reading mapped into the map.
  if (options_.network_error_model && kf.network_fit.valid) {
    const double mapped = kf.network_fit.Map(f.depth[i] / f.depth_scale);
    if (mapped > 0) z = mapped;
  }
  const double independent = NetworkSigmaLog(), shared = NetworkSharedSigmaLog();
  const double sigma_log =
      shared > 0 ? std::sqrt(independent * independent +
                             std::max(1, priors_in_view) * shared * shared)
                 : independent;
  return f.PriorObservation(i, z, sigma_log * z);
}

double LocalMapping::NetworkSharedSigmaLog() const {
  if (shared_sigma_logs_.empty() || !options_.network_error_model ||
      !options_.network_shared_error)
    return 0.0;
  return RecentMedian(shared_sigma_logs_);
}

double LocalMapping::NetworkSigmaLog() const {
  if (sigma_logs_.empty() || !options_.network_error_model) return configured_sigma_log_;
  return RecentMedian(sigma_logs_);
}

std::optional<double> LocalMapping::KeyFrameScaleSpread() const {
  std::vector<double> logs;
  for (const auto& [id, kf] : map_.KeyFrames()) {
    if (!kf->bad && kf->F().DepthIsPrior() && kf->F().depth_scale > 0)
      logs.push_back(std::log(kf->F().depth_scale));
  }
  if (logs.size() < 5) return std::nullopt;
  const double spread = RobustSpread(logs, Median(logs));
  if (!(spread > 0)) return std::nullopt;
  return spread;
}

bool LocalMapping::IsNetworkPrior(const MapPoint& p, const KeyFrame& kf, size_t i) const {
  // The network's depth holds the point only where geometry cannot yet.
  return monocular_ && options_.network_priors && p.depth_prior && &kf == p.reference &&
         kf.F().depth[i] > 0 && PriorActive(p);
}

bool LocalMapping::PriorActive(const MapPoint& p) const {
  const KeyFrame* ref = p.reference;
  if (ref == nullptr || ref->bad) return false;
  const auto it = p.observations.find(const_cast<KeyFrame*>(ref));
  if (it == p.observations.end()) return false;
  // Depth from parallax alpha with an angular keypoint error sigma_theta: relative sigma
  // sigma_theta / alpha (two views; more views only do better).
  const Eigen::Vector3d ray_ref = (p.position - ref->CameraCenter()).normalized();
  double max_angle = 0.0;
  for (const auto& [kf, idx] : p.observations) {
    if (kf == ref || kf->bad) continue;
    const Eigen::Vector3d ray = (p.position - kf->CameraCenter()).normalized();
    max_angle = std::max(max_angle, std::acos(std::clamp(ray_ref.dot(ray), -1.0, 1.0)));
  }
  const FrameFeatures& f = ref->F();
  const double sigma_px = f.pyramid->scale_factors[f.keypoints_un[it->second].octave];
  const double sigma_theta = sigma_px / f.intrinsics.fx;
  return sigma_theta > NetworkSigmaLog() * max_angle;
}

void LocalMapping::MeasureNetworkErrors(const Pending& pending) {
  for (size_t c = 0; c < pending.cameras.size(); ++c) {
    if (pending.problem.cameras[c].fixed) continue;
    KeyFrame& kf = *pending.cameras[c];
    if (kf.bad) continue;
    const FrameFeatures& f = kf.F();
    std::vector<double> map_depths, network_depths;
    for (size_t i = 0; i < kf.map_points.size(); ++i) {
      const auto& p = kf.map_points[i];
      if (!p || p->bad || !(f.depth[i] > 0) || p->NumObservations() < 2) continue;
      if (p->depth_prior && PriorActive(*p)) continue;  // held by the network: no evidence
      map_depths.push_back((kf.cam_from_world * p->position).z());
      // The network's own reading (undo the per-frame scale correction it was given).
      network_depths.push_back(f.depth[i] / f.depth_scale);
    }
    const InverseDepthAffine fit = FitInverseDepthAffine(map_depths, network_depths);
    if (!fit.valid) continue;
    kf.network_fit = fit;
    if (&kf == pending.keyframe.get()) {
      sigma_logs_.push_back(fit.sigma_log);
      shared_sigma_logs_.push_back(fit.shared_sigma_log);
      spdlog::debug(
          "keyframe {}: network error after its affine map {:.3f} (log, {} points), shared "
          "{:.3f}",
          kf.id, fit.sigma_log, map_depths.size(), fit.shared_sigma_log);
    }
  }
}

}  // namespace ademono
