#include "ademono/synth/renderer.h"

#include <limits>

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "ademono/synth/camera_motion.h"
#include "ademono/synth/generator.h"
#include "ademono/synth/random.h"

namespace ademono::synth {
namespace {

Camera TestCamera() {
  Camera camera;
  camera.width = 160, camera.height = 120;
  camera.fx = 150.0, camera.fy = 140.0;
  camera.cx = 79.5, camera.cy = 61.25;
  return camera;
}

std::vector<Texture> OneTexture() {
  TextureSpec spec;
  spec.width_m = 4, spec.height_m = 4, spec.texel_m = 0.02;
  return {Texture::Generate(spec)};
}

Rigid3d Pose(const Eigen::Vector3d& omega, const Eigen::Vector3d& t) {
  Rigid3d pose = Rigid3d::Identity();
  pose.linear() = ExpSO3(omega);
  pose.translation() = t;
  return pose;
}

// A flat box (plane) at a known pose: every pixel's depth is the analytic ray/plane depth and its
// 16-bit PNG value is that depth rounded to 1/5000 m.
TEST(Renderer, PlaneDepthIsExactToPngQuantisation) {
  const Camera camera = TestCamera();
  const auto textures = OneTexture();
  for (const auto& [omega, t] : std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>>{
           {{0, 0, 0}, {0, 0, 2.5}},
           {{0.4, -0.3, 0.2}, {0.3, -0.2, 3.0}},
           {{-0.6, 0.5, 0.1}, {0, 0.5, 7.0}}}) {
    // The box's +z face (normal along the box z axis) faces the camera at the origin.
    const Rigid3d cam_from_plane = Pose(omega, t) * Pose({M_PI, 0, 0}, {0, 0, 0});
    const double thickness = 0.01;
    Box plane =
        MakeBox(cam_from_plane * Pose({0, 0, 0}, {0, 0, -thickness}), {50, 50, thickness}, 0);
    const Rigid3d world_from_cam = Pose({0.1, 0.2, 0.3}, {1, 2, 3});
    plane.world_from_box = world_from_cam * plane.world_from_box;
    const RenderedFrame frame = RenderBoxes(camera, textures, {plane}, world_from_cam, {0, 0, 0});
    const cv::Mat png = DepthToPng(frame.depth);

    const Eigen::Vector3d normal = cam_from_plane.linear().col(2);
    const double offset = normal.dot(cam_from_plane.translation());
    int beyond = 0;
    for (int v = 0; v < camera.height; ++v) {
      for (int u = 0; u < camera.width; ++u) {
        const Eigen::Vector3d ray((u - camera.cx) / camera.fx, (v - camera.cy) / camera.fy, 1.0);
        const double z = offset / normal.dot(ray);
        ASSERT_NEAR(frame.depth.at<float>(v, u), z, 2e-6 * z) << u << "," << v;
        if (z * kDepthPngScale > 65535.5) {
          ASSERT_EQ(png.at<uint16_t>(v, u), 0) << "beyond the PNG range: invalid";
          ++beyond;
        } else {
          ASSERT_LE(std::abs(png.at<uint16_t>(v, u) / kDepthPngScale - z),
                    0.5 / kDepthPngScale + 1e-6)
              << u << "," << v;
        }
        ASSERT_EQ(frame.object_id.at<int32_t>(v, u), 0);
      }
    }
    if (t.z() > 5) {
      EXPECT_GT(beyond, 100);  // the steep plane reaches beyond 13.1 m
    }
  }
}

// Signed distance (pixels, > 0 inside) of pixel centres to the projected silhouette of a box:
// the convex hull of its eight projected corners.
cv::Mat SilhouetteDistance(const Camera& camera, const Box& box, const Rigid3d& world_from_cam) {
  std::vector<cv::Point2f> corners;
  const Rigid3d cam_from_box = world_from_cam.inverse() * box.world_from_box;
  for (int c = 0; c < 8; ++c) {
    const Eigen::Vector3d local((c & 1 ? 1 : -1) * box.half_extents.x(),
                                (c & 2 ? 1 : -1) * box.half_extents.y(),
                                (c & 4 ? 1 : -1) * box.half_extents.z());
    const Eigen::Vector2d px = camera.ProjectUndistorted(cam_from_box * local);
    corners.emplace_back(static_cast<float>(px.x()), static_cast<float>(px.y()));
  }
  std::vector<cv::Point2f> hull;
  cv::convexHull(corners, hull);
  cv::Mat distance(camera.height, camera.width, CV_64F);
  for (int v = 0; v < camera.height; ++v)
    for (int u = 0; u < camera.width; ++u)
      distance.at<double>(v, u) = cv::pointPolygonTest(hull, cv::Point2f(u, v), true);
  return distance;
}

// Box corners projected with the camera model land on the rendered silhouette: every pixel more
// than 0.5 px inside the projected outline shows the box, every pixel more than 0.5 px outside
// does not, for random box and camera poses.
TEST(Renderer, ProjectedCornersMatchRenderedEdgesWithinHalfPixel) {
  const Camera camera = TestCamera();
  const auto textures = OneTexture();
  Rng rng(7);
  for (int trial = 0; trial < 20; ++trial) {
    const Rigid3d world_from_cam =
        Pose({rng.Uniform(-1, 1), rng.Uniform(-1, 1), rng.Uniform(-1, 1)},
             {rng.Uniform(-2, 2), rng.Uniform(-2, 2), rng.Uniform(-2, 2)});
    const Rigid3d cam_from_box =
        Pose({rng.Uniform(-2, 2), rng.Uniform(-2, 2), rng.Uniform(-2, 2)},
             {rng.Uniform(-0.4, 0.4), rng.Uniform(-0.3, 0.3), rng.Uniform(2.5, 4)});
    Box box = MakeBox(world_from_cam * cam_from_box,
                      {rng.Uniform(0.1, 0.5), rng.Uniform(0.1, 0.5), rng.Uniform(0.1, 0.5)}, 0, 7);
    const RenderedFrame frame = RenderBoxes(camera, textures, {box}, world_from_cam, {0, 0, 0});
    const cv::Mat distance = SilhouetteDistance(camera, box, world_from_cam);
    int inside = 0;
    for (int v = 0; v < camera.height; ++v) {
      for (int u = 0; u < camera.width; ++u) {
        const double d = distance.at<double>(v, u);
        const int id = frame.object_id.at<int32_t>(v, u);
        if (d > 0.5) {
          ASSERT_EQ(id, 7) << "trial " << trial << " pixel " << u << "," << v;
          ++inside;
        }
        if (d < -0.5) {
          ASSERT_EQ(id, -1) << "trial " << trial << " pixel " << u << "," << v;
        }
        ASSERT_EQ(id == 7, frame.depth.at<float>(v, u) > 0.f);
      }
    }
    EXPECT_GT(inside, 50) << "trial " << trial;
  }
}

TEST(Renderer, RoomSeenFromInsideAndNearestSurfaceWins) {
  const Camera camera = TestCamera();
  const auto textures = OneTexture();
  Box room = MakeBox(Rigid3d::Identity(), {3, 3, 3}, 0);
  room.inside = true;
  // The camera at the room centre looks along +z: the far wall is 3 m away.
  Box near_box = MakeBox(Pose({0, 0, 0}, {0, 0, 1.5}), {0.2, 0.2, 0.2}, 0, 4);
  const RenderedFrame frame =
      RenderBoxes(camera, textures, {room, near_box}, Rigid3d::Identity(), {0, 0, 0});
  EXPECT_FLOAT_EQ(frame.depth.at<float>(0, 0), 3.0f);
  EXPECT_EQ(frame.object_id.at<int32_t>(0, 0), 0);
  const int u = static_cast<int>(std::round(camera.cx)),
            v = static_cast<int>(std::round(camera.cy));
  EXPECT_NEAR(frame.depth.at<float>(v, u), 1.3f, 1e-6);
  EXPECT_EQ(frame.object_id.at<int32_t>(v, u), 4);
}

TEST(Renderer, ResultDoesNotDependOnThreadCount) {
  SceneOptions options;
  options.width = 200, options.height = 150, options.persons = 3, options.seed = 5;
  const Scene scene = BuildScene(options);
  GeneratorOptions generator;
  generator.scene = options;
  generator.noise_sigma = 3.0;
  generator.blur_px = 4.0;
  const int threads = cv::getNumThreads();
  cv::setNumThreads(1);
  const RenderedFrame one = RenderSceneFrame(scene, 12, generator);
  cv::setNumThreads(4);
  const RenderedFrame four = RenderSceneFrame(scene, 12, generator);
  cv::setNumThreads(threads);
  EXPECT_EQ(cv::norm(one.image, four.image, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(one.depth, four.depth, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(one.object_id, four.object_id, cv::NORM_INF), 0.0);
}

TEST(Renderer, RejectsDistortedCameraAndMissingTexture) {
  Camera camera = TestCamera();
  const auto textures = OneTexture();
  Box box = MakeBox(Pose({0, 0, 0}, {0, 0, 2}), {0.2, 0.2, 0.2}, 1);
  EXPECT_THROW(RenderBoxes(camera, textures, {box}, Rigid3d::Identity(), {0, 0, 0}),
               std::invalid_argument);
  box.face_texture.fill(0);
  camera.distortion[0] = 0.1;
  EXPECT_THROW(RenderBoxes(camera, textures, {box}, Rigid3d::Identity(), {0, 0, 0}),
               std::invalid_argument);
}

TEST(Texture, RichEnoughForCornersAndDeterministic) {
  TextureSpec spec;
  spec.width_m = 2, spec.height_m = 1, spec.texel_m = 0.004, spec.seed = 11;
  const Texture a = Texture::Generate(spec);
  const Texture b = Texture::Generate(spec);
  spec.seed = 12;
  const Texture c = Texture::Generate(spec);
  EXPECT_EQ(cv::norm(a.level(0), b.level(0), cv::NORM_INF), 0.0);
  EXPECT_GT(cv::norm(a.level(0), c.level(0), cv::NORM_L1) / a.level(0).total(), 5.0);
  // Local contrast everywhere: the grey spread over 32x32 texel windows is never flat.
  cv::Mat mean, sq;
  cv::Mat f;
  a.level(0).convertTo(f, CV_32F);
  cv::boxFilter(f, mean, CV_32F, {32, 32});
  cv::boxFilter(f.mul(f), sq, CV_32F, {32, 32});
  cv::Mat stddev;
  cv::sqrt(cv::max(sq - mean.mul(mean), 0), stddev);
  double min_std = 0;
  cv::minMaxLoc(stddev(cv::Rect(16, 16, f.cols - 32, f.rows - 32)), &min_std);
  EXPECT_GT(min_std, 4.0);
  // Mip levels halve.
  ASSERT_GT(a.num_levels(), 4);
  EXPECT_EQ(a.level(1).cols, (a.level(0).cols + 1) / 2);
}

TEST(CameraMotion, MotionsAreSmoothAndStaticStaysPut) {
  for (const std::string name : {"xyz", "halfsphere", "rpy", "static", "forward"}) {
    MotionSpec spec;
    spec.kind = ParseMotionKind(name);
    EXPECT_EQ(MotionKindName(spec.kind), name);
    spec.base_world_from_cam = LookAt({0, -1.6, 1.4}, {0, 1.5, 1.0}, {0, 0, 1});
    spec.look_at = {0, 1.5, 1.0};
    spec.forward_speed = 1.0;
    const auto trajectory = MakeCameraTrajectory(spec);
    double max_step = 0.0, max_offset = 0.0;
    for (int i = 1; i < 300; ++i) {
      const Rigid3d a = trajectory((i - 1) / 30.0), b = trajectory(i / 30.0);
      max_step = std::max(max_step, (a.translation() - b.translation()).norm());
      max_offset = std::max(max_offset, (b.translation() - trajectory(0).translation()).norm());
      EXPECT_NEAR(b.linear().determinant(), 1.0, 1e-9);
    }
    EXPECT_LT(max_step, 0.06) << name;
    if (name == "static") {
      EXPECT_LT(max_offset, 0.02);
    } else if (name == "xyz") {
      EXPECT_GT(max_offset, 0.2);
    } else if (name == "forward") {
      EXPECT_GT(max_offset, 9.0);
    }
  }
  EXPECT_THROW(ParseMotionKind("spin"), std::invalid_argument);
}

// Regression: seed 11 of the 3-person office hit a footprint of exactly sqrt(2) texels, which
// passed the level test but gave ilogb(0.99999...) = -1 and indexed before the pyramid.
TEST(Texture, DegenerateFootprintsSampleTheCoarsestOrFinestLevel) {
  const Texture texture = OneTexture().front();
  const double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (double footprint : {0.02 * std::sqrt(2.0), inf, nan, 1e300, 0.0, -1.0}) {
    const cv::Vec3f colour = texture.Sample(1.0, 1.0, footprint);
    for (int c = 0; c < 3; ++c) EXPECT_TRUE(std::isfinite(colour[c])) << footprint;
  }
  const cv::Mat& coarsest = texture.level(texture.num_levels() - 1);
  EXPECT_FALSE(coarsest.empty());
}

}  // namespace
}  // namespace ademono::synth
