#include "ademono/eval/shared_error.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

namespace ademono {
namespace {

PoseSeries Path(size_t n) {
  PoseSeries s;
  for (size_t i = 0; i < n; ++i) {
    const double a = 0.1 * static_cast<double>(i);
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    m.topRightCorner<3, 1>() = Eigen::Vector3d(std::cos(a), std::sin(a), 0.3 * a);
    s.timestamps.push_back(0.1 * static_cast<double>(i));
    s.world_from_cam.push_back(m);
  }
  return s;
}

// The ground truth's path with `error(i)` added to each position.
template <typename F>
PoseSeries WithError(const PoseSeries& gt, F error) {
  PoseSeries s = gt;
  for (size_t i = 0; i < s.size(); ++i) s.world_from_cam[i].topRightCorner<3, 1>() += error(i);
  return s;
}

TEST(SharedErrorTest, SplitsTwoErrorsIntoWhatTheyShareAndWhatTheyDoNot) {
  const PoseSeries gt = Path(40);
  // A common error c (what the ground truth itself got wrong, say) and one of each run's own,
  // +d and -d: shared |c|, half the difference |d|.
  auto c = [](size_t i) { return Eigen::Vector3d(0.02, 0, i % 2 ? 0.01 : -0.01); };
  auto d = [](size_t i) { return Eigen::Vector3d(0, i % 4 < 2 ? 0.005 : -0.005, 0); };
  PoseSeries b = WithError(gt, [&](size_t i) {
    Eigen::Vector3d e = c(i) - d(i);
    return e;
  });
  // b lost frames 30-39: only the frames both matched count.
  b.timestamps.resize(30);
  b.world_from_cam.resize(30);
  EvalOptions options;
  options.alignment = Alignment::kNone;
  const EvalResult ra = EvaluateTrajectories(
      gt, WithError(gt, [&](size_t i) { return Eigen::Vector3d(c(i) + d(i)); }), options);
  const EvalResult rb = EvaluateTrajectories(gt, b, options);
  const SharedError s = ComputeSharedError(ra, rb);
  EXPECT_EQ(s.frames, 30u);
  const double cc = std::sqrt(0.02 * 0.02 + 0.01 * 0.01), dd = 0.005;
  EXPECT_NEAR(s.shared_rmse, cc, 1e-12);
  EXPECT_NEAR(s.half_difference_rmse, dd, 1e-12);
  EXPECT_NEAR(s.rmse_a, std::hypot(cc, dd), 1e-12);
  EXPECT_NEAR(s.rmse_b, std::hypot(cc, dd), 1e-12);
  EXPECT_NEAR(s.correlation, (cc * cc - dd * dd) / (cc * cc + dd * dd), 1e-12);
  EXPECT_EQ(s.ToJson()["frames"].get<size_t>(), 30u);
  // The same error twice: all shared; opposite errors: none.
  EXPECT_NEAR(ComputeSharedError(ra, ra).correlation, 1.0, 1e-12);
  EXPECT_NEAR(ComputeSharedError(ra, ra).half_difference_rmse, 0.0, 1e-15);
  const EvalResult opposite = EvaluateTrajectories(
      gt, WithError(gt, [&](size_t i) { return Eigen::Vector3d(-c(i) - d(i)); }), options);
  EXPECT_NEAR(ComputeSharedError(ra, opposite).shared_rmse, 0.0, 1e-15);
  EXPECT_NEAR(ComputeSharedError(ra, opposite).correlation, -1.0, 1e-12);
}

TEST(SharedErrorTest, EachEstimateKeepsItsOwnAlignment) {
  const PoseSeries gt = Path(40);
  EvalOptions options;
  options.alignment = Alignment::kSim3;
  // b is the same as a up to a similarity: after their alignments, the same errors.
  auto e = [](size_t i) {
    return Eigen::Vector3d(0.01 * std::sin(i), 0.01 * std::cos(3.0 * i), 0);
  };
  const PoseSeries a = WithError(gt, e);
  PoseSeries b = a;
  for (Eigen::Matrix4d& m : b.world_from_cam)
    m.topRightCorner<3, 1>() = 2.5 * m.topRightCorner<3, 1>() + Eigen::Vector3d(1, 2, 3);
  const SharedError s = ComputeSharedError(EvaluateTrajectories(gt, a, options),
                                           EvaluateTrajectories(gt, b, options));
  EXPECT_NEAR(s.correlation, 1.0, 1e-9);
  EXPECT_NEAR(s.rmse_a, s.rmse_b, 1e-9);
}

TEST(SharedErrorTest, TooFewFramesInCommonAreRefused) {
  const PoseSeries gt = Path(10);
  EvalOptions options;
  options.alignment = Alignment::kNone;
  PoseSeries a = gt;
  a.timestamps.resize(2);
  a.world_from_cam.resize(2);
  const EvalResult ra = EvaluateTrajectories(gt, a, options);
  EXPECT_THROW(ComputeSharedError(ra, ra), std::invalid_argument);
}

}  // namespace
}  // namespace ademono
