#include "ademono/slam/map_io.h"

#include <fcntl.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>
#include <zlib.h>

#include <cereal/archives/portable_binary.hpp>
#include <cereal/types/array.hpp>
#include <cereal/types/utility.hpp>
#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <iomanip>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <type_traits>

#include "ademono/core/error.h"

namespace ademono {

namespace {

// Bytes left in the payload being decoded: a length read from a file is checked against it
// before anything is allocated (cereal's own vector/string loaders would resize to whatever a
// corrupt length says). Writing: unbounded.
thread_local uint64_t t_payload_limit = std::numeric_limits<uint64_t>::max();
// The format version of the payload being written or read (fields added in later versions are
// skipped for older ones).
thread_local uint32_t t_format_version = kMapFormatVersion;

// Sets t_format_version for one archive operation.
struct FormatVersionScope {
  explicit FormatVersionScope(uint32_t version) { t_format_version = version; }
  ~FormatVersionScope() { t_format_version = kMapFormatVersion; }
  FormatVersionScope(const FormatVersionScope&) = delete;
  FormatVersionScope& operator=(const FormatVersionScope&) = delete;
};

void CheckLength(uint64_t count, uint64_t min_element_bytes) {
  if (count > t_payload_limit / std::max<uint64_t>(1, min_element_bytes))
    throw std::runtime_error("a length of " + std::to_string(count) + " exceeds the payload");
}

// The same bytes as cereal's std::vector / std::string serialisation (size tag, then the
// elements; arithmetic ones as one block), with the length checked on load.
template <class Archive, class T>
void Elements(Archive& ar, std::vector<T>& v, uint64_t min_element_bytes) {
  cereal::size_type n = v.size();
  ar(cereal::make_size_tag(n));
  if constexpr (Archive::is_loading::value) {
    CheckLength(n, min_element_bytes);
    v.resize(static_cast<size_t>(n));
  }
  if constexpr (std::is_arithmetic_v<T>) {
    ar(cereal::binary_data(v.data(), static_cast<size_t>(n) * sizeof(T)));
  } else {
    for (auto& x : v) ar(x);
  }
}

template <class Archive>
void Text(Archive& ar, std::string& s) {
  cereal::size_type n = s.size();
  ar(cereal::make_size_tag(n));
  if constexpr (Archive::is_loading::value) {
    CheckLength(n, 1);
    s.resize(static_cast<size_t>(n));
  }
  ar(cereal::binary_data(s.data(), static_cast<size_t>(n)));
}

}  // namespace

template <class Archive>
void serialize(Archive& ar, MapKeyPointRecord& k) {
  ar(k.x, k.y, k.size, k.angle, k.response, k.octave);
}

template <class Archive>
void serialize(Archive& ar, MapKeyFrameRecord& k) {
  ar(k.id, k.frame_id, k.index, k.timestamp, k.cam_from_world);
  Elements(ar, k.keypoints, 24);
  Elements(ar, k.descriptors, 1);
  Elements(ar, k.depth, 4);
  ar(k.bf, k.close_depth, k.depth_error_relative, k.depth_error_per_metre,
     k.weight_by_error_model, k.depth_scale, k.parent);
  Elements(ar, k.connections, 12);
}

template <class Archive>
void serialize(Archive& ar, MapPointRecord& p) {
  ar(p.id, p.position, p.normal, p.descriptor, p.min_distance, p.max_distance, p.reference,
     p.first_keyframe_id, p.first_frame_id, p.visible, p.found, p.dynamic_hits);
  Elements(ar, p.observations, 12);
  if (t_format_version >= 2) ar(p.static_probability, p.admitted);
}

template <class Archive>
void serialize(Archive& ar, Camera& c) {
  ar(c.width, c.height, c.fx, c.fy, c.cx, c.cy, c.distortion);
}

template <class Archive>
void serialize(Archive& ar, MapFileData& d) {
  ar(d.camera);
  Text(ar, d.options_yaml);
  ar(d.next_keyframe_id, d.next_point_id);
  Elements(ar, d.keyframes, 100);
  Elements(ar, d.points, 140);
}

namespace {

constexpr char kMagic[8] = {'A', 'D', 'E', 'M', 'A', 'P', '\r', '\n'};

template <typename T>
void PutLittleEndian(std::string& out, T value) {
  for (size_t i = 0; i < sizeof(T); ++i)
    out.push_back(static_cast<char>((value >> (8 * i)) & 0xff));
}

template <typename T>
T GetLittleEndian(const std::string& bytes, size_t offset) {
  T value = 0;
  for (size_t i = 0; i < sizeof(T); ++i)
    value |= static_cast<T>(static_cast<unsigned char>(bytes[offset + i])) << (8 * i);
  return value;
}

uint32_t Crc32(const char* data, size_t size) {
  uLong crc = crc32(0L, Z_NULL, 0);
  // zlib takes uInt lengths: feed large payloads in chunks.
  while (size > 0) {
    const uInt chunk = static_cast<uInt>(std::min<size_t>(size, 1u << 30));
    crc = crc32(crc, reinterpret_cast<const Bytef*>(data), chunk);
    data += chunk;
    size -= chunk;
  }
  return static_cast<uint32_t>(crc);
}

std::array<double, 12> PoseToArray(const Rigid3d& pose) {
  std::array<double, 12> a{};
  const Eigen::Matrix<double, 3, 4> m = pose.matrix().topRows<3>();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) a[r * 4 + c] = m(r, c);
  return a;
}

Rigid3d PoseFromArray(const std::array<double, 12>& a) {
  Rigid3d pose = Rigid3d::Identity();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) pose.matrix()(r, c) = a[r * 4 + c];
  return pose;
}

bool Finite(double v) { return std::isfinite(v); }

// Everything RestoreMap relies on; the first problem as one line.
void Validate(const MapFileData& d, const std::filesystem::path& path) {
  auto fail = [&](const std::string& message) { ThrowInputError(path, message); };
  try {
    d.camera.Check();
  } catch (const std::exception& e) {
    fail(std::string("bad camera: ") + e.what());
  }
  std::set<uint64_t> keyframe_ids;
  std::map<uint64_t, size_t> num_keypoints;
  for (const auto& k : d.keyframes) {
    const std::string where = "keyframe " + std::to_string(k.id) + ": ";
    if (!keyframe_ids.insert(k.id).second) fail(where + "duplicate id");
    if (k.id >= d.next_keyframe_id) fail(where + "id not below next_keyframe_id");
    const size_t n = k.keypoints.size();
    if (k.descriptors.size() != 32 * n || k.depth.size() != n)
      fail(where + "keypoint, descriptor and depth counts differ");
    for (double v : k.cam_from_world)
      if (!Finite(v)) fail(where + "pose is not finite");
    for (const auto& kp : k.keypoints) {
      if (!Finite(kp.x) || !Finite(kp.y) || !Finite(kp.size) || !Finite(kp.response) ||
          !(kp.angle >= -1.f && kp.angle <= 360.f) || kp.octave < 0)
        fail(where + "bad keypoint");
      // Keypoints are extracted on the image; one pixel of slack for sub-pixel positions.
      if (!(kp.x >= -1.0 && kp.x <= d.camera.width + 1.0 && kp.y >= -1.0 &&
            kp.y <= d.camera.height + 1.0))
        fail(where + "keypoint outside the image");
    }
    for (float z : k.depth)
      if (!std::isfinite(z)) fail(where + "depth is not finite");
    if (!Finite(k.bf) || !std::isfinite(k.close_depth) || !std::isfinite(k.depth_scale) ||
        !(k.depth_scale > 0) || !Finite(k.depth_error_relative) ||
        !Finite(k.depth_error_per_metre))
      fail(where + "bad depth parameters");
    if (k.weight_by_error_model > 1) fail(where + "bad weight_by_error_model flag");
    num_keypoints[k.id] = n;
  }
  if (d.keyframes.empty()) fail("the map has no keyframe");
  for (const auto& k : d.keyframes) {
    const std::string where = "keyframe " + std::to_string(k.id) + ": ";
    if (k.parent >= 0 && (keyframe_ids.count(static_cast<uint64_t>(k.parent)) == 0 ||
                          static_cast<uint64_t>(k.parent) == k.id))
      fail(where + "unknown parent " + std::to_string(k.parent));
    for (const auto& [id, w] : k.connections)
      if (keyframe_ids.count(id) == 0 || id == k.id || w <= 0)
        fail(where + "bad covisibility edge to " + std::to_string(id));
  }
  std::set<uint64_t> point_ids;
  std::set<std::pair<uint64_t, uint32_t>> used;
  for (const auto& p : d.points) {
    const std::string where = "point " + std::to_string(p.id) + ": ";
    if (!point_ids.insert(p.id).second) fail(where + "duplicate id");
    if (p.id >= d.next_point_id) fail(where + "id not below next_point_id");
    for (double v : p.position)
      if (!Finite(v)) fail(where + "position is not finite");
    for (double v : p.normal)
      if (!Finite(v)) fail(where + "normal is not finite");
    if (!std::isfinite(p.min_distance) || !std::isfinite(p.max_distance))
      fail(where + "bad distance range");
    if (!(p.static_probability >= 0 && p.static_probability <= 1))
      fail(where + "static probability outside [0, 1]");
    if (p.admitted > 1) fail(where + "admitted flag is neither 0 nor 1");
    if (p.observations.empty()) fail(where + "no observation");
    for (const auto& [kf, idx] : p.observations) {
      const auto it = num_keypoints.find(kf);
      if (it == num_keypoints.end() || idx >= it->second)
        fail(where + "observation of an unknown keyframe or keypoint");
      if (!used.insert({kf, idx}).second) fail(where + "keypoint observed by two points");
    }
  }
}

}  // namespace

MapFileData MapToRecords(const Map& map, const Camera& camera, const SystemOptions& options) {
  MapFileData d;
  d.camera = camera;
  d.options_yaml = YamlToText(options.ToYaml());
  d.next_keyframe_id = map.NextKeyFrameId();
  d.next_point_id = map.NextMapPointId();
  for (const auto& [id, kf] : map.KeyFrames()) {
    if (kf->bad) continue;
    const FrameFeatures& f = kf->F();
    MapKeyFrameRecord r;
    r.id = id;
    r.frame_id = kf->frame_id;
    r.index = kf->index;
    r.timestamp = kf->timestamp;
    r.cam_from_world = PoseToArray(kf->cam_from_world);
    r.keypoints.reserve(f.Size());
    for (const auto& kp : f.keypoints)
      r.keypoints.push_back({kp.pt.x, kp.pt.y, kp.size, kp.angle, kp.response, kp.octave});
    r.descriptors.resize(32 * f.Size());
    for (size_t i = 0; i < f.Size(); ++i)
      std::memcpy(r.descriptors.data() + 32 * i, f.descriptors.ptr<uint8_t>(static_cast<int>(i)),
                  32);
    r.depth = f.depth;
    r.bf = f.intrinsics.bf;
    r.close_depth = f.close_depth;
    r.depth_error_relative = f.depth_error.relative;
    r.depth_error_per_metre = f.depth_error.per_metre;
    r.weight_by_error_model = f.weight_by_error_model ? 1 : 0;
    r.depth_scale = f.depth_scale;
    r.parent =
        kf->parent != nullptr && !kf->parent->bad ? static_cast<int64_t>(kf->parent->id) : -1;
    for (const auto& [other, weight] : kf->connections)
      if (!other->bad) r.connections.emplace_back(other->id, weight);
    d.keyframes.push_back(std::move(r));
  }
  for (const auto& [id, p] : map.MapPoints()) {
    if (p->bad) continue;
    MapPointRecord r;
    r.id = id;
    r.position = {p->position.x(), p->position.y(), p->position.z()};
    r.normal = {p->normal.x(), p->normal.y(), p->normal.z()};
    if (p->descriptor.rows == 1 && p->descriptor.cols == 32)
      std::memcpy(r.descriptor.data(), p->descriptor.ptr<uint8_t>(0), 32);
    r.min_distance = p->min_distance;
    r.max_distance = p->max_distance;
    r.first_keyframe_id = p->first_keyframe_id;
    r.first_frame_id = p->first_frame_id;
    r.visible = p->visible;
    r.found = p->found;
    r.dynamic_hits = p->dynamic_hits;
    r.static_probability = p->static_probability;
    r.admitted = p->admitted ? 1 : 0;
    for (const auto& [kf, idx] : p->observations)
      if (!kf->bad) r.observations.emplace_back(kf->id, static_cast<uint32_t>(idx));
    if (r.observations.empty()) continue;
    r.reference = p->reference != nullptr && !p->reference->bad ? p->reference->id
                                                                  : r.observations.front().first;
    d.points.push_back(std::move(r));
  }
  return d;
}

std::string SerializeMapFile(const MapFileData& data) {
  std::ostringstream payload_stream(std::ios::binary);
  if (data.version < kMapOldestReadableVersion || data.version > kMapFormatVersion)
    throw std::invalid_argument("SerializeMapFile: no format version " +
                                std::to_string(data.version));
  {
    const FormatVersionScope scope(data.version);
    cereal::PortableBinaryOutputArchive archive(payload_stream);
    archive(data);
  }
  const std::string payload = payload_stream.str();
  std::string out(kMagic, sizeof(kMagic));
  PutLittleEndian<uint32_t>(out, data.version);
  PutLittleEndian<uint64_t>(out, payload.size());
  PutLittleEndian<uint32_t>(out, Crc32(payload.data(), payload.size()));
  out += payload;
  return out;
}

MapFileData ParseMapFile(const std::string& bytes, const std::filesystem::path& path) {
  if (bytes.size() < sizeof(kMagic) || std::memcmp(bytes.data(), kMagic, sizeof(kMagic)) != 0)
    ThrowInputError(path, "not an ademono map file (bad magic)");
  if (bytes.size() < kMapHeaderSize)
    ThrowInputError(path, "truncated map file (" + std::to_string(bytes.size()) +
                              " bytes, header needs " + std::to_string(kMapHeaderSize) + ")");
  const uint32_t version = GetLittleEndian<uint32_t>(bytes, 8);
  if (version < kMapOldestReadableVersion || version > kMapFormatVersion)
    ThrowInputError(path, "map format version " + std::to_string(version) +
                              ", this build reads versions " +
                              std::to_string(kMapOldestReadableVersion) + " to " +
                              std::to_string(kMapFormatVersion));
  const uint64_t payload_size = GetLittleEndian<uint64_t>(bytes, 12);
  const uint64_t available = bytes.size() - kMapHeaderSize;
  if (payload_size > available)
    ThrowInputError(path, "truncated map file (payload " + std::to_string(available) + " of " +
                              std::to_string(payload_size) + " bytes)");
  if (payload_size < available)
    ThrowInputError(path, "map file has " + std::to_string(available - payload_size) +
                              " bytes after the payload");
  const uint32_t crc = GetLittleEndian<uint32_t>(bytes, 20);
  if (Crc32(bytes.data() + kMapHeaderSize, payload_size) != crc)
    ThrowInputError(path, "checksum mismatch (the map file is corrupt)");
  MapFileData data;
  struct LimitGuard {
    explicit LimitGuard(uint64_t limit) { t_payload_limit = limit; }
    ~LimitGuard() { t_payload_limit = std::numeric_limits<uint64_t>::max(); }
  } guard(payload_size);
  data.version = version;
  try {
    const FormatVersionScope scope(version);
    std::istringstream in(bytes.substr(kMapHeaderSize), std::ios::binary);
    cereal::PortableBinaryInputArchive archive(in);
    archive(data);
    if (in.tellg() != static_cast<std::streamoff>(payload_size))
      ThrowInputError(path, "map payload has trailing bytes");
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    ThrowInputError(path, std::string("cannot decode the map payload: ") + e.what());
  }
  Validate(data, path);
  return data;
}

MapFileData LoadMapFile(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) ThrowInputError(path, "map file not found");
  std::ifstream in(path, std::ios::binary);
  if (!in) ThrowInputError(path, "cannot open the map file");
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return ParseMapFile(bytes, path);
}

void SaveMapFile(const std::filesystem::path& path, const MapFileData& data) {
  const std::string bytes = SerializeMapFile(data);
  if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path());
  const std::filesystem::path tmp =
      path.string() + ".tmp." + std::to_string(static_cast<long>(::getpid()));
  // POSIX I/O for fsync: the rename must never expose a file whose bytes are not on disk.
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) ThrowInputError(path, std::string("cannot write: ") + std::strerror(errno));
  size_t written = 0;
  bool ok = true;
  while (written < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + written, bytes.size() - written);
    if (n < 0) {
      if (errno == EINTR) continue;
      ok = false;
      break;
    }
    written += static_cast<size_t>(n);
  }
  const int saved_errno = errno;
  ok = ok && ::fsync(fd) == 0;
  ok = (::close(fd) == 0) && ok;
  std::error_code ignored;
  if (!ok) {
    std::filesystem::remove(tmp, ignored);
    ThrowInputError(path, std::string("cannot write: ") + std::strerror(saved_errno));
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::filesystem::remove(tmp, ignored);
    ThrowInputError(path, "cannot rename the temp file: " + ec.message());
  }
}

double MapCameraHeight(const MapFileData& data) {
  try {
    const YAML::Node options = YAML::Load(data.options_yaml);
    if (!options.IsMap() || !options["depth"].IsMap()) return 0.0;
    const YAML::Node height = options["depth"]["camera_height"];
    return height.IsScalar() ? std::max(0.0, height.as<double>()) : 0.0;
  } catch (const YAML::Exception&) {
    return 0.0;  // a file's options are informative only: unreadable ones say nothing
  }
}

namespace {

// MapScaleOf with the camera height already read (the options are parsed once).
MapScale ScaleOf(const MapFileData& data, double camera_height) {
  for (const MapKeyFrameRecord& kf : data.keyframes)
    for (float z : kf.depth)
      if (z > 0) return MapScale::kDepth;
  return camera_height > 0 ? MapScale::kRoad : MapScale::kArbitrary;
}

}  // namespace

MapScale MapScaleOf(const MapFileData& data) { return ScaleOf(data, MapCameraHeight(data)); }

MapFileSummary SummarizeMap(const MapFileData& data, uint64_t file_size) {
  MapFileSummary s;
  s.camera_height = MapCameraHeight(data);
  s.scale = ScaleOf(data, s.camera_height);
  s.version = data.version;
  s.file_size = file_size;
  s.camera = data.camera;
  s.num_keyframes = data.keyframes.size();
  s.num_points = data.points.size();
  s.options_yaml = data.options_yaml;
  bool first = true;
  for (const auto& p : data.points) {
    const Eigen::Vector3d x(p.position[0], p.position[1], p.position[2]);
    s.min_corner = first ? x : s.min_corner.cwiseMin(x);
    s.max_corner = first ? x : s.max_corner.cwiseMax(x);
    first = false;
    s.num_observations += p.observations.size();
    if (p.admitted == 0) ++s.num_points_not_admitted;
  }
  return s;
}

std::string MapSummaryText(const std::filesystem::path& path, const MapFileSummary& s) {
  std::ostringstream o;
  o << std::setprecision(6);
  o << "map: " << path.string() << "\n";
  o << "format version: " << s.version << "\n";
  o << "file size: " << s.file_size << " bytes\n";
  o << "camera: " << s.camera.width << "x" << s.camera.height << " fx " << s.camera.fx << " fy "
    << s.camera.fy << " cx " << s.camera.cx << " cy " << s.camera.cy << " distortion ["
    << s.camera.distortion[0] << ", " << s.camera.distortion[1] << ", " << s.camera.distortion[2]
    << ", " << s.camera.distortion[3] << ", " << s.camera.distortion[4] << "]\n";
  o << "keyframes: " << s.num_keyframes << "\n";
  o << "map points: " << s.num_points << " (" << s.num_points_not_admitted
    << " not admitted: awaiting a confirming view or judged moving)\n";
  o << "observations: " << s.num_observations << "\n";
  const bool metric = s.scale != MapScale::kArbitrary;
  o << "scale: ";
  if (s.scale == MapScale::kDepth) {
    o << "metric (built with sensor or network depth)";
  } else if (s.scale == MapScale::kRoad) {
    o << "metric (the road held at the camera height, " << s.camera_height << " m)";
  } else {
    o << "arbitrary (built with --depth none: geometry alone, in units of its two-view start)";
  }
  o << "\n";
  o << "bounding box (" << (metric ? "m" : "map units") << "): min [" << s.min_corner.x() << ", "
    << s.min_corner.y() << ", " << s.min_corner.z() << "] max [" << s.max_corner.x() << ", " << s.max_corner.y() << ", "
    << s.max_corner.z() << "]\n";
  o << "options:\n";
  std::istringstream lines(s.options_yaml);
  for (std::string line; std::getline(lines, line);) o << "  " << line << "\n";
  return o.str();
}

void RestoreMap(const MapFileData& data, const std::shared_ptr<const ScalePyramid>& pyramid,
                Map& map, const std::filesystem::path& path_for_errors) {
  if (map.NumKeyFrames() != 0) throw std::logic_error("RestoreMap: the map is not empty");
  for (const auto& r : data.keyframes) {
    for (const auto& k : r.keypoints) {
      if (k.octave >= pyramid->num_levels)
        ThrowInputError(path_for_errors,
                        "keyframe " + std::to_string(r.id) + ": keypoint on pyramid level " +
                            std::to_string(k.octave) + ", the ORB options have " +
                            std::to_string(pyramid->num_levels) + " levels");
    }
  }
  std::map<uint64_t, KeyFrame*> keyframes;
  for (const auto& r : data.keyframes) {
    std::vector<cv::KeyPoint> keypoints;
    keypoints.reserve(r.keypoints.size());
    for (const auto& k : r.keypoints)
      keypoints.emplace_back(cv::Point2f(k.x, k.y), k.size, k.angle, k.response, k.octave);
    cv::Mat descriptors(static_cast<int>(r.keypoints.size()), 32, CV_8UC1);
    if (!r.descriptors.empty())
      std::memcpy(descriptors.data, r.descriptors.data(), r.descriptors.size());
    auto built = MakeFrameFeatures(
        data.camera, pyramid, data.camera.fx > 0 ? r.bf / data.camera.fx : 0, r.close_depth,
        std::move(keypoints), descriptors, r.depth,
        {r.depth_error_relative, r.depth_error_per_metre}, r.weight_by_error_model != 0);
    // Exactly the saved values (bf / fx * fx may differ in the last bit).
    auto features = std::make_shared<FrameFeatures>(*built);
    features->intrinsics.bf = r.bf;
    features->close_depth = r.close_depth;
    features->depth_scale = r.depth_scale;
    for (size_t i = 0; i < features->Size(); ++i) {
      if (features->depth[i] > 0)
        features->u_right[i] =
            static_cast<float>(features->keypoints_un[i].pt.x - r.bf / features->depth[i]);
    }
    Frame frame(r.frame_id, r.index, r.timestamp, std::move(features));
    frame.cam_from_world = PoseFromArray(r.cam_from_world);
    keyframes[r.id] = map.RestoreKeyFrame(r.id, frame).get();
  }
  for (const auto& r : data.keyframes) {
    KeyFrame* kf = keyframes.at(r.id);
    if (r.parent >= 0) {
      kf->parent = keyframes.at(static_cast<uint64_t>(r.parent));
      kf->parent->children.insert(kf);
    }
    for (const auto& [id, weight] : r.connections) kf->connections[keyframes.at(id)] = weight;
    kf->SortConnections();
  }
  for (const auto& r : data.points) {
    KeyFrame* reference = keyframes.count(r.reference) ? keyframes.at(r.reference)
                                                       : keyframes.at(r.observations.front().first);
    auto p = map.RestoreMapPoint(r.id, {r.position[0], r.position[1], r.position[2]}, reference,
                                 r.first_frame_id);
    p->first_keyframe_id = r.first_keyframe_id;
    p->normal = {r.normal[0], r.normal[1], r.normal[2]};
    p->descriptor = cv::Mat(1, 32, CV_8UC1);
    std::memcpy(p->descriptor.data, r.descriptor.data(), 32);
    p->min_distance = r.min_distance;
    p->max_distance = r.max_distance;
    p->visible = r.visible;
    p->found = r.found;
    p->dynamic_hits = r.dynamic_hits;
    p->static_probability = r.static_probability;
    p->admitted = r.admitted != 0;
    for (const auto& [id, idx] : r.observations) {
      KeyFrame* kf = keyframes.at(id);
      p->AddObservation(kf, idx);
      kf->AddMapPoint(p, idx);
    }
  }
  map.SetNextIds(std::max(map.NextKeyFrameId(), data.next_keyframe_id),
                 std::max(map.NextMapPointId(), data.next_point_id));
}

}  // namespace ademono
