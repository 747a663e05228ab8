#include "ademono/report/report.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iomanip>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "ademono/core/error.h"
#include "ademono/core/file_util.h"
#include "ademono/core/statistics.h"
#include "ademono/core/yaml_util.h"
#include "ademono/report/web_assets.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace ademono {
namespace {

constexpr const char* kSchema = "ademono.run/1";
// Per-frame stage times: the prefetch worker computes depth and detection of frame k+1 while the
// main thread extracts, filters, tracks and maps frame k (slam/pipeline), so a frame costs the
// longer of the two branches.
const std::vector<std::string> kWorkerStages = {"depth", "detection"};
const std::vector<std::string> kMainStages = {"extraction", "filter", "tracking", "mapping"};
// Stages a newer summary.json places on a thread ("timing".<stage>.thread): decode, extraction
// and keypoint depths run on the prefetch worker when the pipeline overlaps frames.
const std::vector<std::string> kMovableStages = {"decode", "extraction", "keypoint_depth"};

// The main-thread and worker stages of a run: the fixed lists above, with kMovableStages put
// where summary.json's "timing" says they ran (absent there: the fixed lists, older runs).
std::pair<std::vector<std::string>, std::vector<std::string>> StageBranches(const json& timing) {
  std::vector<std::string> main, worker;
  auto thread_of = [&](const std::string& stage) -> std::string {
    if (!timing.is_object() || !timing.contains(stage) || !timing[stage].is_object()) return "";
    return timing[stage].value("thread", std::string());
  };
  for (const auto& s : kMovableStages) {
    const std::string t = thread_of(s);
    if (t == "prefetch") worker.push_back(s);
    else if (t == "tracking" || (t.empty() && s == "extraction")) main.push_back(s);
  }
  for (const auto& s : kMainStages)
    if (s != "extraction") main.push_back(s);
  for (const auto& s : kWorkerStages) worker.push_back(s);
  return {main, worker};
}

std::string Base64(const uint8_t* data, size_t size) {
  static const char* kAlphabet =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((size + 2) / 3 * 4);
  for (size_t i = 0; i < size; i += 3) {
    const uint32_t b0 = data[i];
    const uint32_t b1 = i + 1 < size ? data[i + 1] : 0;
    const uint32_t b2 = i + 2 < size ? data[i + 2] : 0;
    const uint32_t v = (b0 << 16) | (b1 << 8) | b2;
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += i + 1 < size ? kAlphabet[(v >> 6) & 63] : '=';
    out += i + 2 < size ? kAlphabet[v & 63] : '=';
  }
  return out;
}

// Rounded so the embedded JSON stays small (millimetres, microseconds are below what a plot shows).
double Round(double v, double step) { return std::round(v / step) * step; }

json RequireKey(const json& object, const char* key, const fs::path& file) {
  if (!object.is_object() || !object.contains(key)) {
    ThrowInputError(file, std::string("missing key '") + key + "'");
  }
  return object.at(key);
}

// Applies the similarity (scale, rotation, translation) to a point.
Eigen::Vector3d Apply(const Similarity& s, const Eigen::Vector3d& p) {
  return s.scale * (s.rotation * p) + s.translation;
}

json XyzColumns(const std::vector<Eigen::Vector3d>& points) {
  json x = json::array(), y = json::array(), z = json::array();
  for (const Eigen::Vector3d& p : points) {
    x.push_back(Round(p.x(), 1e-4));
    y.push_back(Round(p.y(), 1e-4));
    z.push_back(Round(p.z(), 1e-4));
  }
  return json::array({x, y, z});
}

// Thumbnail of viz/frame-XXXXXX.jpg, downscaled, as base64 JPEG; nullopt when the file is absent.
std::optional<std::string> Thumbnail(const fs::path& viz_dir, int frame,
                                     const ReportOptions& options) {
  std::ostringstream name;
  name << "frame-" << std::setw(6) << std::setfill('0') << frame << ".jpg";
  const fs::path path = viz_dir / name.str();
  if (!fs::is_regular_file(path)) return std::nullopt;
  const cv::Mat image = ReadImage(path, cv::IMREAD_COLOR);
  cv::Mat small = image;
  if (image.cols > options.thumbnail_width) {
    const double f = static_cast<double>(options.thumbnail_width) / image.cols;
    cv::resize(image, small, cv::Size(), f, f, cv::INTER_AREA);
  }
  std::vector<uint8_t> bytes;
  cv::imencode(".jpg", small, bytes, {cv::IMWRITE_JPEG_QUALITY, options.thumbnail_jpeg_quality});
  return Base64(bytes.data(), bytes.size());
}

struct AlignedRun {
  std::optional<EvalResult> eval;
  Similarity gt_from_est;  // identity without ground truth
  std::string note;
};

AlignedRun Align(const RunFolder& run, Alignment alignment) {
  AlignedRun aligned;
  if (!run.ground_truth) {
    aligned.note =
        "no ground truth in the run folder (groundtruth.tum): the estimate is drawn as is";
    return aligned;
  }
  EvalOptions eval;
  eval.alignment = alignment;
  try {
    aligned.eval = EvaluateTrajectories(*run.ground_truth, run.trajectory, eval);
    aligned.gt_from_est = aligned.eval->gt_from_est;
  } catch (const std::exception& e) {
    aligned.note = std::string("no alignment: ") + e.what();
  }
  return aligned;
}

// traj[t_key]: times since t0; traj[xyz_key]: positions in the aligned world.
void AddAlignedPositions(const Trajectory& poses, const AlignedRun& aligned, double t0,
                         const char* t_key, const char* xyz_key, json& traj) {
  std::vector<Eigen::Vector3d> xyz;
  json t = json::array();
  for (const StampedPose& p : poses) {
    xyz.push_back(Apply(aligned.gt_from_est, p.world_from_cam.translation()));
    t.push_back(Round(p.timestamp - t0, 1e-4));
  }
  traj[t_key] = std::move(t);
  traj[xyz_key] = XyzColumns(xyz);
}

json TrajectoryJson(const RunFolder& run, const AlignedRun& aligned, double t0) {
  json traj;
  AddAlignedPositions(run.trajectory, aligned, t0, "t", "est", traj);
  // Mean optical axis (camera z in the aligned world), so the 3D view starts looking the way the
  // camera looked.
  Eigen::Vector3d axis = Eigen::Vector3d::Zero();
  for (const StampedPose& p : run.trajectory)
    axis += aligned.gt_from_est.rotation * p.world_from_cam.linear().col(2);
  if (axis.norm() > 1e-9) {
    axis.normalize();
    traj["view_dir"] = {axis.x(), axis.y(), axis.z()};
  }
  if (aligned.eval) {
    const EvalResult& e = *aligned.eval;
    std::vector<Eigen::Vector3d> gt;
    json gt_t = json::array(), err = json::array();
    for (size_t i = 0; i < e.gt_matched.size(); ++i) {
      gt.push_back(e.gt_matched.world_from_cam[i].block<3, 1>(0, 3));
      gt_t.push_back(Round(e.est_aligned.timestamps[i] - t0, 1e-4));
      err.push_back(Round(e.ape_errors[i], 1e-5));
    }
    traj["gt_t"] = std::move(gt_t);
    traj["gt"] = XyzColumns(gt);
    traj["err"] = std::move(err);
    json worst;
    if (!e.ape_errors.empty()) {
      const size_t i = std::max_element(e.ape_errors.begin(), e.ape_errors.end()) -
                       e.ape_errors.begin();
      worst = {{"t", e.est_aligned.timestamps[i] - t0}, {"timestamp", e.est_aligned.timestamps[i]},
               {"error_m", e.ape_errors[i]}};
    }
    traj["worst"] = worst;
    traj["ate"] = ToJson(e.ape);
    traj["scale"] = e.gt_from_est.scale;
  }
  AddAlignedPositions(run.keyframes, aligned, t0, "kf_t", "kf", traj);
  return traj;
}

json MapJson(const RunFolder& run, const AlignedRun& aligned, const ReportOptions& options) {
  json map;
  const size_t total = run.map.xyz.size();
  map["total"] = total;
  if (!run.has_map) {
    map["note"] = "no map.ply in the run folder";
    map["count"] = 0;
    return map;
  }
  // An even stride keeps the subset spread over the whole map and deterministic.
  const size_t cap = static_cast<size_t>(options.max_map_points);
  const size_t stride = total > cap ? (total + cap - 1) / cap : 1;
  std::vector<float> xyz;
  std::vector<uint8_t> rgb;
  for (size_t i = 0; i < total; i += stride) {
    const Eigen::Vector3d p = Apply(aligned.gt_from_est, run.map.xyz[i].cast<double>());
    for (int k = 0; k < 3; ++k) xyz.push_back(static_cast<float>(p[k]));
    for (int k = 0; k < 3; ++k) rgb.push_back(run.map.rgb[i][k]);
  }
  map["count"] = xyz.size() / 3;
  map["stride"] = stride;
  // Float32 little-endian, decoded in the page straight into a typed array.
  map["xyz_b64"] = Base64(reinterpret_cast<const uint8_t*>(xyz.data()), xyz.size() * sizeof(float));
  map["rgb_b64"] = Base64(rgb.data(), rgb.size());
  return map;
}

// Per-frame columns (one array per field) from summary.json's per_frame list.
json FramesJson(const RunFolder& run, double t0) {
  const fs::path file = run.dir / "summary.json";
  const json& per_frame = run.summary.at("per_frame");
  json cols;
  std::vector<std::string> ints = {"keypoints", "kept", "with_depth", "inliers",
                                   "dynamic_points_culled"};
  for (const char* k : {"frame", "t", "tracked", "state", "relocalised", "keyframe"})
    cols[k] = json::array();
  for (const auto& k : ints) cols[k] = json::array();
  // Optional (runs before the geometric test lack them): -1 = not recorded, left out of the plot.
  const std::vector<std::string> optional_ints = {"static_points", "geometric_dynamic"};
  for (const auto& k : optional_ints) cols[k] = json::array();
  cols["weak"] = json::array();  // 0 good (or untracked), 1 few static points, 2 motion model, 3
                                 // depth odometry
  json filter = json::object(), ms = json::object(), depth_scale = json::array();
  json scale_sigma = json::array();  // the metric scale's relative standard error, per frame
  bool any_scale = false, any_sigma = false;
  size_t i = 0;
  for (const json& f : per_frame) {
    const std::string where = "per_frame[" + std::to_string(i) + "]";
    try {
      cols["frame"].push_back(f.at("frame").get<int>());
      cols["t"].push_back(Round(f.at("timestamp").get<double>() - t0, 1e-4));
      cols["tracked"].push_back(f.at("tracked").get<bool>() ? 1 : 0);
      const std::string state = f.at("state").get<std::string>();
      if (state != "not_initialized" && state != "ok" && state != "lost") {
        ThrowInputError(file, where + ".state: unknown state '" + state + "'");
      }
      cols["state"].push_back(state == "ok" ? 1 : state == "lost" ? 2 : 0);
      cols["relocalised"].push_back(f.at("relocalised").get<bool>() ? 1 : 0);
      cols["keyframe"].push_back(f.at("keyframe").get<bool>() ? 1 : 0);
      for (const auto& k : ints) cols[k].push_back(f.at(k).get<int>());
      for (const auto& k : optional_ints) cols[k].push_back(f.value(k, -1));
      const std::string quality = f.value("pose_quality", std::string("good"));
      cols["weak"].push_back(quality == "few_static_points" ? 1
                             : quality == "motion_model" ? 2
                             : quality == "depth_odometry" ? 3
                                                          : 0);
      // "filter" and "ms" may be absent, but then from every frame (checked below).
      if (f.contains("filter")) {
        for (const auto& [name, value] : f["filter"].items()) {
          if (!filter.contains(name)) filter[name] = json::array();
          filter[name].push_back(value.get<double>());
        }
      }
      if (f.contains("ms")) {
        for (const auto& [name, value] : f["ms"].items()) {
          if (!ms.contains(name)) ms[name] = json::array();
          ms[name].push_back(Round(value.get<double>(), 1e-3));
        }
      }
      if (f.contains("depth_scale") && !f["depth_scale"].is_null()) {
        depth_scale.push_back(f["depth_scale"].get<double>());
        any_scale = true;
      } else {
        depth_scale.push_back(nullptr);
      }
      if (f.contains("scale_sigma") && !f["scale_sigma"].is_null()) {
        scale_sigma.push_back(f["scale_sigma"].get<double>());
        any_sigma = true;
      } else {
        scale_sigma.push_back(nullptr);
      }
    } catch (const json::exception& e) {
      ThrowInputError(file, where + ": " + e.what());
    }
    ++i;
  }
  // Every frame must carry the same filter and timing fields (a column per field).
  for (const json* group : {&filter, &ms}) {
    for (const auto& [name, values] : group->items()) {
      if (values.size() != per_frame.size()) {
        ThrowInputError(file, "per_frame: '" + name + "' is missing in some frames");
      }
    }
  }
  cols["filter"] = std::move(filter);
  cols["ms"] = std::move(ms);
  // The rows of each input frame, for the summary's per-loop and per-keyframe entries.
  std::map<int, std::vector<size_t>> rows_of_frame;
  for (size_t k = 0; k < per_frame.size(); ++k)
    rows_of_frame[cols["frame"][k].get<int>()].push_back(k);
  auto rows_of = [&](int frame) -> const std::vector<size_t>& {
    static const std::vector<size_t> kNone;
    const auto it = rows_of_frame.find(frame);
    return it == rows_of_frame.end() ? kNone : it->second;
  };
  // Frames that closed a loop (summary.json `loops`, absent in older runs): 1, else 0.
  json loop = json::array();
  for (size_t k = 0; k < per_frame.size(); ++k) loop.push_back(0);
  if (run.summary.contains("loops")) {
    try {
      for (const json& l : run.summary.at("loops")) {
        for (size_t k : rows_of(l.at("query_frame").get<int>())) loop[k] = 1;
      }
    } catch (const json::exception& e) {
      ThrowInputError(file, std::string("loops: ") + e.what());
    }
  }
  cols["loop"] = std::move(loop);
  if (any_scale) cols["depth_scale"] = std::move(depth_scale);
  if (any_sigma) cols["scale_sigma"] = std::move(scale_sigma);
  // The map's scale against the dataset's depth at each measured keyframe (summary.json
  // `map_scale`, runs on datasets with depth images): null at the other frames.
  if (run.summary.contains("map_scale")) {
    json map_scale = json::array();
    for (size_t k = 0; k < per_frame.size(); ++k) map_scale.push_back(nullptr);
    try {
      for (const json& m : run.summary.at("map_scale").at("per_keyframe")) {
        const double scale = m.at("scale").get<double>();
        for (size_t k : rows_of(m.at("frame").get<int>())) map_scale[k] = scale;
      }
    } catch (const json::exception& e) {
      ThrowInputError(file, std::string("map_scale: ") + e.what());
    }
    cols["map_scale"] = std::move(map_scale);
  }
  return cols;
}

// Without per-frame times, the same analysis on summary.json's per-stage medians ("timing",
// where mapping is called local_mapping).
json CriticalPathFromMedians(const json& timing) {
  if (!timing.is_object() || timing.empty()) return nullptr;
  const auto [main_stages, worker_stages] = StageBranches(timing);
  auto median = [&](const std::string& stage) {
    const std::string key = stage == "mapping" ? "local_mapping" : stage;
    return timing.contains(key) ? timing[key].value("median_ms", 0.0) : 0.0;
  };
  json stages = json::array();
  double main = 0, worker = 0;
  for (const auto& s : main_stages) {
    main += median(s);
    stages.push_back({{"stage", s}, {"branch", "main"}, {"median_ms", median(s)}});
  }
  for (const auto& s : worker_stages) {
    worker += median(s);
    stages.push_back({{"stage", s}, {"branch", "worker"}, {"median_ms", median(s)}});
  }
  const bool main_critical = main >= worker;
  std::string dominant;
  double dominant_ms = -1;
  for (const json& s : stages) {
    if ((s["branch"] == "main") == main_critical && s["median_ms"].get<double>() > dominant_ms) {
      dominant_ms = s["median_ms"].get<double>();
      dominant = s["stage"].get<std::string>();
    }
  }
  return {{"stages", stages},         {"main_median_ms", main},
          {"worker_median_ms", worker}, {"frame_median_ms", std::max(main, worker)},
          {"from_medians", true},       {"critical_branch", main_critical ? "main" : "worker"},
          {"dominant_stage", dominant}, {"dominant_median_ms", dominant_ms}};
}

json CriticalPathJson(const json& frames, const json& summary) {
  const json& ms = frames.at("ms");
  json out;
  json stages = json::array();
  const size_t n = frames.at("frame").size();
  if (n == 0 || ms.empty()) return CriticalPathFromMedians(summary.value("timing", json()));
  const auto [main_stages, worker_stages] = StageBranches(summary.value("timing", json()));
  auto column = [&](const std::string& name) {
    std::vector<double> v(n, 0.0);
    if (ms.contains(name))
      for (size_t i = 0; i < n; ++i) v[i] = ms[name][i].get<double>();
    return v;
  };
  std::vector<double> main(n, 0.0), worker(n, 0.0);
  for (const auto& s : main_stages) {
    const std::vector<double> v = column(s);
    for (size_t i = 0; i < n; ++i) main[i] += v[i];
    stages.push_back({{"stage", s}, {"branch", "main"}, {"median_ms", Median(v)}});
  }
  for (const auto& s : worker_stages) {
    const std::vector<double> v = column(s);
    for (size_t i = 0; i < n; ++i) worker[i] += v[i];
    stages.push_back({{"stage", s}, {"branch", "worker"}, {"median_ms", Median(v)}});
  }
  size_t main_bound = 0;
  std::vector<double> frame_ms(n);
  for (size_t i = 0; i < n; ++i) {
    main_bound += main[i] >= worker[i] ? 1 : 0;
    frame_ms[i] = std::max(main[i], worker[i]);
  }
  const bool main_critical = 2 * main_bound >= n;
  // The dominating stage: the largest median on the branch that bounds most frames.
  std::string dominant;
  double dominant_ms = -1;
  for (const json& s : stages) {
    if ((s["branch"] == "main") != main_critical) continue;
    if (s["median_ms"].get<double>() > dominant_ms) {
      dominant_ms = s["median_ms"].get<double>();
      dominant = s["stage"].get<std::string>();
    }
  }
  out["stages"] = std::move(stages);
  out["main_median_ms"] = Median(main);
  out["worker_median_ms"] = Median(worker);
  out["frame_median_ms"] = Median(frame_ms);
  out["main_bound_frames"] = main_bound;
  out["frames"] = n;
  out["critical_branch"] = main_critical ? "main" : "worker";
  out["dominant_stage"] = dominant;
  out["dominant_median_ms"] = dominant_ms;
  return out;
}

// The moments worth a picture: worst error, relocalisations, most dynamic removals.
json ThumbnailsJson(const RunFolder& run, const json& frames, const json& traj,
                    const ReportOptions& options, std::string* note) {
  std::vector<std::pair<int, std::string>> wanted;
  auto add = [&](int frame, const std::string& reason) {
    for (auto& w : wanted) {
      if (w.first == frame) {
        w.second += "; " + reason;
        return;
      }
    }
    wanted.emplace_back(frame, reason);
  };
  const json& frame_ids = frames.at("frame");
  const json& t = frames.at("t");
  const size_t n = frame_ids.size();
  if (traj.contains("worst") && !traj["worst"].is_null()) {
    // The per-frame entry nearest in time to the worst-error pose.
    const double tw = traj["worst"]["t"].get<double>();
    size_t best = 0;
    for (size_t i = 1; i < n; ++i)
      if (std::abs(t[i].get<double>() - tw) < std::abs(t[best].get<double>() - tw)) best = i;
    if (n > 0) {
      std::ostringstream reason;
      reason << "worst error (" << std::fixed << std::setprecision(3)
             << traj["worst"]["error_m"].get<double>() << " m)";
      add(frame_ids[best].get<int>(), reason.str());
    }
  }
  for (size_t i = 0; i < n; ++i) {
    if (frames["relocalised"][i].get<int>() == 1) {
      add(frame_ids[i].get<int>(), "relocalised");
      break;  // the first one; later ones look alike
    }
  }
  // Dynamic removals: the filter's stage-1, stage-2, box-vote and small-box removals.
  const json& filter = frames.at("filter");
  int best_frame = -1;
  double best_removed = 0;
  for (size_t i = 0; i < n; ++i) {
    double removed = 0;
    for (const char* k :
         {"removed_small_box", "removed_stage1", "removed_stage2", "removed_box_vote"}) {
      if (filter.contains(k)) removed += filter[k][i].get<double>();
    }
    if (removed > best_removed) {
      best_removed = removed;
      best_frame = frame_ids[i].get<int>();
    }
  }
  if (best_frame >= 0) {
    add(best_frame, "most dynamic removals (" + std::to_string(static_cast<int>(best_removed)) +
                        " points)");
  }
  for (size_t i = 0; i < n; ++i) {
    if (frames["state"][i].get<int>() == 2) {
      add(frame_ids[i].get<int>(), "first lost frame");
      break;
    }
  }
  if (wanted.size() > static_cast<size_t>(options.max_thumbnails))
    wanted.resize(options.max_thumbnails);
  json thumbs = json::array();
  if (!run.has_viz) {
    *note =
        "no thumbnails: the run folder has no viz/ frames (run with --viz RUN_DIR/viz to get them)";
    return thumbs;
  }
  std::vector<std::string> missing;
  for (const auto& [frame, reason] : wanted) {
    const std::optional<std::string> jpeg = Thumbnail(run.dir / "viz", frame, options);
    if (!jpeg) {
      missing.push_back(std::to_string(frame));
      continue;
    }
    thumbs.push_back({{"frame", frame}, {"reason", reason}, {"jpeg_b64", *jpeg}});
  }
  if (!missing.empty()) {
    std::string list;
    for (const auto& m : missing) list += (list.empty() ? "" : ", ") + m;
    *note = "viz/ has no image for frame(s) " + list;
  }
  return thumbs;
}

json SummaryJson(const RunFolder& run) {
  json s;
  for (const char* k :
       {"dataset", "config", "depth", "detector", "seed", "deterministic", "filters", "frames",
        "tracked", "untracked", "lost", "keyframes", "map_points", "wall_seconds", "fps", "timing",
        "filter_counts", "accuracy", "metric_scale"}) {
    if (run.summary.contains(k)) s[k] = run.summary[k];
  }
  return s;
}

double FirstTimestamp(const RunFolder& run) {
  const json& per_frame = run.summary.at("per_frame");
  if (!per_frame.empty() && per_frame[0].contains("timestamp") &&
      per_frame[0]["timestamp"].is_number()) {
    return per_frame[0]["timestamp"].get<double>();
  }
  return run.trajectory.empty() ? 0.0 : run.trajectory.front().timestamp;
}

// JSON inside <script>: "</script" or "<!--" would end or change the element early; '<' only
// occurs inside JSON strings, where "\u003c" means the same.
std::string ScriptSafe(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    if (c == '<') {
      out += "\\u003c";
    } else {
      out += c;
    }
  }
  return out;
}

std::string HtmlEscape(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '&': out += "&amp;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

}  // namespace

void ReportOptions::Check() const {
  if (max_map_points < 1) throw std::invalid_argument("report.max_map_points must be >= 1");
  if (max_thumbnails < 0) throw std::invalid_argument("report.max_thumbnails must be >= 0");
  if (thumbnail_width < 16 || thumbnail_width > 4096)
    throw std::invalid_argument("report.thumbnail_width must be in [16, 4096]");
  if (thumbnail_jpeg_quality < 1 || thumbnail_jpeg_quality > 100)
    throw std::invalid_argument("report.thumbnail_jpeg_quality must be in [1, 100]");
}

ReportOptions ReportOptions::FromYaml(const YAML::Node& node) {
  ReportOptions o;
  CheckYamlKeys(node, "report",
                {"alignment", "max_map_points", "max_thumbnails", "thumbnail_width",
                 "thumbnail_jpeg_quality"});
  if (node.IsMap() && node["alignment"]) o.sim3_without_metric_scale = false;  // asked for
  o.alignment = ReadYamlChoice<Alignment>(node, "report", "alignment",
                                          {{"none", Alignment::kNone},
                                           {"se3", Alignment::kSe3},
                                           {"sim3", Alignment::kSim3},
                                           {"origin", Alignment::kOrigin}},
                                          o.alignment);
  o.max_map_points = ReadYamlKey(node, "report", "max_map_points", o.max_map_points);
  o.max_thumbnails = ReadYamlKey(node, "report", "max_thumbnails", o.max_thumbnails);
  o.thumbnail_width = ReadYamlKey(node, "report", "thumbnail_width", o.thumbnail_width);
  o.thumbnail_jpeg_quality =
      ReadYamlKey(node, "report", "thumbnail_jpeg_quality", o.thumbnail_jpeg_quality);
  o.Check();
  return o;
}

MapCloud ReadPlyPoints(const fs::path& path) {
  RequireFile(path);
  std::ifstream in(path, std::ios::binary);
  if (!in) ThrowInputError(path, "cannot open");
  std::string line;
  if (!std::getline(in, line) || line.rfind("ply", 0) != 0) ThrowInputError(path, "not a PLY file");
  enum class Format { kAscii, kBinaryLe } format = Format::kAscii;
  size_t vertices = 0;
  bool in_vertex = false;
  std::vector<std::pair<std::string, std::string>> props;  // (type, name) of the vertex element
  bool header_done = false;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream ls(line);
    std::string word;
    ls >> word;
    if (word == "format") {
      std::string f;
      ls >> f;
      if (f == "ascii") format = Format::kAscii;
      else if (f == "binary_little_endian") format = Format::kBinaryLe;
      else ThrowInputError(path, "unsupported PLY format '" + f + "'");
    } else if (word == "element") {
      std::string name;
      ls >> name;
      in_vertex = name == "vertex";
      if (in_vertex && !(ls >> vertices)) ThrowInputError(path, "bad vertex count");
    } else if (word == "property" && in_vertex) {
      std::string type, name;
      ls >> type >> name;
      if (type == "list") ThrowInputError(path, "list properties on vertices are not supported");
      props.emplace_back(type, name);
    } else if (word == "end_header") {
      header_done = true;
      break;
    }
  }
  if (!header_done) ThrowInputError(path, "PLY header has no end_header");
  int ix = -1, iy = -1, iz = -1, ir = -1, ig = -1, ib = -1;
  for (size_t i = 0; i < props.size(); ++i) {
    const std::string& n = props[i].second;
    if (n == "x") ix = i;
    if (n == "y") iy = i;
    if (n == "z") iz = i;
    if (n == "red") ir = i;
    if (n == "green") ig = i;
    if (n == "blue") ib = i;
  }
  if (ix < 0 || iy < 0 || iz < 0) ThrowInputError(path, "PLY vertices have no x, y, z");
  const bool has_rgb = ir >= 0 && ig >= 0 && ib >= 0;
  auto type_size = [&](const std::string& t) -> size_t {
    if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
    if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
    if (t == "int" || t == "uint" || t == "float" || t == "int32" || t == "uint32" ||
        t == "float32")
      return 4;
    if (t == "double" || t == "float64") return 8;
    ThrowInputError(path, "unknown PLY property type '" + t + "'");
  };
  MapCloud cloud;
  cloud.xyz.reserve(vertices);
  cloud.rgb.reserve(vertices);
  std::vector<double> values(props.size());
  for (size_t v = 0; v < vertices; ++v) {
    if (format == Format::kAscii) {
      for (size_t i = 0; i < props.size(); ++i) {
        if (!(in >> values[i])) {
          ThrowInputError(path, "vertex " + std::to_string(v) + " is truncated or not a number");
        }
      }
    } else {
      for (size_t i = 0; i < props.size(); ++i) {
        const std::string& t = props[i].first;
        char buf[8];
        const size_t size = type_size(t);
        if (!in.read(buf, size))
          ThrowInputError(path, "vertex " + std::to_string(v) + " is truncated");
        if (t == "float" || t == "float32") { float f; std::memcpy(&f, buf, 4); values[i] = f;
        } else if (t == "double" || t == "float64") {
          double d;
          std::memcpy(&d, buf, 8);
          values[i] = d;
        } else if (t == "uchar" || t == "uint8")
          values[i] = static_cast<uint8_t>(buf[0]);
        else if (t == "char" || t == "int8") values[i] = static_cast<int8_t>(buf[0]);
        else if (size == 2) {
          uint16_t s;
          std::memcpy(&s, buf, 2);
          values[i] = (t == "short" || t == "int16") ? static_cast<int16_t>(s) : s;
        } else {
          uint32_t s;
          std::memcpy(&s, buf, 4);
          values[i] = (t == "int" || t == "int32") ? static_cast<int32_t>(s) : s;
        }
      }
    }
    const Eigen::Vector3d p(values[ix], values[iy], values[iz]);
    if (!p.allFinite()) ThrowInputError(path, "vertex " + std::to_string(v) + " is not finite");
    cloud.xyz.push_back(p.cast<float>());
    if (has_rgb) {
      cloud.rgb.push_back({static_cast<uint8_t>(std::clamp(values[ir], 0.0, 255.0)),
                           static_cast<uint8_t>(std::clamp(values[ig], 0.0, 255.0)),
                           static_cast<uint8_t>(std::clamp(values[ib], 0.0, 255.0))});
    } else {
      cloud.rgb.push_back({200, 200, 200});
    }
  }
  return cloud;
}

RunFolder ReadRunFolder(const fs::path& dir) {
  RequireDirectory(dir);
  RunFolder run;
  run.dir = dir;
  const fs::path summary_path = dir / "summary.json";
  RequireFile(summary_path);
  try {
    run.summary = json::parse(ReadTextFile(summary_path));
  } catch (const json::exception& e) {  // syntax, or a number beyond a double
    ThrowInputError(summary_path, std::string("not valid JSON: ") + e.what());
  }
  const json schema = RequireKey(run.summary, "schema", summary_path);
  if (!schema.is_string() || schema.get<std::string>() != kSchema) {
    ThrowInputError(summary_path, "schema is " + schema.dump() + ", expected \"" + kSchema + "\"");
  }
  const json per_frame = RequireKey(run.summary, "per_frame", summary_path);
  if (!per_frame.is_array()) ThrowInputError(summary_path, "per_frame is not a list");
  run.trajectory = ReadTumTrajectory(dir / "trajectory.tum");
  if (fs::exists(dir / "keyframes.tum")) run.keyframes = ReadTumTrajectory(dir / "keyframes.tum");
  if (fs::exists(dir / "groundtruth.tum"))
    run.ground_truth = ReadTumTrajectory(dir / "groundtruth.tum");
  if (fs::exists(dir / "map.ply")) {
    run.map = ReadPlyPoints(dir / "map.ply");
    run.has_map = true;
  }
  run.has_viz = fs::is_directory(dir / "viz");
  return run;
}

bool RunHasMetricScale(const RunFolder& run) {
  if (run.summary.value("depth", std::string()) != "none") return true;
  const auto ground = run.summary.find("ground_scale");
  return ground != run.summary.end() && ground->is_object() &&
         ground->value("camera_height", 0.0) > 0.0;
}

Alignment RunAlignment(const RunFolder& run, const ReportOptions& options) {
  if (options.sim3_without_metric_scale && options.alignment == Alignment::kSe3 &&
      !RunHasMetricScale(run))
    return Alignment::kSim3;
  return options.alignment;
}

json RunReportData(const RunFolder& run, const ReportOptions& options) {
  options.Check();
  const double t0 = FirstTimestamp(run);
  const Alignment alignment = RunAlignment(run, options);
  const AlignedRun aligned = Align(run, alignment);
  json data;
  data["kind"] = "run";
  data["title"] = run.dir.filename().empty() ? run.dir.parent_path().filename().string()
                                             : run.dir.filename().string();
  data["summary"] = SummaryJson(run);
  data["alignment"] = aligned.eval ? ToString(alignment) : "none";
  if (alignment != options.alignment)
    data["alignment_reason"] = "no metric scale without depth: se3 would score the map's unit";
  if (!aligned.note.empty()) data["alignment_note"] = aligned.note;
  data["t0"] = t0;
  data["frames"] = FramesJson(run, t0);
  data["traj"] = TrajectoryJson(run, aligned, t0);
  data["critical_path"] = CriticalPathJson(data["frames"], run.summary);
  data["map"] = MapJson(run, aligned, options);
  std::string thumbs_note;
  data["thumbs"] = ThumbnailsJson(run, data["frames"], data["traj"], options, &thumbs_note);
  if (!thumbs_note.empty()) data["thumbs_note"] = thumbs_note;
  return data;
}

json ComparisonReportData(const std::vector<RunFolder>& runs, const std::vector<std::string>& names,
                          const ReportOptions& options) {
  options.Check();
  if (runs.empty()) throw std::invalid_argument("a comparison needs at least one run");
  if (!names.empty() && names.size() != runs.size())
    throw std::invalid_argument("one name per run expected");
  json data;
  data["kind"] = "comparison";
  data["alignment"] = ToString(options.alignment);
  json variants = json::array();
  for (size_t i = 0; i < runs.size(); ++i) {
    const RunFolder& run = runs[i];
    const double t0 = FirstTimestamp(run);
    const AlignedRun aligned = Align(run, options.alignment);
    json v;
    v["name"] = names.empty() ? run.dir.filename().string() : names[i];
    v["summary"] = SummaryJson(run);
    v["aligned"] = aligned.eval.has_value();
    if (!aligned.note.empty()) v["alignment_note"] = aligned.note;
    v["traj"] = TrajectoryJson(run, aligned, t0);
    const json frames = FramesJson(run, t0);
    v["frames"] = {{"t", frames["t"]}, {"filter", frames["filter"]}, {"state", frames["state"]}};
    if (aligned.eval) {
      v["ate_rmse_m"] = aligned.eval->ape.rmse;
      v["scale"] = aligned.eval->gt_from_est.scale;
    }
    variants.push_back(std::move(v));
  }
  data["variants"] = std::move(variants);
  data["title"] = "comparison of " + std::to_string(runs.size()) + " runs";
  return data;
}

std::string RenderReportHtml(const json& data) {
  std::string html;
  const std::string title = "ademono report: " + data.value("title", std::string("run"));
  html += "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n";
  // The inlined libraries' MIT licences travel with every copy.
  html += "<!--\nuPlot 1.6.32, https://github.com/leeoniya/uPlot\n";
  html += web::kUplotLicense;
  html += "\nregl 2.1.1, https://github.com/regl-project/regl\n";
  html += web::kReglLicense;
  html += "\n-->\n<title>";
  html += HtmlEscape(title);
  html += "</title>\n<style>\n";
  html += web::kUplotCss;
  html += "\n";
  html += web::kReportCss;
  html += "\n</style>\n</head>\n<body>\n<div id=\"app\"></div>\n";
  html += "<script id=\"report-data\" type=\"application/json\">";
  html += ScriptSafe(data.dump());
  html += "</script>\n<script>\n";
  html += web::kUplotJs;
  html += "\n</script>\n<script>\n";
  html += web::kReglJs;
  html += "\n</script>\n<script>\n";
  html += web::kReportJs;
  html += "\n</script>\n</body>\n</html>\n";
  return html;
}

fs::path WriteRunReport(const fs::path& run_dir, const ReportOptions& options,
                        const fs::path& out) {
  const RunFolder run = ReadRunFolder(run_dir);
  const fs::path target = out.empty() ? run_dir / "report.html" : out;
  WriteTextFileAtomic(target, RenderReportHtml(RunReportData(run, options)));
  return target;
}

fs::path WriteComparisonReport(const std::vector<fs::path>& run_dirs,
                               const std::vector<std::string>& names, const ReportOptions& options,
                               const fs::path& out) {
  std::vector<RunFolder> runs;
  for (const fs::path& dir : run_dirs) runs.push_back(ReadRunFolder(dir));
  fs::path target = out;
  if (target.empty()) {
    const fs::path first = fs::absolute(run_dirs.at(0)).lexically_normal();
    target = (first.filename().empty() ? first.parent_path().parent_path() : first.parent_path()) /
             "report.html";
  }
  WriteTextFileAtomic(target, RenderReportHtml(ComparisonReportData(runs, names, options)));
  return target;
}

}  // namespace ademono
