// The trajectory formats the field writes reproduce the published evo and kitti-odom-eval results
// (../shared/data/trajectories/expected.json): kitti-odom-eval's indexed KITTI files (with and
// without skipped indices), TUM files with comments, ORB-SLAM's KeyFrameTrajectory.txt and the
// EuRoC ground-truth CSV.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "ademono/core/error.h"
#include "ademono/core/file_util.h"
#include "ademono/eval/trajectory_eval.h"

namespace fs = std::filesystem;

namespace ademono {
namespace {

const fs::path kTrajectories = fs::path(ADEMONO_SHARED_DIR) / "data" / "trajectories";
constexpr double kPrinted = 5e-4 + 1e-9;  // kitti-odom-eval prints 3 decimals

class FileFormatsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::exists(kTrajectories / "expected.json")) GTEST_SKIP() << "no shared data";
    dir_ = fs::temp_directory_path() /
           ("ademono_formats_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
    std::ifstream in(kTrajectories / "expected.json");
    expected_ = nlohmann::json::parse(in);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }

  // Rewrites a plain KITTI file in kitti-odom-eval's indexed form, keeping every number's text,
  // and only the lines whose index `keep` accepts.
  template <typename Keep>
  fs::path WriteIndexed(const fs::path& plain, const std::string& name, Keep keep) {
    std::ifstream in(plain);
    std::ofstream out(dir_ / name);
    std::string line;
    for (int64_t index = 0; std::getline(in, line); ++index) {
      if (keep(index)) out << index << " " << line << "\n";
    }
    return dir_ / name;
  }

  fs::path dir_;
  nlohmann::json expected_;
};

EvalOptions IndexOptions(KittiAlignment alignment) {
  EvalOptions options;
  options.associate_by_timestamp = false;
  options.associate_by_frame_index = true;
  options.alignment = Alignment::kNone;
  options.kitti_metrics = true;
  options.kitti_alignment = alignment;
  return options;
}

TEST_F(FileFormatsTest, IndexedKittiReproducesKittiOdomEvalForEveryAlignment) {
  for (const std::string seq : {"09", "10"}) {
    const fs::path plain = kTrajectories / "kitti-odom-eval" / "example_1" / (seq + ".txt");
    const fs::path indexed = WriteIndexed(plain, seq + ".txt", [](int64_t) { return true; });
    EXPECT_EQ(DetectTrajectoryFormat(indexed), TrajectoryFormat::kKittiIndexed);
    EXPECT_EQ(DetectTrajectoryFormat(plain), TrajectoryFormat::kKitti);
    const PoseSeries gt = ReadPoseSeries(kTrajectories / "kitti-odom-eval" / "gt" / (seq + ".txt"),
                                         TrajectoryFormat::kKitti);
    // "kitti" reads either form, as kitti-odom-eval's loader does.
    const PoseSeries est = ReadPoseSeries(indexed, TrajectoryFormat::kKitti);
    EXPECT_EQ(est.format, TrajectoryFormat::kKittiIndexed);
    const PoseSeries est_plain = ReadPoseSeries(plain, TrajectoryFormat::kKitti);
    ASSERT_EQ(est.size(), est_plain.size());
    for (const auto& [name, values] : expected_["kitti_odom_eval"]["example_1"].items()) {
      SCOPED_TRACE(seq + " " + name);
      const KittiAlignment alignment = ParseKittiAlignment(name);
      const EvalResult r = EvaluateTrajectories(gt, est, IndexOptions(alignment));
      const auto& v = values[seq];
      ASSERT_TRUE(r.kitti.has_value());
      EXPECT_NEAR(r.kitti->t_rel_percent, v["t_rel_percent"].get<double>(), kPrinted);
      EXPECT_NEAR(r.kitti->r_rel_deg_per_100m, v["r_rel_deg_per_100m"].get<double>(), kPrinted);
      EXPECT_NEAR(r.kitti->ate_m, v["ate_m"].get<double>(), kPrinted);
      EXPECT_NEAR(r.kitti->rpe_m, v["rpe_m"].get<double>(), kPrinted);
      EXPECT_NEAR(r.kitti->rpe_deg, v["rpe_deg"].get<double>(), kPrinted);
      // Bit for bit what the plain file gives.
      const KittiOdometryResult p =
          EvaluateKittiOdometry(gt.world_from_cam, est_plain.world_from_cam, alignment);
      EXPECT_EQ(r.kitti->t_rel_percent, p.t_rel_percent);
      EXPECT_EQ(r.kitti->ate_m, p.ate_m);
      EXPECT_EQ(r.kitti->rpe_deg, p.rpe_deg);
      EXPECT_EQ(r.kitti->segments, p.segments);
      EXPECT_EQ(r.matched_poses, gt.size());
    }
  }
}

TEST_F(FileFormatsTest, SkippedIndicesAssociateByIndex) {
  const std::string seq = "09";
  const PoseSeries gt = ReadPoseSeries(kTrajectories / "kitti-odom-eval" / "gt" / (seq + ".txt"),
                                       TrajectoryFormat::kKitti);
  const fs::path plain = kTrajectories / "kitti-odom-eval" / "example_1" / (seq + ".txt");
  // The frames kitti-odom-eval's sub-sequences start and end at: every 10th frame, and for each
  // the first frame more than 100, 200, ..., 800 m further along the ground truth.
  const size_t n = gt.size();
  std::vector<double> dist(n, 0.0);
  for (size_t i = 1; i < n; ++i) {
    dist[i] = dist[i - 1] + (gt.world_from_cam[i].topRightCorner<3, 1>() -
                             gt.world_from_cam[i - 1].topRightCorner<3, 1>())
                                .norm();
  }
  std::set<int64_t> ends;
  for (size_t first = 0; first < n; first += 10) {
    ends.insert(static_cast<int64_t>(first));
    for (double length = 100; length <= 800; length += 100) {
      for (size_t i = first; i < n; ++i) {
        if (dist[i] > dist[first] + length) {
          ends.insert(static_cast<int64_t>(i));
          break;
        }
      }
    }
  }
  // Leave out half of the other frames (452 of 1591): same segments, so t_rel and r_rel stay the
  // published values for the alignments that do not depend on the other frames (none, and 6dof,
  // which moves the estimate rigidly).
  const fs::path skipping =
      WriteIndexed(plain, "skip.txt", [&](int64_t i) { return ends.count(i) > 0 || i % 10 < 5; });
  const PoseSeries est = ReadPoseSeries(skipping, TrajectoryFormat::kKittiIndexed);
  ASSERT_EQ(est.size(), 1139u);
  for (const std::string name : {"none", "6dof"}) {
    SCOPED_TRACE(name);
    const auto& v = expected_["kitti_odom_eval"]["example_1"][name][seq];
    const EvalResult r = EvaluateTrajectories(gt, est, IndexOptions(ParseKittiAlignment(name)));
    EXPECT_EQ(r.matched_poses, est.size());
    EXPECT_NEAR(r.kitti->t_rel_percent, v["t_rel_percent"].get<double>(), kPrinted);
    EXPECT_NEAR(r.kitti->r_rel_deg_per_100m, v["r_rel_deg_per_100m"].get<double>(), kPrinted);
    const KittiOdometryResult dense = EvaluateKittiOdometry(
        gt.world_from_cam, ReadPoseSeries(plain, TrajectoryFormat::kKitti).world_from_cam,
        ParseKittiAlignment(name));
    EXPECT_EQ(r.kitti->segments, dense.segments);
    // Frame-to-frame RPE over the pairs (i, i + 1) both estimated: about the same mean.
    EXPECT_NEAR(r.kitti->rpe_m, dense.rpe_m, 0.01);
    // The APE pairs are the estimated frames with their own ground-truth frames.
    for (size_t k = 0; k < r.matched_poses; ++k) {
      ASSERT_EQ(r.gt_matched.timestamps[k], r.est_aligned.timestamps[k]);
    }
  }
  // Without frame 10, the sub-sequences starting there are gone.
  const fs::path no_ten = WriteIndexed(plain, "no10.txt", [&](int64_t i) { return i != 10; });
  const EvalResult r = EvaluateTrajectories(gt, ReadPoseSeries(no_ten, TrajectoryFormat::kKitti),
                                            IndexOptions(KittiAlignment::kNone));
  const EvalResult full = EvaluateTrajectories(gt, ReadPoseSeries(plain, TrajectoryFormat::kKitti),
                                               IndexOptions(KittiAlignment::kNone));
  EXPECT_EQ(r.kitti->segments + 8, full.kitti->segments);
}

TEST_F(FileFormatsTest, IndexedKittiErrorsNameTheLine) {
  const fs::path gt_path = kTrajectories / "kitti-odom-eval" / "gt" / "10.txt";
  const std::string row = "1 0 0 0 0 1 0 0 0 0 1 0";
  const std::pair<std::string, std::string> cases[] = {
      {"0 " + row + "\n0 " + row + "\n", ":2: frame index 0 already on line 1"},
      {"0 " + row + "\n1.5 " + row + "\n", ":2: frame index '1.5' is not a whole number >= 0"},
      {"-1 " + row + "\n", ":1: frame index '-1' is not a whole number >= 0"},
      {"0 " + row + "\n" + row + "\n",
       ":2: expected 13 fields (frame index and 12 pose values), "
       "found 12"},
      {"0 " + row + " 7\n",
       ":1: cannot tell the trajectory format from 14 fields (TUM has 8, "
       "KITTI 12, indexed KITTI 13, EuRoC is CSV)"},
  };
  for (const auto& [text, message] : cases) {
    SCOPED_TRACE(text);
    const fs::path bad = dir_ / "bad.txt";
    std::ofstream(bad) << text;
    try {
      const TrajectoryFormat format = DetectTrajectoryFormat(bad);
      ReadPoseSeries(bad, format);
      ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()), bad.string() + message);
    }
  }
  // An estimated frame the ground truth does not have.
  const fs::path beyond = dir_ / "beyond.txt";
  std::ofstream(beyond) << "0 " << row << "\n1 " << row << "\n5000 " << row << "\n";
  EXPECT_THROW(
      {
        try {
          EvaluateTrajectories(ReadPoseSeries(gt_path, TrajectoryFormat::kKitti),
                               ReadPoseSeries(beyond, TrajectoryFormat::kKitti),
                               IndexOptions(KittiAlignment::kNone));
        } catch (const std::invalid_argument& e) {
          EXPECT_STREQ(e.what(), "estimate frame index 5000 has no ground-truth pose");
          throw;
        }
      },
      std::invalid_argument);
}

void ExpectApeSe3(const EvalResult& r, const nlohmann::json& e) {
  EXPECT_NEAR(r.ape.rmse, e["ape_se3"]["rmse"].get<double>(),
              1e-6 * e["ape_se3"]["rmse"].get<double>());
  EXPECT_NEAR(r.ape.max, e["ape_se3"]["max"].get<double>(),
              1e-6 * e["ape_se3"]["max"].get<double>());
  EXPECT_NEAR(r.rpe_trans.mean, e["rpe_trans_1frame"]["mean"].get<double>(),
              1e-6 * e["rpe_trans_1frame"]["mean"].get<double>());
  EXPECT_NEAR(r.rpe_rot_deg.rmse, e["rpe_rot_deg_1frame"]["rmse"].get<double>(),
              1e-6 * e["rpe_rot_deg_1frame"]["rmse"].get<double>());
}

TEST_F(FileFormatsTest, TumWithCommentsAndOrbSlamKeyFrameTrajectory) {
  // Comments in the header, between poses and at the end, blank lines, CRLF-free TUM text.
  std::ifstream in(kTrajectories / "evo" / "freiburg1_xyz-rgbdslam.txt");
  const fs::path commented = dir_ / "commented.txt";
  {
    std::ofstream out(commented);
    out << "# estimated trajectory\n# timestamp tx ty tz qx qy qz qw\n\n";
    std::string line;
    for (int i = 0; std::getline(in, line); ++i) {
      out << line << "\n";
      if (i % 100 == 50) out << "# relocalised here\n\n";
    }
    out << "# end\n";
  }
  EXPECT_EQ(DetectTrajectoryFormat(commented), TrajectoryFormat::kTum);
  const PoseSeries gt = ReadPoseSeries(kTrajectories / "evo" / "freiburg1_xyz-groundtruth.txt",
                                       TrajectoryFormat::kTum);
  ExpectApeSe3(EvaluateTrajectories(gt, ReadPoseSeries(commented, TrajectoryFormat::kTum), {}),
               expected_["evo"]["fr1_xyz_rgbdslam"]);

  // ORB-SLAM writes KeyFrameTrajectory.txt in TUM layout: "orbslam" names it.
  const fs::path kf = dir_ / "KeyFrameTrajectory.txt";
  fs::copy_file(kTrajectories / "evo" / "fr2_desk_ORB.txt", kf);
  EXPECT_EQ(DetectTrajectoryFormat(kf), TrajectoryFormat::kTum);
  EXPECT_EQ(ParseTrajectoryFormat("orbslam"), TrajectoryFormat::kTum);
  const PoseSeries desk_gt =
      ReadPoseSeries(kTrajectories / "evo" / "fr2_desk_groundtruth.txt", TrajectoryFormat::kTum);
  ExpectApeSe3(
      EvaluateTrajectories(desk_gt, ReadPoseSeries(kf, ParseTrajectoryFormat("orbslam")), {}),
      expected_["evo"]["fr2_desk_orb"]);
}

TEST_F(FileFormatsTest, EurocGroundTruthCsvBuiltFromTum) {
  // The TUM ground truth rewritten as EuRoC's state_groundtruth_estimate0/data.csv: integer
  // nanoseconds (exact decimal shift of the text), quaternion w first, then velocity and biases.
  std::ifstream in(kTrajectories / "evo" / "freiburg1_xyz-groundtruth.txt");
  const fs::path csv = dir_ / "data.csv";
  {
    std::ofstream out(csv);
    out << "#timestamp [ns], p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], "
           "q_RS_y [], q_RS_z [], v_RS_R_x [m s^-1], v_RS_R_y [m s^-1], v_RS_R_z [m s^-1], "
           "b_w_RS_S_x [rad s^-1], b_w_RS_S_y [rad s^-1], b_w_RS_S_z [rad s^-1], "
           "b_a_RS_S_x [m s^-2], b_a_RS_S_y [m s^-2], b_a_RS_S_z [m s^-2]\n";
    std::string line;
    while (std::getline(in, line)) {
      if (line.empty() || line[0] == '#') continue;
      std::istringstream fields(line);
      std::string t, x, y, z, qx, qy, qz, qw;
      fields >> t >> x >> y >> z >> qx >> qy >> qz >> qw;
      const size_t dot = t.find('.');
      std::string frac = dot == std::string::npos ? "" : t.substr(dot + 1);
      frac.resize(9, '0');
      const std::string ns = t.substr(0, dot) + frac;
      out << ns << "," << x << "," << y << "," << z << "," << qw << "," << qx << "," << qy << ","
          << qz << ",0.1,0.2,0.3,0,0,0,0,0,0\n";
    }
  }
  EXPECT_EQ(DetectTrajectoryFormat(csv), TrajectoryFormat::kEuroc);
  const PoseSeries gt = ReadPoseSeries(csv, TrajectoryFormat::kEuroc);
  const PoseSeries est =
      ReadPoseSeries(kTrajectories / "evo" / "freiburg1_xyz-rgbdslam.txt", TrajectoryFormat::kTum);
  ExpectApeSe3(EvaluateTrajectories(gt, est, {}), expected_["evo"]["fr1_xyz_rgbdslam"]);
}

}  // namespace
}  // namespace ademono
