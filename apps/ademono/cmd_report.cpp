// `ademono report RUN_DIR... [--out FILE] [--align se3] [--name NAME...]`: writes the run report
// (one self-contained report.html, docs/report.md) for a run folder, or, for several folders
// (e.g. ablate's variants), one report comparing them.
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "ademono/core/error.h"
#include "ademono/eval/trajectory_eval.h"
#include "ademono/report/report.h"
#include "command.h"

namespace {

struct ReportArgs {
  std::vector<std::string> runs;
  std::vector<std::string> names;
  std::string out;
  std::string align = "auto";
  int max_map_points = ademono::ReportOptions().max_map_points;
};

int RunReport(const ReportArgs& a) {
  using namespace ademono;
  ReportOptions options;
  if (a.align != "auto") {
    options.alignment = ParseAlignment(a.align);
    options.sim3_without_metric_scale = false;
  }
  options.max_map_points = a.max_map_points;
  try {
    options.Check();
  } catch (const std::invalid_argument& e) {
    throw InputError(e.what());
  }
  if (!a.names.empty() && a.names.size() != a.runs.size()) {
    throw InputError("--name given " + std::to_string(a.names.size()) + " times for " +
                     std::to_string(a.runs.size()) + " run folders");
  }
  std::filesystem::path written;
  if (a.runs.size() == 1) {
    written = WriteRunReport(a.runs[0], options, a.out);
  } else {
    const std::vector<std::filesystem::path> dirs(a.runs.begin(), a.runs.end());
    written = WriteComparisonReport(dirs, a.names, options, a.out);
  }
  std::cout << "wrote " << written.string() << "\n";
  return 0;
}

const bool kRegistered = ademono::cli::RegisterCommand(
    "report", "Write the browser report (report.html) of a run folder, or compare several",
    [](CLI::App& app) -> ademono::cli::Runner {
      auto args = std::make_shared<ReportArgs>();
      app.add_option("runs", args->runs, "Run folder(s) written by `ademono run`")->required();
      app.add_option("--out", args->out,
                     "Output HTML (default: RUN_DIR/report.html; for several runs, report.html "
                     "next to the first)");
      app.add_option("--name", args->names, "Label per run folder (repeat; default: folder names)");
      app.add_option("--align", args->align,
                     "Alignment of each estimate to its ground truth (auto: se3, or sim3 for a "
                     "run without metric scale: --depth none without a camera height)")
          ->check(CLI::IsMember({"auto", "none", "se3", "sim3", "origin"}))
          ->capture_default_str();
      app.add_option("--max-map-points", args->max_map_points,
                     "Map points embedded in the 3D view (evenly subsampled beyond)")
          ->capture_default_str();
      return [args] { return RunReport(*args); };
    });

}  // namespace
