#pragma once
// The first map of a monocular run without depth (ORB-SLAM's MonocularInitialization and
// CreateInitialMapMonocular): a reference frame is kept, each new frame is matched with it
// (Matcher::SearchForInitialization, windows that follow the matches from frame to frame) and
// handed to the two-view initialiser (initializer/two_view); once it finds a clear motion with
// enough parallax, both frames become keyframes, the triangulated matches map points, a bundle
// adjustment of the two refines them, and the map is scaled so that the first keyframe's median
// scene depth is 1. Too few matches replace the reference frame by the current one.

#include <memory>
#include <optional>
#include <vector>

#include "ademono/initializer/two_view.h"
#include "ademono/slam/frame.h"
#include "ademono/slam/map.h"
#include "ademono/slam/options.h"

namespace ademono {

class MonocularInitialization {
 public:
  explicit MonocularInitialization(const SystemOptions& options) : options_(options) {}

  struct Keyframes {
    std::shared_ptr<KeyFrame> first, second;  // the reference frame's and the current frame's
  };
  // `frame` (no pose yet): made the reference, or matched with it. When the map is made, `frame`
  // gets its pose and its map points and both keyframes are returned (registered: observations
  // and covisibility set; the second still goes through local mapping).
  std::optional<Keyframes> Add(Frame& frame, Map& map) ADEMONO_REQUIRES(map.mutex);
  void Reset() { reference_.reset(); }
  bool HasReference() const { return reference_.has_value(); }
  // The last attempt's two-view result (for the log and tests).
  const TwoViewResult& LastResult() const { return last_; }

 private:
  SystemOptions options_;
  std::optional<Frame> reference_;
  std::vector<cv::Point2f> prev_matched_;
  TwoViewResult last_;
};

}  // namespace ademono
