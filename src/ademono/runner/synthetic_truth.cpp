#include "ademono/runner/synthetic_truth.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>

#include "ademono/core/error.h"
#include "ademono/core/file_util.h"

namespace fs = std::filesystem;

namespace ademono {

nlohmann::json TruthCounts::ToJson() const {
  auto ratio = [](long long a, long long b) {
    return b > 0 ? nlohmann::json(static_cast<double>(a) / b) : nlohmann::json(nullptr);
  };
  auto states = [](const StateCounts& c) {
    return nlohmann::json{{"unmatched", c[0]},
                          {"pose_inlier", c[1]},
                          {"pose_outlier", c[2]},
                          {"unconfirmed", c[3]},
                          {"judged_moving", c[4]}};
  };
  return {{"moving_keypoints", moving_keypoints},
          {"moving_removed", moving_removed},
          {"moving_kept", moving_kept},
          {"moving_removed_ratio", ratio(moving_removed, moving_keypoints)},
          {"moving_unboxed_keypoints", moving_unboxed_keypoints},
          {"moving_unboxed_removed", moving_unboxed_removed},
          {"moving_unboxed_removed_ratio", ratio(moving_unboxed_removed, moving_unboxed_keypoints)},
          {"static_keypoints", static_keypoints},
          {"static_removed", static_removed},
          {"static_removed_ratio", ratio(static_removed, static_keypoints)},
          {"static_person_keypoints", static_person_keypoints},
          {"static_person_removed", static_person_removed},
          {"static_person_removed_ratio", ratio(static_person_removed, static_person_keypoints)},
          {"static_in_box_keypoints", static_in_box_keypoints},
          {"static_in_box_removed", static_in_box_removed},
          {"static_in_box_removed_ratio", ratio(static_in_box_removed, static_in_box_keypoints)},
          {"static_removed_by",
           {{"small_box", static_removed_small_box},
            {"stage1", static_removed_stage1},
            {"stage2", static_removed_stage2},
            {"box_vote", static_removed_box_vote},
            {"geometric_unconfirmed", static_removed_unconfirmed},
            {"geometric_judged_moving", static_removed_judged_moving}}},
          {"static_kept_by_state", states(static_kept_by_state)},
          {"moving_kept_by_state", states(moving_kept_by_state)},
          {"moving_not_removed_at_edge", moving_not_removed_at_edge},
          {"moving_not_removed_unboxed", moving_not_removed_unboxed},
          {"static_at_mover_edge_keypoints", static_at_mover_edge_keypoints},
          {"static_at_mover_edge_removed", static_at_mover_edge_removed},
          {"moving_removed_geometric", moving_removed_geometric},
          {"moving_pose_inliers", moving_pose_inliers},
          {"moving_new_points", moving_new_points},
          {"moving_new_points_admitted", moving_new_points_admitted},
          {"moving_entered", MovingEntered()},
          {"moving_kept_out", moving_keypoints - MovingEntered()},
          {"moving_kept_out_ratio", ratio(moving_keypoints - MovingEntered(), moving_keypoints)},
          {"static_new_points", static_new_points},
          {"static_new_points_judged_out", static_new_points_judged_out},
          {"static_new_points_unconfirmed", static_new_points_unconfirmed},
          {"static_kept_out", static_kept_out},
          {"static_kept_out_ratio", ratio(static_kept_out, static_keypoints)}};
}

SyntheticTruth::SyntheticTruth(const fs::path& sequence_dir) : masks_dir_(sequence_dir / "masks") {
  available_ = fs::is_directory(masks_dir_);
}

namespace {

cv::Point Pixel(const cv::KeyPoint& kp, const cv::Size& size) {
  return {std::clamp(static_cast<int>(std::lround(kp.pt.x)), 0, size.width - 1),
          std::clamp(static_cast<int>(std::lround(kp.pt.y)), 0, size.height - 1)};
}

}  // namespace

void SyntheticTruth::Score(const FrameData& frame, const std::vector<Detection>& detections,
                           const std::vector<cv::KeyPoint>& keypoints,
                           const std::vector<PointLabel>& labels, TruthCounts* counts,
                           const std::vector<MatchState>* match_state,
                           const std::vector<std::pair<size_t, std::shared_ptr<const MapPoint>>>*
                               created,
                           std::vector<PendingPoint>* pending) const {
  const fs::path path = masks_dir_ / (frame.name + ".png");
  const cv::Mat mask = ReadImage(path, cv::IMREAD_GRAYSCALE);  // InputError naming the file
  if (!frame.image.empty() && mask.size() != frame.image.size())
    ThrowInputError(path, "mask size differs from the image size");
  // The static person: the person box with the fewest moving pixels, if under 20%.
  std::optional<cv::Rect> static_box;
  double best = 0.2;
  const cv::Rect bounds(0, 0, mask.cols, mask.rows);
  for (const Detection& d : detections) {
    if (d.class_id != 0) continue;
    const cv::Rect box = cv::Rect(d.box) & bounds;
    if (box.area() == 0) continue;
    const double moving = cv::countNonZero(mask(box) > 127) / static_cast<double>(box.area());
    if (moving < best) {
      best = moving;
      static_box = box;
    }
  }
  cv::Mat near_mover, near_static;  // moving (static) pixels grown by 2 px
  const cv::Mat kernel = cv::getStructuringElement(cv::MORPH_RECT, cv::Size(5, 5));
  cv::dilate(mask > 127, near_mover, kernel);
  cv::dilate(mask <= 127, near_static, kernel);
  std::vector<const std::shared_ptr<const MapPoint>*> created_by(keypoints.size(), nullptr);
  if (created != nullptr) {
    for (const auto& [i, point] : *created) {
      if (i < created_by.size()) created_by[i] = &point;
    }
  }
  for (size_t i = 0; i < keypoints.size() && i < labels.size(); ++i) {
    const cv::Point p = Pixel(keypoints[i], mask.size());
    // Only keypoints the dynamic filter judged: enhancement drops happen before it.
    if (labels[i] == PointLabel::kEnhancementDropped) continue;
    const MatchState state = match_state && i < match_state->size() ? (*match_state)[i]
                                                                     : MatchState::kUnmatched;
    const bool geometric =
        state == MatchState::kUnconfirmed || state == MatchState::kJudgedMoving;
    const bool dynamic = IsDynamic(labels[i]) || geometric;
    const auto state_index = static_cast<size_t>(state);
    const auto& classes = DefaultDynamicClassIds();
    const bool in_box = std::any_of(detections.begin(), detections.end(), [&](const Detection& d) {
      return std::find(classes.begin(), classes.end(), d.class_id) != classes.end() &&
             d.box.contains(cv::Point2f(static_cast<float>(p.x), static_cast<float>(p.y)));
    });
    const bool geometric_only = dynamic && !IsDynamic(labels[i]);
    const bool moving = mask.at<uint8_t>(p) > 127;
    if (moving) {
      if (state == MatchState::kPoseInlier) ++counts->moving_pose_inliers;
    } else {
      if (dynamic) ++counts->static_kept_out;
    }
    if (created_by[i] != nullptr && pending != nullptr) {
      (moving ? counts->moving_new_points : counts->static_new_points) += 1;
      pending->push_back({moving, dynamic, *created_by[i]});
    }
    if (moving) {
      ++counts->moving_keypoints;
      if (dynamic) ++counts->moving_removed;
      if (geometric_only) ++counts->moving_removed_geometric;
      if (labels[i] == PointLabel::kKept) {
        ++counts->moving_kept;
        ++counts->moving_kept_by_state[state_index];
      }
      if (!in_box) {
        ++counts->moving_unboxed_keypoints;
        if (dynamic) ++counts->moving_unboxed_removed;
      }
      if (!dynamic) {
        if (near_static.at<uint8_t>(p) != 0) ++counts->moving_not_removed_at_edge;
        if (!in_box) ++counts->moving_not_removed_unboxed;
      }
    } else {
      ++counts->static_keypoints;
      if (dynamic) ++counts->static_removed;
      if (labels[i] == PointLabel::kKept) ++counts->static_kept_by_state[state_index];
      if (geometric_only && state == MatchState::kUnconfirmed) ++counts->static_removed_unconfirmed;
      if (geometric_only && state == MatchState::kJudgedMoving)
        ++counts->static_removed_judged_moving;
      if (near_mover.at<uint8_t>(p) != 0) {
        ++counts->static_at_mover_edge_keypoints;
        if (dynamic) ++counts->static_at_mover_edge_removed;
      }
      switch (labels[i]) {
        case PointLabel::kDynamicSmallBox: ++counts->static_removed_small_box; break;
        case PointLabel::kDynamicStage1: ++counts->static_removed_stage1; break;
        case PointLabel::kDynamicStage2: ++counts->static_removed_stage2; break;
        case PointLabel::kDynamicBoxVote: ++counts->static_removed_box_vote; break;
        default: break;
      }
      if (static_box && static_box->contains(p)) {
        ++counts->static_person_keypoints;
        if (dynamic) ++counts->static_person_removed;
      }
      if (in_box) {
        ++counts->static_in_box_keypoints;
        if (dynamic) ++counts->static_in_box_removed;
      }
    }
  }
}

void SyntheticTruth::Resolve(const std::vector<PendingPoint>& pending, TruthCounts* counts) {
  for (const PendingPoint& p : pending) {
    bool admitted = false;
    // Fusion may have replaced the point; its keypoint's view went to the replacement.
    for (const MapPoint* q = p.point.get(); q != nullptr && !admitted; q = q->replaced_by.get())
      admitted = q->admitted;
    if (p.moving) {
      if (admitted) ++counts->moving_new_points_admitted;
    } else if (!admitted) {
      if (p.point->motion_verdicts > 0) {
        ++counts->static_new_points_judged_out;
        if (!p.already_removed) ++counts->static_kept_out;
      } else {
        ++counts->static_new_points_unconfirmed;
      }
    }
  }
}

}  // namespace ademono
