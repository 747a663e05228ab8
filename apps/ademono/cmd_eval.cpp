// `ademono eval`: scores an estimated trajectory against ground truth the way evo (APE/RPE) and
// kitti-odom-eval (t_rel/r_rel) do. See docs/evaluation.md.
#include <iostream>
#include <optional>
#include <string>

#include "ademono/core/error.h"
#include "ademono/core/file_util.h"
#include "ademono/eval/svg_plot.h"
#include "ademono/eval/trajectory_eval.h"
#include "command.h"

namespace {

struct EvalArgs {
  std::string gt, est, format = "tum", gt_format, est_format, align = "se3", rpe_unit = "frames",
                       kitti_align;
  double max_diff = 0.01, rpe_delta = 1;
  bool rpe_pairs_from_reference = false, kitti_metrics = false;
  std::string json, plot;
};

int RunEval(const EvalArgs& a) {
  using namespace ademono;
  const TrajectoryFormat gt_format =
      ParseTrajectoryFormat(a.gt_format.empty() ? a.format : a.gt_format);
  const TrajectoryFormat est_format =
      ParseTrajectoryFormat(a.est_format.empty() ? a.format : a.est_format);
  EvalOptions options;
  options.alignment = ParseAlignment(a.align);
  // KITTI files carry no timestamps: match pose i to pose i as soon as one side is KITTI.
  options.associate_by_timestamp =
      gt_format != TrajectoryFormat::kKitti && est_format != TrajectoryFormat::kKitti;
  options.max_diff = a.max_diff;
  options.rpe_delta = a.rpe_delta;
  options.rpe_unit = ParseDeltaUnit(a.rpe_unit);
  options.rpe_pairs_from_reference = a.rpe_pairs_from_reference;
  options.kitti_metrics = a.kitti_metrics || !a.kitti_align.empty();
  options.kitti_alignment = a.kitti_align.empty() ? KittiAlignmentFor(options.alignment)
                                                  : ParseKittiAlignment(a.kitti_align);
  options.Check();

  const PoseSeries gt = ReadPoseSeries(a.gt, gt_format);
  const PoseSeries est = ReadPoseSeries(a.est, est_format);
  EvalResult result;
  try {
    result = EvaluateTrajectories(gt, est, options);
  } catch (const std::invalid_argument& e) {
    // The library does not know the files; name both here.
    throw InputError(std::string(e.what()) + " between " + a.gt + " (" + std::to_string(gt.size()) +
                     " poses) and " + a.est + " (" + std::to_string(est.size()) + " poses)");
  }

  // Render everything before writing anything, so a failure leaves no partial output.
  const std::string json = a.json.empty() ? "" : ToJson(result).dump(2) + "\n";
  const std::string svg = a.plot.empty() ? "" : RenderEvalSvg(result, a.est);
  std::cout << FormatReport(result);
  if (!a.json.empty()) WriteTextFileAtomic(a.json, json);
  if (!a.plot.empty()) WriteTextFileAtomic(a.plot, svg);
  return 0;
}

const bool kRegistered = ademono::cli::RegisterCommand(
    "eval", "Score an estimated trajectory against ground truth (evo APE/RPE, KITTI t_rel/r_rel)",
    [](CLI::App& app) -> ademono::cli::Runner {
      auto args = std::make_shared<EvalArgs>();
      app.add_option("--gt", args->gt, "Ground-truth trajectory file")->required();
      app.add_option("--est", args->est, "Estimated trajectory file")->required();
      app.add_option("--format", args->format, "File format of both files")
          ->check(CLI::IsMember({"tum", "kitti", "euroc"}))
          ->capture_default_str();
      app.add_option("--gt-format", args->gt_format, "Format of --gt (default: --format)")
          ->check(CLI::IsMember({"tum", "kitti", "euroc"}));
      app.add_option("--est-format", args->est_format, "Format of --est (default: --format)")
          ->check(CLI::IsMember({"tum", "kitti", "euroc"}));
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
      app.add_option("--json", args->json, "Write the metrics as JSON to this file");
      app.add_option("--plot", args->plot, "Write an SVG plot (top view and APE over time)");
      return [args] { return RunEval(*args); };
    });

}  // namespace
