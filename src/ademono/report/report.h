#pragma once
// The run report: one self-contained HTML file (report.html) that shows a run folder
// (`ademono run --out DIR`, schema "ademono.run/1", docs/report.md) in a browser, offline.
// The C++ side reads the folder, aligns the estimate to the ground truth with the eval module,
// chooses and downscales the thumbnail frames, subsamples the map, and embeds it all as JSON next
// to the inlined plotting (uPlot) and WebGL (regl) libraries; web/report.js draws it.

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "ademono/eval/trajectory_eval.h"
#include "ademono/io/trajectory.h"

namespace ademono {

struct ReportOptions {
  // How the estimate is aligned to the ground truth before it is drawn and its error measured.
  Alignment alignment = Alignment::kSe3;
  // A run without metric scale (summary.json: depth "none" and no ground_scale camera height) is
  // aligned with sim3 when `alignment` is se3: se3 would score the unit of its two-view start,
  // not its shape. Off when an alignment is asked for (`ademono report --align`, the YAML key).
  bool sim3_without_metric_scale = true;
  // Map points embedded for the 3D view; beyond this an evenly strided subset (the report says so).
  int max_map_points = 100000;
  // Thumbnail frames (from the run folder's viz/ images) and their width in pixels.
  int max_thumbnails = 4;
  int thumbnail_width = 360;
  int thumbnail_jpeg_quality = 80;
  // Throws std::invalid_argument naming the first bad option.
  void Check() const;
  // The `report` sub-node: alignment, max_map_points, max_thumbnails, thumbnail_width,
  // thumbnail_jpeg_quality. Unknown keys are rejected (std::invalid_argument).
  static ReportOptions FromYaml(const YAML::Node& node);
};

struct MapCloud {
  std::vector<Eigen::Vector3f> xyz;
  std::vector<std::array<uint8_t, 3>> rgb;
};

// A run folder as read from disk. summary.json, trajectory.tum are required; keyframes.tum,
// groundtruth.tum, map.ply and viz/ are optional.
struct RunFolder {
  std::filesystem::path dir;
  nlohmann::json summary;
  Trajectory trajectory;
  Trajectory keyframes;
  std::optional<Trajectory> ground_truth;
  MapCloud map;
  bool has_map = false;
  bool has_viz = false;
};

// Throws InputError naming the file and the problem (missing, malformed, wrong schema).
RunFolder ReadRunFolder(const std::filesystem::path& dir);
// False for a run with neither depth nor a camera height (--depth none indoors).
bool RunHasMetricScale(const RunFolder& run);
// The alignment a single run's report uses (ReportOptions::sim3_without_metric_scale).
Alignment RunAlignment(const RunFolder& run, const ReportOptions& options);
// ASCII or binary little-endian PLY with float x, y, z and optional uchar red, green, blue.
MapCloud ReadPlyPoints(const std::filesystem::path& path);

// The data the page draws (aligned trajectories, error, per-frame series, critical path, map,
// thumbnails). Exposed for tests; keys in docs/report.md.
nlohmann::json RunReportData(const RunFolder& run, const ReportOptions& options);
// Several runs (e.g. ablate's variants) side by side: ATE per variant, trajectories overlaid
// (each aligned to its own ground truth), filter counts. `names` labels the runs (folder names
// when empty).
nlohmann::json ComparisonReportData(const std::vector<RunFolder>& runs,
                                    const std::vector<std::string>& names,
                                    const ReportOptions& options);

// The self-contained page around the data.
std::string RenderReportHtml(const nlohmann::json& data);

// Read, render and write atomically. `out` defaults to <run_dir>/report.html, and for a
// comparison to <parent of the first run>/report.html.
std::filesystem::path WriteRunReport(const std::filesystem::path& run_dir,
                                     const ReportOptions& options,
                                     const std::filesystem::path& out = {});
std::filesystem::path WriteComparisonReport(const std::vector<std::filesystem::path>& run_dirs,
                                            const std::vector<std::string>& names,
                                            const ReportOptions& options,
                                            const std::filesystem::path& out = {});

}  // namespace ademono
