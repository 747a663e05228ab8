#include "ademono/slam/map_io.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <fstream>
#include <sstream>

#include "ademono/core/error.h"
#include "ademono/slam/system.h"
#include "slam_test_util.h"

namespace ademono {
namespace {

namespace fs = std::filesystem;
using testing_util::Slice;

SystemOptions TestOptions() {
  SystemOptions options;
  options.depth.min_depth = 0.3;
  options.depth.max_depth = 6.0;
  return options;
}

void Track(System& system, const Sequence& sequence, std::vector<TrackResult>* results = nullptr) {
  for (size_t i = 0; i < sequence.Size(); ++i) {
    const FrameData frame = sequence.Load(i);
    const TrackResult r = system.TrackFrame(frame, testing_util::SensorDepth(frame), {});
    if (results != nullptr) results->push_back(r);
  }
  system.Shutdown();
}

std::string ReadBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

void WriteBytes(const fs::path& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out << bytes;
}

class MapIoTest : public ::testing::Test {
 protected:
  // One map of 7-Scenes frames 0-59, built once for the whole suite.
  static void SetUpTestSuite() {
    dir_ = std::make_unique<fs::path>(fs::temp_directory_path() /
                                      ("ademono_map_io_" + std::to_string(::getpid())));
    fs::create_directories(*dir_);
    const auto sequence = Slice(0, 60);
    System system(sequence->GetCamera(), TestOptions());
    Track(system, *sequence);
    system.SaveMap(MapPath());
    keyframes_ = system.NumKeyFrames();
    points_ = system.NumMapPoints();
  }
  static void TearDownTestSuite() {
    fs::remove_all(*dir_);
    dir_.reset();
  }
  static fs::path MapPath() { return *dir_ / "a.map"; }
  static inline std::unique_ptr<fs::path> dir_;
  static size_t keyframes_, points_;
};
size_t MapIoTest::keyframes_ = 0, MapIoTest::points_ = 0;

// The ground truth of frame i in the first session's world (its first camera).
Rigid3d GroundTruthInFirstSession(const Sequence& full, size_t i) {
  return full.Load(0).world_from_cam_gt->inverse() * *full.Load(i).world_from_cam_gt;
}

// Largest position error of a second-session trajectory starting at frame `first`, in the first
// session's frame (no alignment: the loaded map fixes it).
double WorstErrorInFirstSession(const Sequence& full, size_t first, const Trajectory& trajectory) {
  double worst = 0;
  for (size_t k = 0; k < trajectory.size(); ++k) {
    const Rigid3d gt = GroundTruthInFirstSession(full, first + k);
    worst = std::max(worst, (gt.translation() - trajectory[k].world_from_cam.translation()).norm());
  }
  return worst;
}

void ExpectSameTrajectory(const Trajectory& a, const Trajectory& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i)
    EXPECT_TRUE(a[i].world_from_cam.matrix() == b[i].world_from_cam.matrix()) << i;
}

// loop.global_ba_on_save: the map is refined by a global bundle adjustment before it is written,
// the same way every time, and the run's trajectory follows it.
TEST_F(MapIoTest, GlobalBundleAdjustmentOnSaveRefinesTheSavedMapDeterministically) {
  const auto sequence = Slice(0, 60);
  SystemOptions options = TestOptions();
  options.loop.global_ba_on_save = true;
  std::vector<std::string> bytes;
  std::vector<Trajectory> keyframes;
  for (int rep = 0; rep < 2; ++rep) {
    System system(sequence->GetCamera(), options);
    Track(system, *sequence);
    const fs::path path = *dir_ / ("on_save_" + std::to_string(rep) + ".map");
    system.SaveMap(path);
    EXPECT_EQ(system.NumKeyFrames(), keyframes_);
    bytes.push_back(ReadBytes(path));
    keyframes.push_back(system.KeyFrameTrajectory());
  }
  EXPECT_EQ(bytes[0], bytes[1]);
  EXPECT_NE(bytes[0], ReadBytes(MapPath()));  // the map without it (same frames and options)
  // The refined keyframes moved, and by little: the local BAs had done most of the work.
  System plain(sequence->GetCamera(), TestOptions());
  Track(plain, *sequence);
  const Trajectory before = plain.KeyFrameTrajectory();
  ASSERT_EQ(before.size(), keyframes[0].size());
  double moved = 0;
  for (size_t k = 0; k < before.size(); ++k) {
    moved = std::max(moved, (before[k].world_from_cam.translation() -
                             keyframes[0][k].world_from_cam.translation())
                                .norm());
  }
  EXPECT_GT(moved, 1e-6);
  EXPECT_LT(moved, 0.05);
  ExpectSameTrajectory(keyframes[0], keyframes[1]);
}

TEST_F(MapIoTest, SaveLoadSaveIsByteIdentical) {
  const MapFileData data = LoadMapFile(MapPath());
  EXPECT_EQ(data.keyframes.size(), keyframes_);
  EXPECT_EQ(data.points.size(), points_);
  EXPECT_GT(keyframes_, 1u);
  System system(Slice(0, 1)->GetCamera(), TestOptions());
  system.LoadMap(MapPath(), true);
  EXPECT_EQ(system.NumKeyFrames(), keyframes_);
  EXPECT_EQ(system.NumMapPoints(), points_);
  EXPECT_EQ(system.GetKeyFrameDatabase().Size(), keyframes_);
  const fs::path again = *dir_ / "again.map";
  system.SaveMap(again);
  EXPECT_TRUE(ReadBytes(again) == ReadBytes(MapPath()));
}

TEST_F(MapIoTest, LocalizeOnlyRelocalisesEveryFrameAndNeverChangesTheMap) {
  const std::string before = ReadBytes(MapPath());
  // Frames 60-89: after the map's frames.
  const auto sequence = Slice(60, 90);
  const auto full = Slice(0, 90);
  auto run = [&] {
    System system(sequence->GetCamera(), TestOptions());
    system.LoadMap(MapPath(), true);
    std::vector<TrackResult> results;
    Track(system, *sequence, &results);
    EXPECT_TRUE(results.front().relocalised);
    for (const TrackResult& r : results) {
      EXPECT_TRUE(r.tracked) << r.index;
      EXPECT_FALSE(r.new_keyframe);
    }
    EXPECT_EQ(system.NumKeyFrames(), keyframes_);
    EXPECT_EQ(system.NumMapPoints(), points_);
    const fs::path after = *dir_ / "after_localize.map";
    system.SaveMap(after);
    EXPECT_TRUE(ReadBytes(after) == before) << "the map changed in localisation-only mode";
    return system.FrameTrajectory();
  };
  const Trajectory a = run();
  ASSERT_EQ(a.size(), 30u);
  EXPECT_LT(WorstErrorInFirstSession(*full, 60, a), 0.05);  // no alignment
  ExpectSameTrajectory(a, run());
  EXPECT_TRUE(ReadBytes(MapPath()) == before);
}

TEST_F(MapIoTest, TemporaryMapLocalisationNeverChangesTheLoadedMap) {
  // tracking.temporary_map: keyframes and points are made beside the loaded map (local BA with
  // it held fixed) and never saved; the loaded keyframes and points stay exactly as read.
  const std::string before = ReadBytes(MapPath());
  const MapFileData loaded = LoadMapFile(MapPath());
  const auto sequence = Slice(60, 120);
  const auto full = Slice(0, 120);
  SystemOptions options = TestOptions();
  options.tracking.temporary_map = true;
  auto run = [&]() -> Trajectory {
    System system(sequence->GetCamera(), options);
    system.LoadMap(MapPath(), true);
    std::vector<TrackResult> results;
    Track(system, *sequence, &results);
    EXPECT_TRUE(results.front().relocalised);
    int tracked = 0, new_keyframes = 0;
    for (const TrackResult& r : results) {
      tracked += r.tracked;
      new_keyframes += r.new_keyframe ? 1 : 0;
    }
    EXPECT_EQ(tracked, 60);
    EXPECT_GT(new_keyframes, 0);  // the temporary map is used
    const MapFileData now = system.MapRecords();
    EXPECT_GT(now.keyframes.size(), loaded.keyframes.size());
    std::map<uint64_t, const MapKeyFrameRecord*> keyframes;
    for (const auto& k : now.keyframes) keyframes[k.id] = &k;
    for (const auto& k : loaded.keyframes) {
      if (!keyframes.count(k.id)) {
        ADD_FAILURE() << "loaded keyframe " << k.id << " culled";
        continue;
      }
      EXPECT_TRUE(keyframes[k.id]->cam_from_world == k.cam_from_world) << k.id;
    }
    std::map<uint64_t, const MapPointRecord*> points;
    for (const auto& p : now.points) points[p.id] = &p;
    for (const auto& p : loaded.points) {
      if (!points.count(p.id)) {
        ADD_FAILURE() << "loaded point " << p.id << " erased";
        continue;
      }
      const MapPointRecord& q = *points[p.id];
      EXPECT_TRUE(q.position == p.position && q.normal == p.normal &&
                  q.descriptor == p.descriptor && q.visible == p.visible && q.found == p.found)
          << p.id;
      for (const auto& o : p.observations) {
        EXPECT_TRUE(std::find(q.observations.begin(), q.observations.end(), o) !=
                    q.observations.end())
            << p.id;
      }
    }
    const fs::path after = *dir_ / "after_temporary.map";
    system.SaveMap(after);
    EXPECT_TRUE(ReadBytes(after) == before) << "a temporary keyframe or point was saved";
    return system.FrameTrajectory();
  };
  const Trajectory a = run();
  ASSERT_EQ(a.size(), 60u);
  EXPECT_LT(WorstErrorInFirstSession(*full, 60, a), 0.05);  // no alignment
  ExpectSameTrajectory(a, run());
  EXPECT_TRUE(ReadBytes(MapPath()) == before);
}

TEST_F(MapIoTest, WithoutLocalizeOnlyTheLoadedMapIsExtended) {
  const auto sequence = Slice(60, 90);
  System system(sequence->GetCamera(), TestOptions());
  system.LoadMap(MapPath(), false);
  std::vector<TrackResult> results;
  Track(system, *sequence, &results);
  int tracked = 0;
  for (const TrackResult& r : results) tracked += r.tracked;
  EXPECT_EQ(tracked, 30);
  EXPECT_GT(system.NumKeyFrames(), keyframes_);
}

TEST_F(MapIoTest, BadMapsFailWithOneLineNamingTheFile) {
  const std::string good = ReadBytes(MapPath());
  auto expect_error = [&](const std::string& bytes, const std::string& needle) {
    const fs::path bad = *dir_ / "bad.map";
    WriteBytes(bad, bytes);
    try {
      LoadMapFile(bad);
      ADD_FAILURE() << "no error for " << needle;
    } catch (const InputError& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(bad.string()), std::string::npos) << message;
      EXPECT_NE(message.find(needle), std::string::npos) << message;
      EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    }
  };
  expect_error(good.substr(0, good.size() / 2), "truncated");
  expect_error(good.substr(0, 12), "truncated");
  expect_error("", "bad magic");
  expect_error("hello world, not a map at all", "bad magic");
  std::string version = good;
  version[8] = 7;
  expect_error(version, "version 7");
  std::string flipped = good;
  flipped[good.size() / 2] ^= 0x10;
  expect_error(flipped, "checksum mismatch");
  expect_error(good + "x", "bytes after the payload");
  try {
    LoadMapFile(*dir_ / "missing.map");
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("not found"), std::string::npos);
  }
  // A consistent file whose payload refers to a keyframe that does not exist.
  MapFileData data = LoadMapFile(MapPath());
  data.points.front().observations.front().first = 999999;
  expect_error(SerializeMapFile(data), "unknown keyframe");
  // Found by fuzz_map_file in CI: a keypoint at 1.6e28 px overflowed the grid's int cast.
  data = LoadMapFile(MapPath());
  data.keyframes.front().keypoints.front().x = 1.58577e28f;
  expect_error(SerializeMapFile(data), "keypoint outside the image");
  // Also found by fuzz_map_file: a flag byte of 3 loaded into a bool (undefined behaviour).
  data = LoadMapFile(MapPath());
  data.keyframes.front().weight_by_error_model = 3;
  expect_error(SerializeMapFile(data), "bad weight_by_error_model flag");
  data = LoadMapFile(MapPath());
  data.points.front().static_probability = 1.5;
  expect_error(SerializeMapFile(data), "static probability outside [0, 1]");
  data = LoadMapFile(MapPath());
  data.points.front().admitted = 2;
  expect_error(SerializeMapFile(data), "admitted flag is neither 0 nor 1");
}

// Format 2 keeps each point's static probability and admission: the geometric test's belief
// survives a reload, so points a mover left unconfirmed stay out of localisation.
TEST_F(MapIoTest, StaticProbabilityAndAdmissionSurviveTheRoundTrip) {
  const MapFileData data = LoadMapFile(MapPath());
  EXPECT_EQ(data.version, kMapFormatVersion);
  size_t not_admitted = 0, below_one = 0;
  for (const MapPointRecord& p : data.points) {
    not_admitted += p.admitted == 0;
    below_one += p.static_probability < 1;
  }
  // The last keyframes' points still wait for a confirming view.
  EXPECT_GT(not_admitted, 0u);
  EXPECT_GE(below_one, not_admitted);
  // Loaded to be extended, the map is written from the restored points themselves (not the
  // loaded records): the same bytes, so every point got its probability and flag back.
  System system(Slice(0, 1)->GetCamera(), TestOptions());
  system.LoadMap(MapPath(), false);
  const fs::path again = *dir_ / "extended_nothing.map";
  system.SaveMap(again);
  EXPECT_TRUE(ReadBytes(again) == ReadBytes(MapPath()));
  // Version 1 semantics for the same map: every point static and admitted.
  MapFileData all_static = data;
  for (MapPointRecord& p : all_static.points) p.static_probability = 1, p.admitted = 1;
  EXPECT_FALSE(SerializeMapFile(all_static) == ReadBytes(MapPath()));
}

// A version 1 file (before static probabilities were saved) still loads, every point static and
// admitted as version 1 meant, and saves back to its own bytes.
TEST_F(MapIoTest, VersionOneMapsAreStillRead) {
  MapFileData data = LoadMapFile(MapPath());
  data.version = 1;
  const std::string v1 = SerializeMapFile(data);
  EXPECT_EQ(v1[8], 1);
  EXPECT_LT(v1.size(), ReadBytes(MapPath()).size());  // no static fields
  const fs::path path = *dir_ / "v1.map";
  WriteBytes(path, v1);
  const MapFileData read = LoadMapFile(path);
  EXPECT_EQ(read.version, 1u);
  ASSERT_EQ(read.points.size(), data.points.size());
  for (const MapPointRecord& p : read.points) {
    EXPECT_EQ(p.static_probability, 1.0);
    EXPECT_EQ(p.admitted, 1);
  }
  EXPECT_TRUE(SerializeMapFile(read) == v1);
  EXPECT_NE(MapSummaryText(path, SummarizeMap(read, v1.size())).find("format version: 1"),
            std::string::npos);
}

TEST_F(MapIoTest, CameraThatDiffersFromTheSequenceIsRejected) {
  Camera other = Slice(0, 1)->GetCamera();
  other.fx += 10;
  System system(other, TestOptions());
  try {
    system.LoadMap(MapPath(), true);
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("does not match the sequence"), std::string::npos)
        << e.what();
  }
  EXPECT_EQ(system.NumKeyFrames(), 0u);
}

TEST_F(MapIoTest, SummaryCountsWhatTheMapHolds) {
  const MapFileData data = LoadMapFile(MapPath());
  const MapFileSummary s = SummarizeMap(data, fs::file_size(MapPath()));
  EXPECT_EQ(s.num_keyframes, keyframes_);
  EXPECT_EQ(s.num_points, points_);
  EXPECT_GE(s.num_observations, points_);
  EXPECT_TRUE((s.min_corner.array() < s.max_corner.array()).all());
  const std::string text = MapSummaryText(MapPath(), s);
  EXPECT_NE(text.find("format version: 2"), std::string::npos);
  EXPECT_GT(s.num_points_not_admitted, 0u);
  EXPECT_NE(text.find("map points: " + std::to_string(points_) + " (" +
                      std::to_string(s.num_points_not_admitted) + " not admitted"),
            std::string::npos);
  EXPECT_NE(text.find("keyframes: " + std::to_string(keyframes_)), std::string::npos);
  EXPECT_NE(text.find("tracking:"), std::string::npos);  // the options
  // Built with sensor depth: metres.
  EXPECT_TRUE(MapHasMetricScale(data));
  EXPECT_EQ(s.scale, MapScale::kDepth);
  EXPECT_NE(text.find("scale: metric"), std::string::npos);
  EXPECT_NE(text.find("bounding box (m)"), std::string::npos);
  System system(Slice(0, 1)->GetCamera(), TestOptions());
  system.LoadMap(MapPath(), true);
  EXPECT_TRUE(system.LoadedMapHasMetricScale());
}

// Without keyframe depth (--depth none) a map is metric only where its run held the road at the
// rig's camera height (outdoors); its options say so. Options that do not parse say nothing.
TEST_F(MapIoTest, AMapWithoutDepthIsMetricOnlyWithACameraHeight) {
  MapFileData data = LoadMapFile(MapPath());
  for (MapKeyFrameRecord& kf : data.keyframes) std::fill(kf.depth.begin(), kf.depth.end(), -1.0f);
  data.options_yaml = "depth:\n  camera_height: 1.65\n  min_depth: 1\n";
  EXPECT_EQ(MapScaleOf(data), MapScale::kRoad);
  EXPECT_DOUBLE_EQ(MapCameraHeight(data), 1.65);
  EXPECT_TRUE(MapHasMetricScale(data));
  const std::string road = MapSummaryText("x.map", SummarizeMap(data, 0));
  EXPECT_NE(road.find("scale: metric (the road held at the camera height, 1.65 m)"),
            std::string::npos)
      << road;
  EXPECT_NE(road.find("bounding box (m)"), std::string::npos);
  for (const std::string& options :
       {std::string("depth:\n  camera_height: 0\n"), std::string("tracking: {}\n"),
        std::string("depth: [1, 2\n"), std::string("depth: 3\n"), std::string("")}) {
    data.options_yaml = options;
    EXPECT_EQ(MapScaleOf(data), MapScale::kArbitrary) << options;
    EXPECT_FALSE(MapHasMetricScale(data)) << options;
  }
}

}  // namespace
}  // namespace ademono
