#include "ademono/slam/loop_closing.h"

#include <spdlog/spdlog.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <random>
#include <set>
#include <thread>

#include "ademono/core/thread_name.h"
#include "ademono/core/timing.h"
#include "ademono/feature/matching.h"
#include "ademono/optimize/residuals.h"
#include "ademono/slam/matcher.h"

namespace ademono {

namespace {

constexpr double kChi2TwoDof = 9.210;  // 99 %, as ORB-SLAM's Sim3 inlier test

// A keyframe's map points with their keypoint index and camera-frame position.
struct KeyFramePoints {
  std::vector<size_t> index;
  std::vector<Eigen::Vector3d> camera;
  std::vector<std::shared_ptr<MapPoint>> point;
  cv::Mat descriptors;
};

KeyFramePoints CollectPoints(const KeyFrame& kf) {
  KeyFramePoints out;
  for (size_t i = 0; i < kf.map_points.size(); ++i) {
    const auto& p = kf.map_points[i];
    if (!p || p->bad) continue;
    out.index.push_back(i);
    out.camera.push_back(kf.cam_from_world * p->position);
    out.point.push_back(p);
    out.descriptors.push_back(kf.F().descriptors.row(static_cast<int>(i)));
  }
  return out;
}

// Whether camera-frame point x reprojects onto keypoint i of `f` within chi2 (2 dof).
bool Reprojects(const FrameFeatures& f, size_t i, const Eigen::Vector3d& x) {
  if (!(x.z() > 0)) return false;
  const PinholeIntrinsics& in = f.intrinsics;
  const double u = in.fx * x.x() / x.z() + in.cx, v = in.fy * x.y() / x.z() + in.cy;
  const cv::KeyPoint& kp = f.keypoints_un[i];
  const double du = u - kp.pt.x, dv = v - kp.pt.y;
  return (du * du + dv * dv) * f.pyramid->inv_level_sigma2[kp.octave] < kChi2TwoDof;
}

Sim3d FromUmeyama(const Eigen::Matrix4d& m) {
  Sim3d s;
  const Eigen::Matrix3d sr = m.topLeftCorner<3, 3>();
  s.scale = std::cbrt(sr.determinant());
  s.rotation = Eigen::Quaterniond(sr / s.scale).normalized();
  s.translation = m.topRightCorner<3, 1>();
  return s;
}

double RotationDegrees(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle() * 180.0 / M_PI;
}

double Median(std::vector<double> v) {
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

// Median depth of each keyframe's map points in its camera; a keyframe without any (or only
// points behind it) takes the median of the others, and 1 m if no keyframe has one.
std::vector<double> SceneDepths(const std::vector<KeyFrame*>& keyframes) {
  std::vector<double> depth(keyframes.size(), 0.0), known;
  for (size_t k = 0; k < keyframes.size(); ++k) {
    std::vector<double> z;
    for (const auto& p : keyframes[k]->map_points) {
      if (!p || p->bad) continue;
      const double d = (keyframes[k]->cam_from_world * p->position).z();
      if (d > 0.0 && std::isfinite(d)) z.push_back(d);
    }
    if (!z.empty()) known.push_back(depth[k] = Median(std::move(z)));
  }
  const double fallback = known.empty() ? 1.0 : Median(known);
  for (double& d : depth) {
    if (d <= 0.0) d = fallback;
  }
  return depth;
}

}  // namespace

LoopClosing::LoopClosing(Map& map, const KeyFrameDatabase& database, const LoopOptions& options,
                         bool sim3, double fuse_radius)
    : map_(map), database_(database), options_(options), sim3_(sim3), fuse_radius_(fuse_radius) {
  options_.Check();
}

std::optional<LoopClosing::Verified> LoopClosing::Verify(KeyFrame& query,
                                                         KeyFrame& candidate) const {
  const KeyFramePoints q = CollectPoints(query), c = CollectPoints(candidate);
  if (static_cast<int>(q.point.size()) < options_.min_matches ||
      static_cast<int>(c.point.size()) < options_.min_matches)
    return std::nullopt;
  // 1. Descriptor matches between the two keyframes' map points.
  BruteForceMatchOptions match_options;
  match_options.ratio = 0.75;
  match_options.max_distance = kOrbDistanceLow;
  std::vector<cv::DMatch> raw = MatchBruteForce(q.descriptors, c.descriptors, match_options);
  std::vector<std::pair<size_t, size_t>> pairs;  // (q row, c row)
  for (const cv::DMatch& m : raw) {
    if (q.point[m.queryIdx] == c.point[m.trainIdx]) continue;  // already the same point
    pairs.emplace_back(m.queryIdx, m.trainIdx);
  }
  if (static_cast<int>(pairs.size()) < options_.min_matches) return std::nullopt;

  // 2. 3D-3D RANSAC: match_cam_from_query_cam from 3 pairs (Umeyama), inliers by reprojection in
  // both images. Seeded by the keyframe ids: the same map gives the same hypotheses.
  const FrameFeatures& fq = query.F();
  const FrameFeatures& fc = candidate.F();
  auto count_inliers = [&](const Sim3d& s, std::vector<bool>* mask) {
    const Sim3d inv = s.Inverse();
    int n = 0;
    if (mask) mask->assign(pairs.size(), false);
    for (size_t k = 0; k < pairs.size(); ++k) {
      const auto [qi, ci] = pairs[k];
      if (Reprojects(fc, c.index[ci], s * q.camera[qi]) &&
          Reprojects(fq, q.index[qi], inv * c.camera[ci])) {
        ++n;
        if (mask) (*mask)[k] = true;
      }
    }
    return n;
  };
  auto fit = [&](const std::vector<size_t>& ks) -> std::optional<Sim3d> {
    Eigen::Matrix3Xd src(3, ks.size()), dst(3, ks.size());
    for (size_t j = 0; j < ks.size(); ++j) {
      src.col(j) = q.camera[pairs[ks[j]].first];
      dst.col(j) = c.camera[pairs[ks[j]].second];
    }
    const Sim3d s = FromUmeyama(Eigen::umeyama(src, dst, sim3_));
    if (!std::isfinite(s.scale) || s.scale < 0.5 || s.scale > 2.0 ||
        !s.translation.allFinite())
      return std::nullopt;
    return s;
  };
  std::mt19937 rng(static_cast<uint32_t>(query.id * 2654435761u + candidate.id));
  std::uniform_int_distribution<size_t> pick(0, pairs.size() - 1);
  int best_inliers = 0;
  Sim3d best;
  for (int it = 0; it < options_.ransac_iterations; ++it) {
    const size_t a = pick(rng), b = pick(rng), d = pick(rng);
    if (a == b || a == d || b == d) continue;
    const auto s = fit({a, b, d});
    if (!s) continue;
    const int n = count_inliers(*s, nullptr);
    if (n > best_inliers) {
      best_inliers = n;
      best = *s;
    }
  }
  if (best_inliers < options_.min_inliers) return std::nullopt;
  // Refit on all inliers.
  std::vector<bool> mask;
  count_inliers(best, &mask);
  std::vector<size_t> inlier_pairs;
  for (size_t k = 0; k < pairs.size(); ++k) {
    if (mask[k]) inlier_pairs.push_back(k);
  }
  if (const auto refined = fit(inlier_pairs); refined) {
    if (count_inliers(*refined, nullptr) >= best_inliers) best = *refined;
  }
  Verified v;
  v.match = &candidate;
  v.match_from_query = best;
  v.matched.assign(query.map_points.size(), nullptr);
  v.inliers = count_inliers(best, &mask);
  if (v.inliers < options_.min_inliers) return std::nullopt;
  for (size_t k = 0; k < pairs.size(); ++k) {
    if (mask[k]) v.matched[q.index[pairs[k].first]] = c.point[pairs[k].second];
  }

  // 3. Guided search: the points of the candidate and its best covisible keyframes projected into
  // the query with the loop transform.
  const Sim3d query_from_world = best.Inverse() * Sim3d::FromRigid(candidate.cam_from_world);
  std::vector<KeyFrame*> place = candidate.BestCovisibles(10);
  place.insert(place.begin(), &candidate);
  std::set<const MapPoint*> used;
  for (const auto& p : v.matched) {
    if (p) used.insert(p.get());
  }
  const PinholeIntrinsics& in = fq.intrinsics;
  const float radius_base = static_cast<float>(options_.search_radius);
  for (KeyFrame* kf : place) {
    for (const auto& p : kf->map_points) {
      if (!p || p->bad || used.count(p.get()) || p->IsInKeyFrame(&query)) continue;
      used.insert(p.get());
      const Eigen::Vector3d x = query_from_world * p->position;
      if (!(x.z() > 0)) continue;
      const float u = static_cast<float>(in.fx * x.x() / x.z() + in.cx);
      const float vv = static_cast<float>(in.fy * x.y() / x.z() + in.cy);
      if (!fq.InBounds(u, vv)) continue;
      // The point's scale range is in the loop side's metric: query distances times the scale.
      const float scaled = static_cast<float>(x.norm() * best.scale);
      const int level = p->PredictScale(scaled, fq.pyramid->log_scale_factor,
                                        fq.pyramid->num_levels);
      const float radius = radius_base * fq.pyramid->scale_factors[level];
      int best_dist = 256, best_idx = -1;
      for (size_t i : fq.FeaturesInArea(u, vv, radius, level - 1, level + 1)) {
        if (v.matched[i]) continue;
        const int dist = DescriptorDistance(p->descriptor, fq.descriptors.row(static_cast<int>(i)));
        if (dist < best_dist) {
          best_dist = dist;
          best_idx = static_cast<int>(i);
        }
      }
      if (best_idx >= 0 && best_dist <= kOrbDistanceLow) {
        v.matched[best_idx] = p;
      }
    }
  }
  // 4. Refinement by reprojection of every match (the 3D fit weighs depth errors, which are
  // large for network depth), then matches that do not reproject are dropped.
  std::vector<Sim3Observation> in_candidate, in_query;
  for (size_t k = 0; k < pairs.size(); ++k) {
    if (!mask[k]) continue;
    const cv::KeyPoint& kp = fc.keypoints_un[c.index[pairs[k].second]];
    in_candidate.push_back({q.camera[pairs[k].first], Eigen::Vector2d(kp.pt.x, kp.pt.y),
                            fc.pyramid->inv_level_sigma2[kp.octave]});
  }
  for (size_t i = 0; i < v.matched.size(); ++i) {
    if (!v.matched[i]) continue;
    const cv::KeyPoint& kp = fq.keypoints_un[i];
    in_query.push_back({candidate.cam_from_world * v.matched[i]->position,
                        Eigen::Vector2d(kp.pt.x, kp.pt.y),
                        fq.pyramid->inv_level_sigma2[kp.octave]});
  }
  v.match_from_query = RefineSim3(best, fq.intrinsics, fc.intrinsics, in_candidate, in_query,
                                  !sim3_);
  if (!(v.match_from_query.scale > 0.5 && v.match_from_query.scale < 2.0)) return std::nullopt;
  const Sim3d query_from_match = v.match_from_query.Inverse();
  v.matches = 0;
  for (size_t i = 0; i < v.matched.size(); ++i) {
    if (!v.matched[i]) continue;
    if (Reprojects(fq, i, query_from_match * (candidate.cam_from_world * v.matched[i]->position))) {
      ++v.matches;
    } else {
      v.matched[i].reset();
    }
  }
  if (v.matches < options_.min_projection_matches) return std::nullopt;
  return v;
}

LoopClosing::~LoopClosing() {
  if (global_ba_ && global_ba_->worker.joinable()) global_ba_->worker.join();
}

bool LoopClosing::Process(KeyFrame& keyframe) {
  if (!options_.enabled || keyframe.bad) return false;
  if (global_ba_ && ++global_ba_->keyframes_since >= options_.global_ba_handoff_keyframes)
    EndGlobalBundleAdjustment(true, keyframe.id);
  if (static_cast<int>(map_.NumKeyFrames()) < options_.min_keyframes ||
      (any_loop_ && keyframe.id < last_loop_keyframe_ + options_.recent_keyframes)) {
    groups_.clear();
    return false;
  }
  const auto start = std::chrono::steady_clock::now();
  // Never propose the keyframe's covisible or most recent keyframes: they are not a loop.
  std::set<uint64_t> exclude{keyframe.id};
  for (const auto& [kf, w] : keyframe.connections) exclude.insert(kf->id);
  const uint64_t recent = static_cast<uint64_t>(options_.recent_keyframes);
  for (auto it = map_.KeyFrames().rbegin(); it != map_.KeyFrames().rend(); ++it) {
    if (it->first + recent < keyframe.id) break;
    exclude.insert(it->first);
  }
  const std::vector<PlaceCandidate> candidates = database_.Query(
      keyframe.F().descriptors, static_cast<size_t>(options_.max_candidates), exclude);

  std::vector<std::pair<std::set<uint64_t>, int>> groups;
  std::optional<Verified> accepted;
  int accepted_count = 0;
  for (const PlaceCandidate& candidate : candidates) {
    const std::shared_ptr<KeyFrame> kf = map_.GetKeyFrame(candidate.keyframe_id);
    if (!kf || kf->bad) continue;
    std::optional<Verified> verified = Verify(keyframe, *kf);
    if (!verified) continue;
    std::set<uint64_t> place{kf->id};
    for (const auto& [other, w] : kf->connections) place.insert(other->id);
    // Consecutive: this place, or one sharing a keyframe with it, was verified last keyframe.
    int count = 1;
    for (const auto& group : groups_) {
      // Not a structured binding: clang 14 (tools/thread_safety.sh) cannot capture one.
      const std::set<uint64_t>& previous = group.first;
      const bool shared = std::any_of(place.begin(), place.end(),
                                      [&](uint64_t id) { return previous.count(id) > 0; });
      if (shared) count = std::max(count, group.second + 1);
    }
    groups.emplace_back(std::move(place), count);
    spdlog::debug("loop: keyframe {} (frame {}) verified against {} (frame {}): {} inliers, {} "
                  "matches, consistency {}",
                  keyframe.id, keyframe.index, kf->id, kf->index, verified->inliers,
                  verified->matches, count);
    if (count >= options_.consistency &&
        (!accepted || count > accepted_count ||
         (count == accepted_count && verified->matches > accepted->matches))) {
      accepted = std::move(verified);
      accepted_count = count;
    }
  }
  groups_ = std::move(groups);
  if (!accepted) return false;

  LoopEvent event;
  event.query_keyframe = keyframe.id;
  event.match_keyframe = accepted->match->id;
  event.query_frame = keyframe.index;
  event.match_frame = accepted->match->index;
  event.query_timestamp = keyframe.timestamp;
  event.inliers = accepted->inliers;
  event.matches = accepted->matches;
  event.scale = accepted->match_from_query.scale;
  event.sim3 = sim3_;
  // The pending global BA was gathered before this loop: its poses would undo the correction.
  if (global_ba_) EndGlobalBundleAdjustment(false, keyframe.id);
  Correct(keyframe, *accepted, event);
  event.milliseconds = MsSince(start);
  spdlog::info("loop closed: keyframe {} (frame {}) with keyframe {} (frame {}): {} matches, "
               "correction {:.3f} m {:.2f} deg, scale {:.3f}",
               event.query_keyframe, event.query_frame, event.match_keyframe, event.match_frame,
               event.matches, event.correction_m, event.correction_deg, event.scale);
  events_.push_back(event);
  groups_.clear();
  any_loop_ = true;
  last_loop_keyframe_ = keyframe.id;
  if (options_.global_ba) StartGlobalBundleAdjustment(events_.size() - 1);
  return true;
}

void LoopClosing::FinishGlobalBundleAdjustment() {
  if (!global_ba_) return;
  uint64_t last = 0;
  for (const auto& [id, kf] : map_.KeyFrames()) last = std::max(last, id);
  EndGlobalBundleAdjustment(true, last);
}

void LoopClosing::GlobalBundleAdjustmentNow() {
  FinishGlobalBundleAdjustment();
  StartGlobalBundleAdjustment(std::nullopt);
  if (!global_ba_) return;
  uint64_t last = 0;
  for (const auto& [id, kf] : map_.KeyFrames()) last = std::max(last, id);
  EndGlobalBundleAdjustment(true, last);
}

void LoopClosing::StartGlobalBundleAdjustment(std::optional<size_t> event) {
  auto job = std::make_unique<GlobalBa>();
  job->event = event;
  BundleAdjustmentProblem& problem = job->problem;
  std::map<const KeyFrame*, size_t> camera_index;
  for (const auto& [id, kf] : map_.KeyFrames()) {
    if (kf->bad) continue;
    // The oldest keyframe fixes the gauge; the scale is fixed by sensor-like depth residuals or
    // by the road (depth.ground_in_ba), and is free in the monocular core without them.
    if (problem.cameras.empty()) problem.intrinsics = kf->F().intrinsics;
    camera_index[kf.get()] = problem.cameras.size();
    problem.cameras.push_back({kf->cam_from_world, problem.cameras.empty()});
    job->keyframes.push_back(kf);
  }
  // Map point id -> problem index, only for the road's residuals below (depth.ground_in_ba).
  const bool any_ground = AnyGround(job->keyframes);
  std::map<uint64_t, size_t> point_index_of;
  for (const auto& [id, p] : map_.MapPoints()) {
    if (p->bad) continue;
    const size_t point_index = problem.points.size();
    size_t observed = 0;
    for (const auto& [kf, idx] : p->observations) {  // keyframe id order
      const auto it = camera_index.find(kf);
      if (it == camera_index.end()) continue;
      problem.observations.push_back({it->second, point_index, kf->F().Observation(idx)});
      ++observed;
    }
    if (observed == 0) continue;
    if (any_ground) point_index_of[id] = point_index;
    problem.points.push_back(p->position);
    job->points.push_back(p);
  }
  // The road local BA held each keyframe's scale with: without it, the global BA lets the
  // scale drift back (KITTI 00 with PyDNet, docs/loops.md).
  for (size_t c = 0; any_ground && c < job->keyframes.size(); ++c)
    AppendGroundDistances(*job->keyframes[c], c, point_index_of, problem.plane_distances);
  if (event) {
    LoopEvent& e = events_[*event];
    e.global_ba = true;
    e.global_ba_keyframes = problem.cameras.size();
    e.global_ba_points = problem.points.size();
  }
  if (problem.cameras.size() < 2 || problem.points.empty()) return;
  BundleAdjustmentOptions ba;
  ba.solver = BaSolver::kCeres;  // the whole map: a sparse reduced system
  ba.first_iterations = options_.global_ba_iterations;
  ba.second_iterations = options_.global_ba_iterations;
  GlobalBa* raw = job.get();
  // Touches only the snapshot in *raw, never the map (single-threaded Ceres: deterministic).
  job->worker = std::thread([raw, ba] {
    SetCurrentThreadName("ademono-globalba");
    const auto start = std::chrono::steady_clock::now();
    try {
      raw->result = SolveBundleAdjustment(raw->problem, ba);
    } catch (...) {
      raw->failure = std::current_exception();  // rethrown on the tracking thread at the merge
    }
    raw->ms = MsSince(start);
  });
  global_ba_ = std::move(job);
}

void LoopClosing::EndGlobalBundleAdjustment(bool apply, uint64_t at_keyframe) {
  std::unique_ptr<GlobalBa> job = std::move(global_ba_);
  job->worker.join();
  if (job->failure) std::rethrow_exception(job->failure);
  LoopEvent none;  // the global BA before a save belongs to no loop
  LoopEvent& e = job->event ? events_[*job->event] : none;
  e.global_ba_ms = job->ms;
  if (!apply) {
    spdlog::info("global BA after the loop at keyframe {} dropped: a newer loop came first",
                 e.query_keyframe);
    return;
  }
  const BundleAdjustmentResult& result = *job->result;
  // Each keyframe's pose before and after, for what was added or moved since the snapshot.
  std::map<const KeyFrame*, std::pair<Rigid3d, Rigid3d>, KeyFrameIdLess> moved;
  for (size_t k = 0; k < job->keyframes.size(); ++k) {
    KeyFrame* kf = job->keyframes[k].get();
    if (kf->bad) continue;
    moved[kf] = {kf->cam_from_world, result.cam_from_world[k]};
  }
  // Keyframes made since follow their spanning-tree ancestor (ids grow along the tree, so the
  // ancestor is already moved when its descendant comes).
  for (const auto& [id, kf] : map_.KeyFrames()) {
    if (kf->bad || moved.count(kf.get())) continue;
    const KeyFrame* ancestor = kf->parent;
    while (ancestor != nullptr && !moved.count(ancestor)) ancestor = ancestor->parent;
    if (ancestor == nullptr) continue;
    const auto& [before, after] = moved.at(ancestor);
    moved[kf.get()] = {kf->cam_from_world, kf->cam_from_world * before.inverse() * after};
  }
  std::set<const MapPoint*> solved;
  for (size_t i = 0; i < job->points.size(); ++i) {
    MapPoint* p = job->points[i].get();
    if (p->bad) continue;
    p->position = result.points[i];
    solved.insert(p);
  }
  // Points made since follow their reference keyframe.
  for (const auto& [id, p] : map_.MapPoints()) {
    if (p->bad || solved.count(p.get())) continue;
    const KeyFrame* ref = p->reference;
    if ((ref == nullptr || ref->bad) && !p->observations.empty())
      ref = p->observations.begin()->first;
    const auto m = ref != nullptr ? moved.find(ref) : moved.end();
    if (m == moved.end()) continue;
    p->position = m->second.second.inverse() * (m->second.first * p->position);
  }
  for (auto& [kf, poses] : moved) const_cast<KeyFrame*>(kf)->cam_from_world = poses.second;
  for (const auto& [id, p] : map_.MapPoints()) {
    if (!p->bad) p->UpdateNormalAndDepth();
  }
  e.global_ba_merged = true;
  e.global_ba_merged_at_keyframe = at_keyframe;
  if (job->event) {
    spdlog::info("global BA after the loop at keyframe {}: {} keyframes, {} points, {:.0f} ms, "
                 "merged at keyframe {}",
                 e.query_keyframe, e.global_ba_keyframes, e.global_ba_points, e.global_ba_ms,
                 at_keyframe);
  } else {
    spdlog::info("global BA of the whole map (before a save, or at the end): {} keyframes, "
                 "{} points, {:.0f} ms",
                 job->keyframes.size(), job->points.size(), job->ms);
  }
  map_.NoteLoopCorrection();  // tracking follows its reference keyframe
}

void LoopClosing::Correct(KeyFrame& query, const Verified& loop, LoopEvent& event) {
  const Rigid3d query_before = query.cam_from_world;
  // 1. The query and its covisible keyframes move with the loop transform.
  std::vector<KeyFrame*> connected{&query};
  for (KeyFrame* kf : query.ordered_connections) {
    if (!kf->bad) connected.push_back(kf);
  }
  std::sort(connected.begin(), connected.end(), KeyFrameIdLess());
  std::map<const KeyFrame*, Sim3d, KeyFrameIdLess> old_pose, corrected_pose;
  const Sim3d query_corrected =
      loop.match_from_query.Inverse() * Sim3d::FromRigid(loop.match->cam_from_world);
  const Rigid3d world_from_query = query.cam_from_world.inverse();
  for (KeyFrame* kf : connected) {
    old_pose[kf] = Sim3d::FromRigid(kf->cam_from_world);
    corrected_pose[kf] = Sim3d::FromRigid(kf->cam_from_world * world_from_query) * query_corrected;
  }
  // Points seen by the connected keyframes follow the first of them that sees them; the
  // reference used is kept for the essential-graph update below.
  std::map<MapPoint*, const KeyFrame*> corrected_by;
  for (KeyFrame* kf : connected) {
    const Sim3d move = corrected_pose[kf].Inverse() * old_pose[kf];
    for (const auto& p : kf->map_points) {
      if (!p || p->bad || corrected_by.count(p.get())) continue;
      p->position = move * p->position;
      corrected_by[p.get()] = kf;
    }
  }
  // 2. Fusion: the loop's points replace the query's duplicates; the loop side's points are
  // fused into every connected keyframe.
  std::set<KeyFrame*, KeyFrameIdLess> neighbours_before(connected.begin(), connected.end());
  // Each connected keyframe's own covisible keyframes before the fusion: links to them are not
  // loop edges (ORB-SLAM removes them too). Counted as loop edges they were measured between a
  // corrected and an uncorrected pose and pulled the corrected side back towards the drift
  // (the keyframes just before the loop ended up worse than without closure).
  std::map<const KeyFrame*, std::set<const KeyFrame*>, KeyFrameIdLess> previous_neighbours;
  for (KeyFrame* kf : connected) {
    auto& set = previous_neighbours[kf];
    for (const auto& [other, w] : kf->connections) set.insert(other);
  }
  for (size_t i = 0; i < loop.matched.size(); ++i) {
    const std::shared_ptr<MapPoint> loop_point = MapPoint::Resolve(loop.matched[i]);
    if (!loop_point || loop_point->bad) continue;
    const std::shared_ptr<MapPoint> current = query.map_points[i];
    if (current && !current->bad) {
      if (current != loop_point) {
        map_.ReplacePoint(current.get(), loop_point);
        ++event.fused_points;
      }
    } else if (!loop_point->IsInKeyFrame(&query)) {
      query.AddMapPoint(loop_point, i);
      loop_point->AddObservation(&query, i);
      loop_point->ComputeDistinctiveDescriptor();
    }
  }
  for (KeyFrame* kf : connected) {
    kf->cam_from_world = corrected_pose[kf].ToRigid();
  }
  std::vector<std::shared_ptr<MapPoint>> loop_points;
  {
    std::set<const MapPoint*> seen;
    std::vector<KeyFrame*> place = loop.match->BestCovisibles(10);
    place.insert(place.begin(), loop.match);
    for (KeyFrame* kf : place) {
      for (const auto& p : kf->map_points) {
        if (p && !p->bad && seen.insert(p.get()).second) loop_points.push_back(p);
      }
    }
  }
  // Fuse works in metric keyframe coordinates: the keyframes' poses are their corrected rigid
  // part, and their points were moved into the same (corrected) world.
  const Matcher matcher(0.8f, false);
  for (KeyFrame* kf : connected) {
    if (kf->bad) continue;
    event.fused_points += matcher.Fuse(map_, *kf, loop_points, static_cast<float>(fuse_radius_));
  }
  // 3. Covisibility: the new links across the loop are the loop edges.
  for (KeyFrame* kf : connected) {
    if (kf->bad) continue;
    kf->UpdateConnections();
    for (const auto& [other, w] : kf->connections) {
      if (!neighbours_before.count(other) && !previous_neighbours[kf].count(other) &&
          !other->bad)
        loop_edges_.emplace_back(std::min(kf->id, other->id), std::max(kf->id, other->id));
    }
  }
  loop_edges_.emplace_back(std::min(query.id, loop.match->id), std::max(query.id, loop.match->id));

  // 4. Essential graph over every keyframe: spanning tree, strong covisibility, loop edges.
  // Relative measurements use the poses before this correction where there is one (ORB-SLAM).
  std::vector<KeyFrame*> vertices;
  std::map<uint64_t, size_t> vertex_of;
  for (const auto& [id, kf] : map_.KeyFrames()) {
    if (kf->bad) continue;
    vertex_of[id] = vertices.size();
    vertices.push_back(kf.get());
  }
  PoseGraphProblem graph;
  graph.fix_scale = !sim3_;
  graph.iterations = options_.pose_graph_iterations;
  std::vector<Sim3d> start(vertices.size());
  std::vector<Sim3d> measure_pose(vertices.size());
  for (size_t k = 0; k < vertices.size(); ++k) {
    KeyFrame* kf = vertices[k];
    const auto c = corrected_pose.find(kf);
    start[k] = c != corrected_pose.end() ? c->second : Sim3d::FromRigid(kf->cam_from_world);
    const auto o = old_pose.find(kf);
    measure_pose[k] = o != old_pose.end() ? o->second : start[k];
  }
  graph.cam_from_world = start;
  graph.fixed.assign(vertices.size(), false);
  // Edge information. Identity (ORB-SLAM) weighs a metre of translation like a radian of
  // rotation, so a loop's translation gap is closed almost only by bending and rescaling the
  // chain (cheap per edge, large at the end of a long lever): on the street ring a 0.58 m,
  // 0.6 deg loop turned the middle of the lap by 1.1 deg and moved it by 1.4 m. A
  // keyframe's relative pose is measured from image motion: a rotation error of e rad and a
  // translation error of e * Z m (Z the scene depth) shift the image alike, so the translation
  // residual is divided by the scene depth. Measured per edge against ground truth (street
  // ring: Z ~26 m, translation / rotation error 38 m/rad; office: Z ~2 m, 2.0 m/rad).
  const bool depth_weighted = options_.edge_information == "depth";
  std::vector<double> scene_depth;
  if (depth_weighted) scene_depth = SceneDepths(vertices);
  graph.fixed[vertex_of.at(loop.match->id)] = true;
  std::set<std::pair<size_t, size_t>> added;
  auto add_edge = [&](size_t i, size_t j, bool loop_edge) {
    if (i == j) return;
    const auto key = std::make_pair(std::min(i, j), std::max(i, j));
    if (!added.insert(key).second) return;
    const std::vector<Sim3d>& poses = loop_edge ? start : measure_pose;
    PoseGraphEdge edge{i, j, poses[i] * poses[j].Inverse()};
    if (depth_weighted) {
      // Translation in units of the two keyframes' scene depth, like the rotation in radians:
      // both are then the image displacement they cause (see where depth_weighted is set).
      const double z = 0.5 * (scene_depth[i] + scene_depth[j]);
      edge.sqrt_information.segment<3>(3).setConstant(1.0 / z);
    }
    graph.edges.push_back(edge);
  };
  for (const auto& [a, b] : loop_edges_) {
    const auto ia = vertex_of.find(a), ib = vertex_of.find(b);
    if (ia != vertex_of.end() && ib != vertex_of.end()) add_edge(ia->second, ib->second, true);
  }
  for (size_t k = 0; k < vertices.size(); ++k) {
    KeyFrame* kf = vertices[k];
    if (kf->parent != nullptr) {
      const auto ip = vertex_of.find(kf->parent->id);
      if (ip != vertex_of.end()) add_edge(k, ip->second, false);
    }
    for (const auto& [other, w] : kf->connections) {
      if (w < options_.strong_edge_weight || other->id > kf->id) continue;
      const auto io = vertex_of.find(other->id);
      if (io != vertex_of.end()) add_edge(k, io->second, false);
    }
  }
  const PoseGraphResult solved = SolvePoseGraph(graph);
  event.graph_keyframes = vertices.size();
  event.graph_edges = graph.edges.size();

  // 5. Points follow the keyframe that corrected them, or their reference keyframe.
  for (const auto& [id, p] : map_.MapPoints()) {
    if (p->bad) continue;
    const KeyFrame* ref = nullptr;
    const auto c = corrected_by.find(p.get());
    if (c != corrected_by.end() && !c->second->bad) {
      ref = c->second;
    } else if (p->reference != nullptr && !p->reference->bad) {
      ref = p->reference;
    } else if (!p->observations.empty()) {
      ref = p->observations.begin()->first;
    }
    if (ref == nullptr) continue;
    const auto v = vertex_of.find(ref->id);
    if (v == vertex_of.end()) continue;
    p->position = solved.cam_from_world[v->second].Inverse() * (start[v->second] * p->position);
  }
  for (size_t k = 0; k < vertices.size(); ++k) {
    KeyFrame* kf = vertices[k];
    const Sim3d& g = solved.cam_from_world[k];
    kf->cam_from_world = g.ToRigid();
    // A network depth prior is metric in the keyframe's camera: points there shrank by 1/s.
    if (kf->F().DepthIsPrior() && std::abs(g.scale - 1.0) > 1e-12) {
      kf->features = RescaleDepth(kf->F(), static_cast<float>(1.0 / g.scale));
      if (kf->network_fit.valid) kf->network_fit.Rescale(1.0 / g.scale);
    }
  }
  for (const auto& [id, p] : map_.MapPoints()) {
    if (!p->bad) p->UpdateNormalAndDepth();
  }
  event.correction_m = (query.CameraCenter() - query_before.inverse().translation()).norm();
  event.correction_deg = RotationDegrees(query_before.linear(), query.cam_from_world.linear());
  map_.NoteLoopCorrection();
}

}  // namespace ademono
