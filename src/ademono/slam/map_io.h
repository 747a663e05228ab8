#pragma once
// Map files (`ademono run --save-map` / `--load-map`, `ademono map info`).
//
// Layout: a 24-byte header, then the payload.
//   magic "ADEMAP\r\n" (8 bytes) | format version (uint32 LE) | payload size (uint64 LE) |
//   CRC-32 of the payload (uint32 LE, zlib) | payload: a cereal portable binary archive of
//   MapFileData (little-endian on every host).
// The header is checked before cereal sees a byte, so a truncated file, another version or a
// flipped bit fail with one clear message; the payload is then checked for consistency (every
// id it refers to exists, sizes agree) before anything is built from it. docs/maps.md.

#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "ademono/core/camera.h"
#include "ademono/slam/frame.h"
#include "ademono/slam/map.h"
#include "ademono/slam/options.h"

namespace ademono {

// 2: map points carry the geometric test's static probability and whether they were admitted.
// Version 1 files (without them: every point static and admitted) are still read.
constexpr uint32_t kMapFormatVersion = 2;
constexpr uint32_t kMapOldestReadableVersion = 1;
constexpr size_t kMapHeaderSize = 24;

struct MapKeyPointRecord {
  float x = 0, y = 0, size = 0, angle = 0, response = 0;
  int32_t octave = 0;
};

struct MapKeyFrameRecord {
  uint64_t id = 0, frame_id = 0, index = 0;
  double timestamp = 0;
  std::array<double, 12> cam_from_world{};  // 3x4 row-major [R | t]
  std::vector<MapKeyPointRecord> keypoints;
  std::vector<uint8_t> descriptors;  // 32 bytes per keypoint
  std::vector<float> depth;          // metres, -1 when unknown
  double bf = 0;                     // virtual stereo baseline x fx
  float close_depth = 0;
  double depth_error_relative = 0, depth_error_per_metre = 0;
  // A byte, not a bool: any other value than 0 or 1 is rejected on load (a bool read from
  // arbitrary bytes would be undefined). Same one-byte layout as before.
  uint8_t weight_by_error_model = 1;
  float depth_scale = 1;
  int64_t parent = -1;  // spanning tree parent id, -1 for the root
  std::vector<std::pair<uint64_t, int32_t>> connections;  // covisibility: (keyframe id, weight)
};

struct MapPointRecord {
  uint64_t id = 0;
  std::array<double, 3> position{}, normal{};
  std::array<uint8_t, 32> descriptor{};
  float min_distance = 0, max_distance = 0;
  uint64_t reference = 0, first_keyframe_id = 0, first_frame_id = 0;
  int32_t visible = 1, found = 1, dynamic_hits = 0;
  std::vector<std::pair<uint64_t, uint32_t>> observations;  // (keyframe id, keypoint index)
  // Version 2: P(static) and whether the point was let into the pose and BA, so a reloaded map
  // keeps a mover's unconfirmed points out of localisation as the live map did. A byte for the
  // flag, as for weight_by_error_model.
  double static_probability = 1;
  uint8_t admitted = 1;
};

struct MapFileData {
  // The file's format version (the header's; not in the payload). Written back as read, so a
  // loaded map saves to the same bytes; new maps get kMapFormatVersion.
  uint32_t version = kMapFormatVersion;
  Camera camera;
  std::string options_yaml;  // the resolved SystemOptions of the run that built the map
  uint64_t next_keyframe_id = 0, next_point_id = 0;
  std::vector<MapKeyFrameRecord> keyframes;  // live keyframes, by id
  std::vector<MapPointRecord> points;        // live points, by id
};

// Where the map's scale comes from: keyframe depths (sensor or network depth built it), the road
// held at the rig's camera height (depth.camera_height in its options: --depth none outdoors), or
// nothing (--depth none without a camera height: the units of its two-view start).
enum class MapScale { kDepth, kRoad, kArbitrary };
MapScale MapScaleOf(const MapFileData& data);
// The depth.camera_height of the run that built the map (0: none, or options it cannot read).
double MapCameraHeight(const MapFileData& data);
inline bool MapHasMetricScale(const MapFileData& data) {
  return MapScaleOf(data) != MapScale::kArbitrary;
}

// What `ademono map info` prints.
struct MapFileSummary {
  uint32_t version = 0;
  uint64_t file_size = 0;
  Camera camera;
  size_t num_keyframes = 0, num_points = 0, num_observations = 0;
  size_t num_points_not_admitted = 0;  // awaiting a confirming view, or judged moving
  MapScale scale = MapScale::kDepth;    // MapScaleOf
  double camera_height = 0;             // MapCameraHeight
  Eigen::Vector3d min_corner = Eigen::Vector3d::Zero(), max_corner = Eigen::Vector3d::Zero();
  std::string options_yaml;
};

// The map as records (the caller holds map.mutex).
MapFileData MapToRecords(const Map& map, const Camera& camera, const SystemOptions& options)
    ADEMONO_REQUIRES(map.mutex);
// The file bytes (header + payload) and back. ParseMapFile throws InputError "path: problem".
std::string SerializeMapFile(const MapFileData& data);
MapFileData ParseMapFile(const std::string& bytes, const std::filesystem::path& path_for_errors);
// Whole-file read + ParseMapFile; SaveMapFile writes atomically (temp + fsync + rename).
MapFileData LoadMapFile(const std::filesystem::path& path);
void SaveMapFile(const std::filesystem::path& path, const MapFileData& data);
MapFileSummary SummarizeMap(const MapFileData& data, uint64_t file_size);
std::string MapSummaryText(const std::filesystem::path& path, const MapFileSummary& summary);

// Rebuilds keyframes (features, grid), points, observations, covisibility and the spanning tree
// into an empty `map` (its keyframe database is filled too). The caller holds map.mutex.
// InputError naming `path_for_errors` when a keypoint's level is beyond `pyramid`.
void RestoreMap(const MapFileData& data, const std::shared_ptr<const ScalePyramid>& pyramid,
                Map& map, const std::filesystem::path& path_for_errors = {})
    ADEMONO_REQUIRES(map.mutex);

}  // namespace ademono
