#include "ademono/io/trajectory.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include "ademono/core/error.h"
#include "ademono/io/timed_poses.h"
#include "io_test_util.h"

namespace fs = std::filesystem;

namespace ademono {
namespace {

using ::testing::HasSubstr;
using testing::MakeTempDir;
using testing::WriteText;

Trajectory SampleTrajectory() {
  Trajectory t;
  for (int i = 0; i < 5; ++i) {
    StampedPose p;
    p.timestamp = 1305031102.0 + 0.033 * i;
    p.world_from_cam = MakeRigid3d(
        Eigen::Quaterniond(Eigen::AngleAxisd(0.1 * i, Eigen::Vector3d(0.3, 1, 0.2).normalized())),
        Eigen::Vector3d(0.5 * i, -0.25 * i, 1.0 + i));
    t.push_back(p);
  }
  return t;
}

void ExpectSame(const Trajectory& a, const Trajectory& b, bool timestamps) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    if (timestamps) {
      EXPECT_NEAR(a[i].timestamp, b[i].timestamp, 1e-6);
    }
    EXPECT_TRUE(a[i].world_from_cam.isApprox(b[i].world_from_cam, 1e-8)) << i;
  }
}

TEST(TrajectoryTest, RoundTripsAllFormats) {
  const fs::path dir = MakeTempDir();
  const Trajectory t = SampleTrajectory();
  WriteTrajectory(dir / "a.tum", t, TrajectoryFormat::kTum);
  ExpectSame(t, ReadTrajectory(dir / "a.tum", ParseTrajectoryFormat("tum")), true);
  WriteTrajectory(dir / "a.kitti", t, TrajectoryFormat::kKitti);
  const Trajectory k = ReadTrajectory(dir / "a.kitti", ParseTrajectoryFormat("kitti"));
  ExpectSame(t, k, false);
  EXPECT_EQ(k[3].timestamp, 3.0);
  WriteTrajectory(dir / "a.csv", t, TrajectoryFormat::kEuroc);
  ExpectSame(t, ReadTrajectory(dir / "a.csv", ParseTrajectoryFormat("euroc")), true);
  EXPECT_THROW(ParseTrajectoryFormat("bag"), std::invalid_argument);
}

TEST(TrajectoryTest, ReadsTumWithCommentsAndNormalisesQuaternion) {
  const fs::path dir = MakeTempDir();
  WriteText(dir / "t.txt", "# header\n\n1.0 1 2 3 0 0 0 2\n2.0 1 2 3 0 0 1 1\n");
  const Trajectory t = ReadTumTrajectory(dir / "t.txt");
  ASSERT_EQ(t.size(), 2u);
  EXPECT_TRUE(t[0].world_from_cam.linear().isApprox(Eigen::Matrix3d::Identity()));
  EXPECT_NEAR(RotationAngle(t[1].world_from_cam.linear()), M_PI / 2, 1e-12);
  EXPECT_EQ(t[1].world_from_cam.translation(), Eigen::Vector3d(1, 2, 3));
}

TEST(TrajectoryTest, RejectsMalformedLinesWithFileAndLine) {
  const fs::path dir = MakeTempDir();
  struct Case {
    std::string text;
    TrajectoryFormat format;
    std::string expected;
  };
  const std::vector<Case> cases = {
      {"1 2 3 4 0 0 0 1\n1 2 3\n", TrajectoryFormat::kTum, ":2: expected 8 fields, found 3"},
      {"1 2 3 4 0 0 0 x\n", TrajectoryFormat::kTum, ":1: field 8 'x' is not a finite number"},
      {"1 2 nan 4 0 0 0 1\n", TrajectoryFormat::kTum, ":1: field 3 'nan'"},
      {"1 2 3 4 0 0 0 0\n", TrajectoryFormat::kTum, ":1: quaternion has zero norm"},
      {"1 0 0 0 0 1 0 0 0 0 1\n", TrajectoryFormat::kKitti, ":1: expected 12 fields, found 11"},
      {"0 0 0 0 0 0 0 0 0 0 0 0\n", TrajectoryFormat::kKitti, ":1: rotation part is singular"},
      {"# only comments\n", TrajectoryFormat::kTum, "trajectory file has no poses"},
      {"100,1,2,3,1,0,0\n", TrajectoryFormat::kEuroc, ":1: expected at least 8 fields"},
  };
  for (const Case& c : cases) {
    WriteText(dir / "bad.txt", c.text);
    try {
      ReadTrajectory(dir / "bad.txt", c.format);
      ADD_FAILURE() << "no error for: " << c.text;
    } catch (const InputError& e) {
      EXPECT_THAT(e.what(), HasSubstr((dir / "bad.txt").string())) << c.text;
      EXPECT_THAT(e.what(), HasSubstr(c.expected)) << c.text;
    }
  }
  EXPECT_THROW(ReadTumTrajectory(dir / "missing.txt"), InputError);
}

TEST(TrajectoryTest, WriterLeavesNoFileWhenTheDirectoryCannotBeCreated) {
  const fs::path dir = MakeTempDir();
  WriteText(dir / "file", "x");
  EXPECT_THROW(WriteTumTrajectory(dir / "file" / "sub" / "t.txt", SampleTrajectory()), InputError);
  EXPECT_FALSE(fs::exists(dir / "file" / "sub"));
}

TEST(TimedPosesTest, AssociatesGreedilyBySmallestDifferenceLikeAssociatePy) {
  // 1.000 could pair with 1.005 or 0.998; 0.998 is closer. 1.005 then pairs with 1.010 (0.005),
  // and 2.0 has no partner within 0.02.
  const std::vector<double> a = {1.000, 1.010, 2.0};
  const std::vector<double> b = {0.998, 1.005, 3.0};
  const auto m = AssociateTimestamps(a, b, 0.02);
  ASSERT_EQ(m.size(), 2u);
  EXPECT_EQ(m[0], std::make_pair(size_t{0}, size_t{0}));
  EXPECT_EQ(m[1], std::make_pair(size_t{1}, size_t{1}));
  EXPECT_TRUE(AssociateTimestamps(a, {5.0}, 0.02).empty());
}

TEST(TimedPosesTest, InterpolatesInsideSmallGapsAndFallsBackToNearest) {
  Trajectory t(3);
  t[0].timestamp = 0.0;
  t[1].timestamp = 0.1;
  t[2].timestamp = 1.0;  // a 0.9 s gap: not bridged
  t[1].world_from_cam.translation() = Eigen::Vector3d(1, 0, 0);
  t[1].world_from_cam.linear() = ExpSO3(Eigen::Vector3d(0, 0, 0.2));
  t[2].world_from_cam.translation() = Eigen::Vector3d(5, 0, 0);

  const auto mid = LookupPose(t, 0.025);
  ASSERT_TRUE(mid.has_value());
  EXPECT_NEAR(mid->translation().x(), 0.25, 1e-12);
  EXPECT_NEAR(RotationAngle(mid->linear()), 0.05, 1e-12);

  const auto near_end = LookupPose(t, 0.115);  // inside the big gap, 0.015 from t[1]
  ASSERT_TRUE(near_end.has_value());
  EXPECT_NEAR(near_end->translation().x(), 1.0, 1e-12);
  EXPECT_FALSE(LookupPose(t, 0.5).has_value());
  EXPECT_FALSE(LookupPose(t, -0.05).has_value());
  EXPECT_TRUE(LookupPose(t, -0.01).has_value());
  EXPECT_TRUE(LookupPose(t, 1.0).has_value());
}

}  // namespace
}  // namespace ademono
