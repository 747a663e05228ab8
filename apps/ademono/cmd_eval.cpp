// `ademono eval`: scores estimated trajectories against one ground truth the way evo (APE/RPE,
// evo_res for several estimates) and kitti-odom-eval (t_rel/r_rel) do. See docs/evaluation.md.
#include <algorithm>
#include <cstdio>
#include <iostream>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "ademono/core/error.h"
#include "ademono/core/file_util.h"
#include "ademono/eval/shared_error.h"
#include "ademono/eval/svg_plot.h"
#include "ademono/eval/trajectory_eval.h"
#include "command.h"

namespace {

const std::vector<std::string> kFormatNames = {"auto",  "tum",           "orbslam",
                                               "kitti", "kitti-indexed", "euroc"};

struct EvalArgs {
  std::string gt, format = "auto", gt_format, est_format, align = "se3", rpe_unit = "frames",
                  kitti_align;
  std::vector<std::string> est;
  double max_diff = 0.01, rpe_delta = 1;
  bool rpe_pairs_from_reference = false, kitti_metrics = false, shared = false;
  std::string json, plot;
};

using LoadedFile = ademono::TrajectoryFile;

LoadedFile Load(const std::string& path, const std::string& format_name) {
  return ademono::LoadTrajectoryFile(path, format_name);
}

std::string Describe(const LoadedFile& file) {
  return file.path + " (" + ademono::ToString(file.poses.format) +
         (file.detected ? ", detected" : ", as given") + ", " + std::to_string(file.poses.size()) +
         " poses)";
}

ademono::EvalResult Evaluate(const LoadedFile& gt, const LoadedFile& est,
                             const ademono::EvalOptions& options) {
  return ademono::EvaluateTrajectoryFiles(gt, est, options);
}

// One row per estimate, evo_res style.
std::string FormatTable(const std::vector<LoadedFile>& ests,
                        const std::vector<ademono::EvalResult>& results) {
  using namespace ademono;
  size_t name_width = 8;
  for (const auto& e : ests) name_width = std::max(name_width, e.path.size());
  const bool kitti = results.front().kitti.has_value();
  std::string out;
  char buf[512];
  std::snprintf(buf, sizeof(buf), "%-*s %7s %10s %10s %10s %10s %10s %12s %12s",
                static_cast<int>(name_width), "estimate", "matched", "APE rmse", "APE mean",
                "APE median", "APE max", "APE std", "RPE t rmse", "RPE r rmse");
  out += buf;
  if (kitti) {
    std::snprintf(buf, sizeof(buf), " %9s %11s", "t_rel %", "r_rel d/100m");
    out += buf;
  }
  out += "\n";
  for (size_t k = 0; k < results.size(); ++k) {
    const EvalResult& r = results[k];
    std::snprintf(buf, sizeof(buf), "%-*s %7zu %10.6f %10.6f %10.6f %10.6f %10.6f %12.6f %12.6f",
                  static_cast<int>(name_width), ests[k].path.c_str(), r.matched_poses, r.ape.rmse,
                  r.ape.mean, r.ape.median, r.ape.max, r.ape.std, r.rpe_trans.rmse,
                  r.rpe_rot_deg.rmse);
    out += buf;
    if (kitti) {
      std::snprintf(buf, sizeof(buf), " %9.3f %11.3f", r.kitti->t_rel_percent,
                    r.kitti->r_rel_deg_per_100m);
      out += buf;
    }
    out += "\n";
  }
  std::snprintf(buf, sizeof(buf),
                "(APE in m after %s alignment; RPE over %g %s, t in m, r in deg)\n",
                ToString(results.front().alignment).c_str(), results.front().rpe_delta,
                results.front().rpe_unit == DeltaUnit::kFrames ? "frames" : "m");
  out += buf;
  return out;
}

int RunEval(const EvalArgs& a) {
  using namespace ademono;
  EvalOptions options;
  options.alignment = ParseAlignment(a.align);
  options.max_diff = a.max_diff;
  options.rpe_delta = a.rpe_delta;
  options.rpe_unit = ParseDeltaUnit(a.rpe_unit);
  options.rpe_pairs_from_reference = a.rpe_pairs_from_reference;
  options.kitti_metrics = a.kitti_metrics || !a.kitti_align.empty();
  options.kitti_alignment = a.kitti_align.empty() ? KittiAlignmentFor(options.alignment)
                                                  : ParseKittiAlignment(a.kitti_align);
  options.Check();
  if (a.shared && a.est.size() != 2)
    throw InputError("--shared compares exactly two --est, got " + std::to_string(a.est.size()));

  const LoadedFile gt = Load(a.gt, a.gt_format.empty() ? a.format : a.gt_format);
  std::vector<LoadedFile> ests;
  std::vector<EvalResult> results;
  for (const std::string& path : a.est) {
    ests.push_back(Load(path, a.est_format.empty() ? a.format : a.est_format));
    results.push_back(Evaluate(gt, ests.back(), options));
  }

  std::optional<SharedError> shared;
  if (a.shared) {
    try {
      shared = ComputeSharedError(results[0], results[1]);
    } catch (const std::invalid_argument& e) {
      throw InputError(a.est[0] + " and " + a.est[1] + ": " + e.what());
    }
  }

  // Render everything before writing anything, so a failure leaves no partial output.
  std::string json, svg;
  if (!a.json.empty()) {
    auto describe = [](const LoadedFile& f) {
      return nlohmann::json{
          {"file", f.path}, {"format", ToString(f.poses.format)}, {"format_detected", f.detected}};
    };
    nlohmann::json j;
    if (results.size() == 1) {
      j = ToJson(results.front());
      j["gt_file"] = describe(gt);
      j["est_file"] = describe(ests.front());
    } else {
      j["gt_file"] = describe(gt);
      j["estimates"] = nlohmann::json::array();
      for (size_t k = 0; k < results.size(); ++k) {
        nlohmann::json e = ToJson(results[k]);
        e["est_file"] = describe(ests[k]);
        j["estimates"].push_back(e);
      }
      if (shared) j["shared"] = shared->ToJson();
    }
    json = j.dump(2) + "\n";
  }
  if (!a.plot.empty()) {
    std::vector<NamedEvalResult> named;
    for (size_t k = 0; k < results.size(); ++k) named.push_back({ests[k].path, &results[k]});
    svg = results.size() == 1 ? RenderEvalSvg(results.front(), a.est.front())
                              : RenderEvalSvg(named, "ground truth " + a.gt);
  }
  std::cout << "ground truth: " << Describe(gt) << "\n";
  for (const auto& e : ests) std::cout << "estimate: " << Describe(e) << "\n";
  if (results.size() == 1) {
    std::cout << FormatReport(results.front());
  } else {
    std::cout << FormatTable(ests, results);
  }
  if (shared) {
    char line[256];
    std::snprintf(line, sizeof(line),
                  "shared by both: %.6f m rms; half their difference: %.6f m; correlation %.2f "
                  "(%zu ground-truth poses both matched)\n",
                  shared->shared_rmse, shared->half_difference_rmse, shared->correlation,
                  shared->frames);
    std::cout << line;
  }
  if (!a.json.empty()) WriteTextFileAtomic(a.json, json);
  if (!a.plot.empty()) WriteTextFileAtomic(a.plot, svg);
  return 0;
}

const bool kRegistered = ademono::cli::RegisterCommand(
    "eval",
    "Score estimated trajectories against ground truth (evo APE/RPE, KITTI t_rel/r_rel); "
    "several --est give one table",
    [](CLI::App& app) -> ademono::cli::Runner {
      auto args = std::make_shared<EvalArgs>();
      app.add_option("--gt", args->gt, "Ground-truth trajectory file")->required();
      app.add_option("--est", args->est,
                     "Estimated trajectory file; repeat to compare several in one table")
          ->required()
          ->take_all();
      app.add_option("--format", args->format,
                     "File format of all files (auto: detected from the first data line)")
          ->check(CLI::IsMember(kFormatNames))
          ->capture_default_str();
      app.add_option("--gt-format", args->gt_format, "Format of --gt (default: --format)")
          ->check(CLI::IsMember(kFormatNames));
      app.add_option("--est-format", args->est_format, "Format of every --est (default: --format)")
          ->check(CLI::IsMember(kFormatNames));
      app.add_option("--align", args->align, "Alignment of the estimate before APE")
          ->check(CLI::IsMember({"none", "se3", "sim3", "origin"}))
          ->capture_default_str();
      app.add_option("--max-diff", args->max_diff, "Max timestamp difference for matching (s)")
          ->check(CLI::NonNegativeNumber)
          ->capture_default_str();
      app.add_option("--rpe-delta", args->rpe_delta, "RPE step between pose pairs")
          ->check(CLI::PositiveNumber)
          ->capture_default_str();
      app.add_option("--rpe-unit", args->rpe_unit, "Unit of --rpe-delta")
          ->check(CLI::IsMember({"frames", "m"}))
          ->capture_default_str();
      app.add_flag("--rpe-pairs-from-reference", args->rpe_pairs_from_reference,
                   "Choose RPE pairs on the ground truth's path (evo --pairs_from_reference)");
      app.add_flag("--kitti-metrics", args->kitti_metrics,
                   "Also compute kitti-odom-eval t_rel (%) and r_rel (deg/100m)");
      app.add_option("--kitti-align", args->kitti_align,
                     "kitti-odom-eval alignment (default: matches --align)")
          ->check(CLI::IsMember({"none", "scale", "6dof", "7dof"}));
      app.add_flag("--shared", args->shared,
                   "With two --est: the part of their errors they share (each aligned on its "
                   "own), e.g. what the ground truth itself gets wrong");
      app.add_option("--json", args->json, "Write the metrics as JSON to this file");
      app.add_option("--plot", args->plot, "Write an SVG plot (top view and APE over time)");
      return [args] { return RunEval(*args); };
    });

}  // namespace
