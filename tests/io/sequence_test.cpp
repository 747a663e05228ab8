#include "ademono/io/sequence.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>
#include <thread>

#include "ademono/core/error.h"
#include "ademono/io/trajectory.h"
#include "io_test_util.h"

namespace fs = std::filesystem;

namespace ademono {
namespace {

using ::testing::HasSubstr;
using testing::MakeTempDir;
using testing::WriteText;

constexpr int kW = 32, kH = 24;

// A colour image whose pixel (0, 0) encodes the frame number, so tests can check ordering.
cv::Mat ColourImage(int n) {
  cv::Mat image(kH, kW, CV_8UC3, cv::Scalar(10, 20, 30));
  image.at<cv::Vec3b>(0, 0) = cv::Vec3b(static_cast<uchar>(n * 10), 0, 0);
  return image;
}

cv::Mat DepthImage(uint16_t value) {
  cv::Mat depth(kH, kW, CV_16UC1, cv::Scalar(value));
  depth.at<uint16_t>(0, 0) = 0;
  depth.at<uint16_t>(0, 1) = 65535;
  return depth;
}

std::string ExpectInputError(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected an InputError";
  return "";
}

void WriteCamera(const fs::path& path) {
  WriteText(path, "width: 32\nheight: 24\nfx: 30\nfy: 31\ncx: 16\ncy: 12\n");
}

// ---- 7-Scenes -------------------------------------------------------------------------------

fs::path MakeSevenScenes(int frames) {
  const fs::path dir = MakeTempDir() / "seq";
  fs::create_directories(dir);
  WriteText(dir / "camera-intrinsics.txt", "40 0 16\n0 41 12\n0 0 1\n");
  for (int i = 0; i < frames; ++i) {
    char stem[32];
    std::snprintf(stem, sizeof(stem), "frame-%06d", i);
    cv::imwrite((dir / (std::string(stem) + ".color.png")).string(), ColourImage(i));
    cv::imwrite((dir / (std::string(stem) + ".depth.png")).string(), DepthImage(1500));
    WriteText(dir / (std::string(stem) + ".pose.txt"),
              "1 0 0 " + std::to_string(i) + "\n0 1 0 0\n0 0 1 0\n0 0 0 1\n");
  }
  return dir;
}

TEST(SevenScenesTest, ReadsFramesDepthPosesAndIntrinsics) {
  const fs::path dir = MakeSevenScenes(3);
  const auto seq = OpenSequence("7scenes:" + dir.string());
  EXPECT_EQ(seq->Kind(), "7scenes");
  ASSERT_EQ(seq->Size(), 3u);
  EXPECT_TRUE(seq->HasDepth());
  EXPECT_TRUE(seq->HasGroundTruth());
  const Camera& cam = seq->GetCamera();
  EXPECT_EQ(cam.width, kW);
  EXPECT_EQ(cam.height, kH);
  EXPECT_EQ(cam.fx, 40);
  EXPECT_EQ(cam.fy, 41);
  EXPECT_DOUBLE_EQ(seq->Timestamp(2), 2.0 / 30.0);
  const FrameData f = seq->Load(2);
  EXPECT_EQ(f.index, 2u);
  EXPECT_EQ(f.name, "frame-000002.color");
  EXPECT_EQ(f.image.type(), CV_8UC3);
  EXPECT_EQ(f.image.at<cv::Vec3b>(0, 0)[0], 20);
  ASSERT_EQ(f.depth.type(), CV_32FC1);
  EXPECT_FLOAT_EQ(f.depth.at<float>(5, 5), 1.5f);
  EXPECT_EQ(f.depth.at<float>(0, 0), 0.0f);
  EXPECT_EQ(f.depth.at<float>(0, 1), 0.0f);  // 65535 = no reading
  ASSERT_TRUE(f.world_from_cam_gt.has_value());
  EXPECT_EQ(f.world_from_cam_gt->translation().x(), 2.0);
  // Without its depth image: the same frame otherwise.
  const FrameData g = seq->LoadWithoutDepth(2);
  EXPECT_TRUE(g.depth.empty());
  EXPECT_EQ(g.name, f.name);
  EXPECT_EQ(cv::norm(g.image, f.image, cv::NORM_INF), 0.0);
  ASSERT_TRUE(g.world_from_cam_gt.has_value());
  EXPECT_EQ(g.world_from_cam_gt->translation().x(), 2.0);
  // Only the depth image (evaluations read it after a run): the same metres as Load's.
  const cv::Mat d = seq->LoadDepth(2);
  ASSERT_EQ(d.type(), CV_32FC1);
  EXPECT_EQ(cv::norm(d, f.depth, cv::NORM_INF), 0.0);
}

TEST(SevenScenesTest, ReportsBadInput) {
  EXPECT_THAT(ExpectInputError([] { OpenSequence("7scenes:/nonexistent/ademono"); }),
              HasSubstr("/nonexistent/ademono: no such directory"));
  const fs::path empty = MakeTempDir();
  EXPECT_EQ(ExpectInputError([&] { OpenSequence("7scenes:" + empty.string()); }),
            empty.string() + ": sequence has no frames");

  const fs::path dir = MakeSevenScenes(2);
  WriteText(dir / "frame-000001.pose.txt", "1 0 0 0\n0 1 0\n0 0 1 0\n0 0 0 1\n");
  EXPECT_THAT(ExpectInputError([&] { OpenSequence("7scenes:" + dir.string()); }),
              HasSubstr("frame-000001.pose.txt:2: expected 4 fields, found 3"));
  WriteText(dir / "frame-000001.pose.txt", "1 0 0 0\n0 1 0 0\n0 0 1 0\n");
  EXPECT_THAT(ExpectInputError([&] { OpenSequence("7scenes:" + dir.string()); }),
              HasSubstr("frame-000001.pose.txt: expected a 4x4 matrix, found 3 rows"));
  WriteText(dir / "frame-000001.pose.txt", "1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n");
  WriteText(dir / "frame-000001.color.png", "not an image");
  const auto seq = OpenSequence("7scenes:" + dir.string());
  EXPECT_THAT(ExpectInputError([&] { seq->Load(1); }),
              HasSubstr("frame-000001.color.png: image does not decode"));
  // A broken depth image fails the frame only where the depth is read.
  WriteText(dir / "frame-000000.depth.png", "not an image");
  EXPECT_THAT(ExpectInputError([&] { seq->Load(0); }),
              HasSubstr("frame-000000.depth.png: image does not decode"));
  EXPECT_TRUE(seq->LoadWithoutDepth(0).depth.empty());
  EXPECT_THAT(ExpectInputError([&] { seq->LoadDepth(0); }),
              HasSubstr("frame-000000.depth.png: image does not decode"));

  EXPECT_THAT(ExpectInputError([] { OpenSequence("nope:/tmp"); }),
              HasSubstr("unknown kind 'nope'"));
  EXPECT_THAT(ExpectInputError([] { OpenSequence("/tmp"); }), HasSubstr("expected KIND:PATH"));
}

TEST(SevenScenesTest, LoadsConcurrentlyAndDeterministically) {
  const fs::path dir = MakeSevenScenes(4);
  const auto seq = OpenSequence("7scenes:" + dir.string());
  std::vector<cv::Mat> images(seq->Size());
  std::vector<std::thread> threads;
  for (size_t i = 0; i < seq->Size(); ++i) {
    threads.emplace_back([&, i] { images[i] = seq->Load(i).image; });
  }
  for (auto& t : threads) t.join();
  for (size_t i = 0; i < seq->Size(); ++i) {
    EXPECT_EQ(cv::norm(images[i], seq->Load(i).image, cv::NORM_INF), 0.0);
  }
}

TEST(SevenScenesTest, RealSequenceA) {
  const fs::path dir = fs::path(ADEMONO_SHARED_DIR) / "data" / "7scenes-seq-a";
  if (!fs::exists(dir)) GTEST_SKIP() << "no " << dir;
  const auto seq = OpenSequence("7scenes:" + dir.string());
  ASSERT_EQ(seq->Size(), 600u);
  EXPECT_TRUE(seq->HasDepth());
  EXPECT_TRUE(seq->HasGroundTruth());
  const Camera& cam = seq->GetCamera();
  EXPECT_EQ(cam.width, 640);
  EXPECT_EQ(cam.height, 480);
  EXPECT_EQ(cam.fx, 585);
  EXPECT_EQ(cam.fy, 585);
  EXPECT_EQ(cam.cx, 320);
  EXPECT_EQ(cam.cy, 240);
  EXPECT_FALSE(cam.HasDistortion());
  EXPECT_NEAR(seq->Timestamp(599), 599.0 / 30.0, 1e-12);

  const FrameData f = seq->Load(0);
  EXPECT_EQ(f.image.type(), CV_8UC3);
  EXPECT_EQ(f.image.size(), cv::Size(640, 480));
  ASSERT_EQ(f.depth.type(), CV_32FC1);
  std::vector<float> valid;
  for (int r = 0; r < f.depth.rows; ++r)
    for (int c = 0; c < f.depth.cols; ++c)
      if (f.depth.at<float>(r, c) > 0) valid.push_back(f.depth.at<float>(r, c));
  ASSERT_GT(valid.size(), f.depth.total() / 2);
  std::nth_element(valid.begin(), valid.begin() + valid.size() / 2, valid.end());
  const float median = valid[valid.size() / 2];
  EXPECT_GT(median, 0.3f);  // metres: an indoor scene, not millimetres
  EXPECT_LT(median, 5.0f);

  // First pose against the file, read independently here.
  std::ifstream in(dir / "frame-000000.pose.txt");
  Eigen::Matrix4d m;
  for (int i = 0; i < 16; ++i) in >> m(i / 4, i % 4);
  ASSERT_TRUE(f.world_from_cam_gt.has_value());
  EXPECT_TRUE(f.world_from_cam_gt->translation().isApprox(m.block<3, 1>(0, 3), 1e-12));
  // The file's rotations are ~1e-4 off orthonormal; the reader projects them onto SO(3).
  EXPECT_LT((f.world_from_cam_gt->linear() - m.topLeftCorner<3, 3>()).cwiseAbs().maxCoeff(), 1e-3);
  EXPECT_NEAR(f.world_from_cam_gt->linear().determinant(), 1.0, 1e-12);
}

// ---- TUM ------------------------------------------------------------------------------------

fs::path MakeTum(const std::string& name) {
  const fs::path dir = MakeTempDir() / name;
  fs::create_directories(dir / "rgb");
  fs::create_directories(dir / "depth");
  // rgb at 0.000, 0.033, 0.066, 1.000; depth at 0.010, 0.030, 0.070 (1.000 has no partner).
  std::string rgb = "# rgb\n", depth = "# depth\n";
  const double rgb_t[] = {100.000, 100.033, 100.066, 101.000};
  const double depth_t[] = {100.010, 100.030, 100.070};
  for (int i = 0; i < 4; ++i) {
    const std::string file = "rgb/" + std::to_string(i) + ".png";
    cv::imwrite((dir / file).string(), ColourImage(i));
    rgb += std::to_string(rgb_t[i]) + " " + file + "\n";
  }
  for (int i = 0; i < 3; ++i) {
    const std::string file = "depth/" + std::to_string(i) + ".png";
    cv::imwrite((dir / file).string(), DepthImage(static_cast<uint16_t>(5000 * (i + 1))));
    depth += std::to_string(depth_t[i]) + " " + file + "\n";
  }
  WriteText(dir / "rgb.txt", rgb);
  WriteText(dir / "depth.txt", depth);
  // Ground truth at 100 Hz moving along x at 1 m/s.
  std::string gt = "# timestamp tx ty tz qx qy qz qw\n";
  for (int i = 0; i <= 5; ++i) {  // 99.99 .. 100.04
    gt += std::to_string(99.99 + 0.01 * i) + " " + std::to_string(0.01 * i) + " 0 0 0 0 0 1\n";
  }
  WriteText(dir / "groundtruth.txt", gt);
  return dir;
}

TEST(TumTest, AssociatesDepthScalesUnitsAndInterpolatesGroundTruth) {
  const fs::path dir = MakeTum("rgbd_dataset_freiburg1_xyz");
  const auto seq = OpenSequence("tum:" + dir.string());
  ASSERT_EQ(seq->Size(), 3u);  // 101.000 has no depth partner
  EXPECT_TRUE(seq->HasDepth());
  EXPECT_TRUE(seq->HasGroundTruth());
  EXPECT_EQ(seq->GetCamera().fx, 517.3);  // freiburg1 default from the folder name
  EXPECT_TRUE(seq->GetCamera().HasDistortion());
  EXPECT_NEAR(seq->Timestamp(1), 100.033, 1e-9);

  // Camera size (640x480) differs from the fixture images: Load reports it.
  EXPECT_THAT(ExpectInputError([&] { seq->Load(0); }),
              HasSubstr("image is 32x24, the camera is 640x480"));

  WriteCamera(dir / "camera.yaml");
  const auto with_yaml = OpenSequence("tum:" + dir.string());
  EXPECT_EQ(with_yaml->GetCamera().fx, 30);
  const FrameData f = with_yaml->Load(1);
  EXPECT_EQ(f.image.at<cv::Vec3b>(0, 0)[0], 10);
  EXPECT_FLOAT_EQ(f.depth.at<float>(3, 3), 2.0f);  // depth 1 (10000 / 5000 m) pairs with rgb 1
  ASSERT_TRUE(f.world_from_cam_gt.has_value());
  EXPECT_NEAR(f.world_from_cam_gt->translation().x(), 0.043, 1e-9);  // interpolated at 100.033
  ASSERT_TRUE(with_yaml->Load(0).world_from_cam_gt.has_value());
  EXPECT_FALSE(with_yaml->Load(2).world_from_cam_gt.has_value());  // 100.066: 0.026 past the end
}

TEST(TumTest, ReportsBadInput) {
  const fs::path dir = MakeTum("unknown_camera");
  EXPECT_THAT(ExpectInputError([&] { OpenSequence("tum:" + dir.string()); }),
              HasSubstr("no camera.yaml in the folder"));
  WriteCamera(dir / "camera.yaml");
  WriteText(dir / "depth.txt", "100.0 depth/0.png extra\n");
  EXPECT_THAT(ExpectInputError([&] { OpenSequence("tum:" + dir.string()); }),
              HasSubstr("depth.txt:1: expected 2 fields (timestamp filename), found 3"));
  WriteText(dir / "depth.txt", "100.0 depth/0.png\n");
  WriteText(dir / "groundtruth.txt", "100.0 0 0 0 0 0 inf 1\n");
  EXPECT_THAT(ExpectInputError([&] { OpenSequence("tum:" + dir.string()); }),
              HasSubstr("groundtruth.txt:1: field 7 'inf' is not a finite number"));
  fs::remove(dir / "rgb.txt");
  EXPECT_THAT(ExpectInputError([&] { OpenSequence("tum:" + dir.string()); }),
              HasSubstr("rgb.txt: no such file"));
}

// ---- KITTI ----------------------------------------------------------------------------------

TEST(KittiTest, ReadsGreyImagesCalibTimesAndPoses) {
  const fs::path root = MakeTempDir();
  const fs::path dir = root / "sequences" / "07";
  fs::create_directories(dir / "image_0");
  for (int i = 0; i < 3; ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "%06d.png", i);
    cv::Mat grey(kH, kW, CV_8UC1, cv::Scalar(i * 40));
    cv::imwrite((dir / "image_0" / name).string(), grey);
  }
  WriteText(dir / "calib.txt",
            "P0: 700 0 16 0 0 701 12 0 0 0 1 0\nP1: 700 0 16 -380 0 701 12 0 0 0 1 0\n");
  WriteText(dir / "times.txt", "0.0\n0.1036\n0.2072\n");
  WriteText(root / "poses" / "07.txt",
            "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0 0 0 0 1 0.8\n1 0 0 0 0 1 0 0 0 0 1 1.6\n");
  const auto seq = OpenSequence("kitti:" + dir.string());
  ASSERT_EQ(seq->Size(), 3u);
  EXPECT_FALSE(seq->HasDepth());
  EXPECT_TRUE(seq->HasGroundTruth());
  EXPECT_EQ(seq->GetCamera().fx, 700);
  EXPECT_EQ(seq->GetCamera().fy, 701);
  EXPECT_EQ(seq->GetCamera().width, kW);
  EXPECT_DOUBLE_EQ(seq->Timestamp(1), 0.1036);
  const FrameData f = seq->Load(2);
  EXPECT_EQ(f.image.type(), CV_8UC3);  // grey converted to BGR
  EXPECT_EQ(f.image.at<cv::Vec3b>(5, 5), cv::Vec3b(80, 80, 80));
  EXPECT_NEAR(f.world_from_cam_gt->translation().z(), 1.6, 1e-12);
  EXPECT_EQ(seq->CameraHeight(), 1.65);  // the KITTI rig's
  // Another rig's camera: no KITTI camera height.
  WriteText(root / "cam.yaml", "width: 32\nheight: 24\nfx: 30\nfy: 30\ncx: 16\ncy: 12\n");
  EXPECT_FALSE(OpenSequence("kitti:" + dir.string(), root / "cam.yaml")->CameraHeight());

  WriteText(dir / "times.txt", "0.0\n0.1\n");
  EXPECT_THAT(ExpectInputError([&] { OpenSequence("kitti:" + dir.string()); }),
              HasSubstr("times.txt: has 2 times for 3 images"));
  WriteText(dir / "times.txt", "0.0\n0.1\n0.2\n");
  WriteText(dir / "calib.txt", "P0: 700 0 16 0 0 701 12\n");
  EXPECT_THAT(ExpectInputError([&] { OpenSequence("kitti:" + dir.string()); }),
              HasSubstr("calib.txt:1: P0 needs 12 numbers, found 7"));
}

TEST(KittiTest, ColourCameraGroundTruthIsCameraZerosMovedByTheCalibrationOffset) {
  const fs::path root = MakeTempDir();
  const fs::path dir = root / "00";
  fs::create_directories(dir / "image_2");
  for (int i = 0; i < 2; ++i) {
    cv::imwrite((dir / "image_2" / ("00000" + std::to_string(i) + ".jpg")).string(),
                cv::Mat(kH, kW, CV_8UC3, cv::Scalar(10, 20, 30)));
  }
  // P2 = K [I | t]: tz = 0.002, ty = (-0.7 - 12 * 0.002) / 701, tx = (42 - 16 * 0.002) / 700.
  WriteText(dir / "calib.txt",
            "P0: 700 0 16 0 0 701 12 0 0 0 1 0\nP2: 700 0 16 42 0 701 12 -0.7 0 0 1 0.002\n");
  // Camera 0 turned 90 degrees about y (yaw) at (1, 0, 2) in frame 1.
  WriteText(root / "poses" / "00.txt",
            "1 0 0 0 0 1 0 0 0 0 1 0\n0 0 1 1 0 1 0 0 -1 0 0 2\n");
  const auto seq = OpenSequence("kitti:" + dir.string());
  ASSERT_EQ(seq->Size(), 2u);
  const Eigen::Vector3d t(41.968 / 700, -0.724 / 701, 0.002);
  const Rigid3d first = *seq->Load(0).world_from_cam_gt;
  EXPECT_LT((first.translation() + t).norm(), 1e-12);
  EXPECT_TRUE(first.linear().isIdentity(1e-12));
  // The offset turns with the camera: world = R (-t) + (1, 0, 2), R x = (z, y, -x).
  const Rigid3d second = *seq->Load(1).world_from_cam_gt;
  EXPECT_LT((second.translation() - Eigen::Vector3d(1 - t.z(), -t.y(), 2 + t.x())).norm(), 1e-12);
}

TEST(KittiTest, ReadsTheSharedDriveWithTheRigsCameraHeight) {
  const auto seq =
      OpenSequence(std::string("kitti:") + ADEMONO_SHARED_DIR + "/data/kitti-00/sequences/00");
  ASSERT_EQ(seq->Size(), 200u);
  EXPECT_EQ(seq->GetCamera().width, 1241);
  EXPECT_EQ(seq->GetCamera().height, 376);
  EXPECT_EQ(seq->GetCamera().fx, 718.856);
  EXPECT_EQ(seq->GetCamera().cy, 185.2157);
  EXPECT_EQ(seq->CameraHeight(), 1.65);
  EXPECT_TRUE(seq->HasGroundTruth());
  EXPECT_DOUBLE_EQ(seq->Timestamp(199), 19.9);
  const FrameData f = seq->Load(199);
  EXPECT_EQ(f.name, "000199");
  EXPECT_EQ(f.image.size(), cv::Size(1241, 376));
  // Frame 0's camera 0 is the origin; the colour camera sits 6 cm to its left.
  const Rigid3d first = *seq->Load(0).world_from_cam_gt;
  EXPECT_NEAR(first.translation().x(), -0.0599, 1e-4);
  EXPECT_NEAR(first.translation().norm(), 0.0600, 1e-4);
}

// ---- EuRoC ----------------------------------------------------------------------------------

TEST(EurocTest, ReadsCameraYamlAndTransformsBodyPosesToCamera) {
  const fs::path dir = MakeTempDir() / "MH_01";
  const fs::path cam = dir / "mav0" / "cam0";
  fs::create_directories(cam / "data");
  std::string list = "#timestamp [ns],filename\n";
  for (int i = 0; i < 3; ++i) {
    const std::string ns = std::to_string(1403636579763555584LL + i * 50000000LL);
    cv::imwrite((cam / "data" / (ns + ".png")).string(), cv::Mat(kH, kW, CV_8UC1, cv::Scalar(9)));
    list += ns + "," + ns + ".png\n";
  }
  WriteText(cam / "data.csv", list);
  // T_BS: camera 0.1 m along body x, same orientation.
  WriteText(cam / "sensor.yaml",
            "%YAML:1.0\nsensor_type: camera\nT_BS:\n  cols: 4\n  rows: 4\n  data: [1, 0, 0, 0.1, "
            "0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]\nrate_hz: 20\nresolution: [32, 24]\n"
            "camera_model: pinhole\nintrinsics: [458.654, 457.296, 16.0, 12.0]\n"
            "distortion_model: radial-tangential\n"
            "distortion_coefficients: [-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05]\n");
  // Body moves 1 m/s along y, sampled every 10 ms around the images; rotated 90 deg about z.
  std::string gt = "#timestamp,p_x,p_y,p_z,q_w,q_x,q_y,q_z\n";
  for (int i = -2; i < 8; ++i) {  // up to +70 ms
    const long long ns = 1403636579763555584LL + i * 10000000LL;
    gt += std::to_string(ns) + "," + "0," + std::to_string(0.01 * i) +
          ",0,0.7071067811865476,0,0,0.7071067811865476,0,0,0\n";
  }
  WriteText(dir / "mav0" / "state_groundtruth_estimate0" / "data.csv", gt);

  const auto seq = OpenSequence("euroc:" + dir.string());
  ASSERT_EQ(seq->Size(), 3u);
  EXPECT_EQ(seq->GetCamera().fx, 458.654);
  EXPECT_NEAR(seq->GetCamera().distortion[0], -0.28340811, 1e-12);
  EXPECT_NEAR(seq->Timestamp(1) - seq->Timestamp(0), 0.05, 1e-6);
  EXPECT_TRUE(seq->HasGroundTruth());
  const FrameData f1 = seq->Load(1);
  ASSERT_TRUE(f1.world_from_cam_gt.has_value());
  // Body at y = 0.05; camera offset 0.1 along body x = world y after the 90 deg yaw... x -> y.
  EXPECT_NEAR(f1.world_from_cam_gt->translation().x(), 0.0, 1e-6);
  EXPECT_NEAR(f1.world_from_cam_gt->translation().y(), 0.15, 1e-6);
  EXPECT_FALSE(
      seq->Load(2).world_from_cam_gt.has_value());  // +100 ms: 30 ms past the ground truth end
}

// ---- Image folder and video -----------------------------------------------------------------

TEST(FolderTest, OrdersByNumericStemsAndNeedsACamera) {
  const fs::path dir = MakeTempDir() / "imgs";
  fs::create_directories(dir);
  for (const std::string stem : {"1305031102.5", "1305031102.25", "1305031103.0"}) {
    cv::imwrite((dir / (stem + ".png")).string(), ColourImage(static_cast<int>(stem.size())));
  }
  EXPECT_THAT(ExpectInputError([&] { OpenSequence("folder:" + dir.string()); }),
              HasSubstr("no camera.yaml in the folder"));
  WriteCamera(dir.parent_path() / "cam.yaml");
  const auto seq = OpenSequence("folder:" + dir.string(), dir.parent_path() / "cam.yaml");
  ASSERT_EQ(seq->Size(), 3u);
  EXPECT_DOUBLE_EQ(seq->Timestamp(0), 1305031102.25);
  EXPECT_DOUBLE_EQ(seq->Timestamp(1), 1305031102.5);
  EXPECT_EQ(seq->Load(0).name, "1305031102.25");

  const fs::path named = MakeTempDir() / "named";
  fs::create_directories(named);
  for (const std::string stem : {"b", "a", "c"}) {
    cv::imwrite((named / (stem + ".jpg")).string(), ColourImage(1));
  }
  WriteCamera(named / "camera.yaml");
  const auto by_name = OpenSequence("folder:" + named.string());
  EXPECT_EQ(by_name->Load(0).name, "a");
  EXPECT_DOUBLE_EQ(by_name->Timestamp(2), 2.0 / 30.0);
}

TEST(VideoTest, ReadsFramesInAnyOrderAndCountsThem) {
  const fs::path dir = MakeTempDir();
  const fs::path file = dir / "clip.avi";
  {
    cv::VideoWriter writer(file.string(), cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 15.0,
                           cv::Size(kW, kH));
    ASSERT_TRUE(writer.isOpened());
    for (int i = 0; i < 6; ++i) writer.write(cv::Mat(kH, kW, CV_8UC3, cv::Scalar(i * 40, 0, 0)));
  }
  EXPECT_THAT(ExpectInputError([&] { OpenSequence("video:" + file.string()); }),
              HasSubstr("a video needs a camera YAML"));
  WriteCamera(dir / "cam.yaml");
  const auto seq = OpenSequence("video:" + file.string(), dir / "cam.yaml");
  ASSERT_EQ(seq->Size(), 6u);
  EXPECT_DOUBLE_EQ(seq->Timestamp(3), 3.0 / 15.0);
  auto blue = [&](size_t i) {
    return static_cast<int>(seq->Load(i).image.at<cv::Vec3b>(10, 10)[0]);
  };
  for (size_t i : {0u, 1u, 4u, 2u, 5u, 5u}) EXPECT_NEAR(blue(i), static_cast<int>(i) * 40, 6) << i;
  EXPECT_EQ(seq->Load(3).name, "frame-3");

  WriteText(dir / "broken.avi", "not a video");
  EXPECT_THROW(OpenSequence("video:" + (dir / "broken.avi").string(), dir / "cam.yaml"),
               InputError);
}

// The pipeline's workers (two by default) may ask for frame k+2 just before k+1: the recently
// decoded frames answer that without reopening the file, which would decode it again from the
// start. The file is moved away after the first loads, so a reopen would fail here.
TEST(VideoTest, WorkersAskingSlightlyOutOfOrderNeverReopenTheFile) {
  const fs::path dir = MakeTempDir();
  const fs::path file = dir / "clip.avi";
  constexpr int kFrames = 24;
  {
    cv::VideoWriter writer(file.string(), cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 15.0,
                           cv::Size(kW, kH));
    ASSERT_TRUE(writer.isOpened());
    for (int i = 0; i < kFrames; ++i)
      writer.write(cv::Mat(kH, kW, CV_8UC3, cv::Scalar(i * 10, 0, 0)));
  }
  WriteCamera(dir / "cam.yaml");
  const auto seq = OpenSequence("video:" + file.string(), dir / "cam.yaml");
  auto blue = [&](size_t i) {
    return static_cast<int>(seq->Load(i).image.at<cv::Vec3b>(10, 10)[0]);
  };
  EXPECT_NEAR(blue(0), 0, 6);
  fs::rename(file, dir / "moved.avi");
  // Pairs swapped, as two workers may take them, then a jump ahead and a look back within it.
  for (size_t i : {2u, 1u, 4u, 3u, 6u, 5u, 7u, 15u, 12u, 13u, 14u, 16u, 10u}) {
    EXPECT_NEAR(blue(i), static_cast<int>(i) * 10, 6) << i;
  }
  // Further back than the recent frames needs the file again.
  EXPECT_THAT(ExpectInputError([&] { seq->Load(0); }), HasSubstr("cannot open as a video"));
}

}  // namespace
}  // namespace ademono
