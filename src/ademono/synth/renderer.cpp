#include "ademono/synth/renderer.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/core/utility.hpp>
#include <stdexcept>

namespace ademono::synth {

namespace {

constexpr double kNear = 1e-3;  // metres; boxes with a corner closer than this are not culled

// A box prepared for one frame: everything in the box frame, rays as linear functions of the
// normalised pixel coordinates.
struct PreparedBox {
  Eigen::Matrix3d box_from_cam_rotation;  // d_box = R * (xn, yn, 1)
  Eigen::Vector3d origin;                 // camera centre in the box frame
  Eigen::Vector3d half;
  std::array<float, 6> shade;  // Lambert-like factor per face for the face normal seen
  const Box* box = nullptr;
  const Sprite* sprite = nullptr;        // photo quad (Box::sprite), else a solid/room box
  double min_depth = 0.0;                // lower bound of the depth of any point of the box
  int u0 = 0, u1 = -1, v0 = 0, v1 = -1;  // pixel bounds (inclusive) where the box can appear
};

// Light from above and slightly to the side: faces of a box get different brightness, which
// gives edges between faces that share a texture.
float FaceShade(const Eigen::Vector3d& normal_world) {
  static const Eigen::Vector3d kLight = Eigen::Vector3d(0.3, -0.4, 0.87).normalized();
  return static_cast<float>(0.65 + 0.35 * std::max(0.0, normal_world.dot(kLight)));
}

PreparedBox Prepare(const Box& box, const Camera& camera, const Rigid3d& world_from_cam) {
  PreparedBox p;
  p.box = &box;
  p.half = box.half_extents;
  const Rigid3d box_from_cam = box.world_from_box.inverse() * world_from_cam;
  p.box_from_cam_rotation = box_from_cam.linear();
  p.origin = box_from_cam.translation();
  const Eigen::Matrix3d world_from_box_rotation = box.world_from_box.linear();
  for (int axis = 0; axis < 3; ++axis) {
    for (int sign = 0; sign < 2; ++sign) {
      // The visible side of a face: outward normal for solid boxes, inward for rooms.
      double direction = sign ? 1.0 : -1.0;
      if (box.inside) direction = -direction;
      p.shade[2 * axis + sign] = FaceShade(world_from_box_rotation.col(axis) * direction);
    }
  }
  if (box.inside) {
    p.min_depth = 0.0;
    p.u0 = 0, p.u1 = camera.width - 1, p.v0 = 0, p.v1 = camera.height - 1;
    return p;
  }
  const Rigid3d cam_from_box = box_from_cam.inverse();
  double umin = std::numeric_limits<double>::infinity(), umax = -umin, vmin = umin, vmax = -umin;
  double zmin = std::numeric_limits<double>::infinity(), zmax = -zmin;
  bool behind = false;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d local((corner & 1 ? 1 : -1) * p.half.x(),
                                (corner & 2 ? 1 : -1) * p.half.y(),
                                (corner & 4 ? 1 : -1) * p.half.z());
    const Eigen::Vector3d c = cam_from_box * local;
    zmin = std::min(zmin, c.z());
    zmax = std::max(zmax, c.z());
    if (c.z() < kNear) {
      behind = true;
      continue;
    }
    const double u = camera.fx * c.x() / c.z() + camera.cx;
    const double v = camera.fy * c.y() / c.z() + camera.cy;
    umin = std::min(umin, u), umax = std::max(umax, u);
    vmin = std::min(vmin, v), vmax = std::max(vmax, v);
  }
  p.min_depth = std::max(zmin, 0.0);
  if (behind) {
    // Part of the box is behind the camera: its projection is unbounded, test every pixel
    // (unless the whole box is behind).
    if (zmax < kNear) return p;  // v1 < v0: never tested
    p.u0 = 0, p.u1 = camera.width - 1, p.v0 = 0, p.v1 = camera.height - 1;
    return p;
  }
  // The projection of a convex body lies inside the hull of its projected corners; one pixel
  // of margin keeps rays through the exact boundary.
  p.u0 = std::max(0, static_cast<int>(std::floor(umin)) - 1);
  p.u1 = std::min(camera.width - 1, static_cast<int>(std::ceil(umax)) + 1);
  p.v0 = std::max(0, static_cast<int>(std::floor(vmin)) - 1);
  p.v1 = std::min(camera.height - 1, static_cast<int>(std::ceil(vmax)) + 1);
  return p;
}

struct Hit {
  double depth = std::numeric_limits<double>::infinity();
  const PreparedBox* box = nullptr;
  int face = 0;
  Eigen::Vector3d point_box;  // hit point in the box frame
  Eigen::Vector3d ray_box;    // ray direction in the box frame
};

// Ray origin + t * dir against the box slabs; updates `hit` when nearer. t is the camera depth
// because the ray direction has z = 1 in the camera frame.
inline void Intersect(const PreparedBox& p, const Eigen::Vector3d& dir, Hit& hit) {
  if (p.sprite) {
    // The quad y = 0 of the box frame; transparent texels let the ray through.
    if (dir.y() == 0.0) return;
    const double t = -p.origin.y() / dir.y();
    if (!(t > 0.0) || t >= hit.depth) return;
    const Eigen::Vector3d point = p.origin + t * dir;
    if (std::abs(point.x()) > p.half.x() || std::abs(point.z()) > p.half.z()) return;
    if (!p.sprite->Opaque(point.x() + p.half.x(), p.half.z() - point.z())) return;
    hit.depth = t;
    hit.box = &p;
    hit.face = dir.y() > 0 ? 2 : 3;
    hit.ray_box = dir;
    hit.point_box = point;
    return;
  }
  double t_enter = -std::numeric_limits<double>::infinity();
  double t_exit = std::numeric_limits<double>::infinity();
  int enter_axis = 0, exit_axis = 0;
  for (int axis = 0; axis < 3; ++axis) {
    const double inv = 1.0 / dir[axis];
    double t0 = (-p.half[axis] - p.origin[axis]) * inv;
    double t1 = (p.half[axis] - p.origin[axis]) * inv;
    if (t0 > t1) std::swap(t0, t1);
    if (t0 > t_enter) t_enter = t0, enter_axis = axis;
    if (t1 < t_exit) t_exit = t1, exit_axis = axis;
  }
  if (!(t_exit >= t_enter)) return;
  double t;
  int face;
  if (p.box->inside) {
    if (t_exit <= 0) return;
    t = t_exit;
    face = 2 * exit_axis + (dir[exit_axis] > 0 ? 1 : 0);
  } else {
    if (t_enter <= 0) return;  // the camera is inside a solid box or it is behind
    t = t_enter;
    face = 2 * enter_axis + (dir[enter_axis] > 0 ? 0 : 1);
  }
  if (t >= hit.depth) return;
  hit.depth = t;
  hit.box = &p;
  hit.face = face;
  hit.ray_box = dir;
  hit.point_box = p.origin + t * dir;
}

}  // namespace

RenderedFrame RenderBoxes(const Camera& camera, const std::vector<Texture>& textures,
                          const std::vector<Box>& boxes, const Rigid3d& world_from_cam,
                          const cv::Vec3f& sky_bgr, const std::vector<Sprite>& sprites) {
  if (camera.HasDistortion())
    throw std::invalid_argument("synthetic rendering needs an undistorted camera");
  camera.Check();
  for (const Box& box : boxes) {
    for (int t : box.face_texture) {
      if (t < 0 || t >= static_cast<int>(textures.size()))
        throw std::invalid_argument("box refers to a missing texture");
    }
    if (box.sprite >= static_cast<int>(sprites.size()))
      throw std::invalid_argument("box refers to a missing sprite");
  }
  std::vector<PreparedBox> prepared;
  prepared.reserve(boxes.size());
  for (const Box& box : boxes) {
    PreparedBox p = Prepare(box, camera, world_from_cam);
    if (box.sprite >= 0) p.sprite = &sprites[box.sprite];
    if (p.v1 >= p.v0) prepared.push_back(p);
  }
  // Nearest first, so a pixel stops testing once its hit is closer than the next box can be.
  // stable_sort keeps the scene order among equal bounds: the result never depends on sorting.
  std::stable_sort(
      prepared.begin(), prepared.end(),
      [](const PreparedBox& a, const PreparedBox& b) { return a.min_depth < b.min_depth; });

  RenderedFrame out;
  out.image.create(camera.height, camera.width, CV_8UC3);
  out.depth.create(camera.height, camera.width, CV_32FC1);
  out.object_id.create(camera.height, camera.width, CV_32SC1);
  const double mean_focal = 0.5 * (camera.fx + camera.fy);

  cv::parallel_for_(cv::Range(0, camera.height), [&](const cv::Range& rows) {
    std::vector<const PreparedBox*> candidates;
    for (int v = rows.start; v < rows.end; ++v) {
      candidates.clear();
      for (const PreparedBox& p : prepared)
        if (v >= p.v0 && v <= p.v1) candidates.push_back(&p);
      const double yn = (v - camera.cy) / camera.fy;
      auto* image_row = out.image.ptr<cv::Vec3b>(v);
      auto* depth_row = out.depth.ptr<float>(v);
      auto* id_row = out.object_id.ptr<int32_t>(v);
      for (int u = 0; u < camera.width; ++u) {
        const Eigen::Vector3d ray_cam((u - camera.cx) / camera.fx, yn, 1.0);
        Hit hit;
        for (const PreparedBox* p : candidates) {
          if (p->min_depth >= hit.depth) break;
          if (u < p->u0 || u > p->u1) continue;
          Intersect(*p, p->box_from_cam_rotation * ray_cam, hit);
        }
        if (!hit.box) {
          image_row[u] = cv::Vec3b(cv::saturate_cast<uint8_t>(sky_bgr[0]),
                                   cv::saturate_cast<uint8_t>(sky_bgr[1]),
                                   cv::saturate_cast<uint8_t>(sky_bgr[2]));
          depth_row[u] = 0.f;
          id_row[u] = -1;
          continue;
        }
        const int axis = hit.face / 2;
        const int ia = axis == 0 ? 1 : 0;
        const int ib = axis == 2 ? 1 : 2;
        const Eigen::Vector3d& half = hit.box->half;
        // Face coordinates in metres: u along the first other axis, v down the second (for
        // walls that is down the z axis, so text in textures reads upright).
        const double face_u = hit.point_box[ia] + half[ia];
        const double face_v = half[ib] - hit.point_box[ib];
        // Pixel footprint on the surface: range / focal / cos(incidence), incidence capped so
        // grazing surfaces keep some detail.
        const double ray_norm2 = hit.ray_box.squaredNorm();
        const double cos_incidence =
            std::max(0.25, std::abs(hit.ray_box[axis]) / std::sqrt(ray_norm2));
        const double footprint = hit.depth * std::sqrt(ray_norm2) / (mean_focal * cos_incidence);
        const cv::Vec3f colour =
            hit.box->sprite
                ? hit.box->sprite->Sample(face_u, face_v, footprint)
                : textures[hit.box->box->face_texture[hit.face]].Sample(face_u, face_v, footprint) *
                      hit.box->shade[hit.face];
        image_row[u] =
            cv::Vec3b(cv::saturate_cast<uint8_t>(colour[0]), cv::saturate_cast<uint8_t>(colour[1]),
                      cv::saturate_cast<uint8_t>(colour[2]));
        depth_row[u] = static_cast<float>(hit.depth);
        id_row[u] = hit.box->box->object_id;
      }
    }
  });
  return out;
}

}  // namespace ademono::synth
