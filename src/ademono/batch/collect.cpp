#include "ademono/batch/collect.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <nlohmann/json.hpp>

#include "ademono/core/error.h"
#include "ademono/core/file_util.h"
#include "ademono/eval/trajectory_eval.h"
#include "ademono/report/report.h"

namespace fs = std::filesystem;

namespace ademono::batch {
namespace {

std::string Fixed(const std::optional<double>& v, int decimals) {
  if (!v) return "";
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.*f", decimals, *v);
  return buf;
}

// The run's figures: counts from summary.json, accuracy through eval's file evaluation.
void ScoreRun(const Task& t, RunRow* row) {
  const nlohmann::json summary = nlohmann::json::parse(ReadTextFile(t.out / "summary.json"));
  row->frames = summary.value("frames", size_t{0});
  row->tracked = summary.value("tracked", size_t{0});
  row->keyframes = summary.value("keyframes", size_t{0});
  row->fps = summary.value("fps", 0.0);
  const fs::path gt = t.out / "groundtruth.tum", est = t.out / "trajectory.tum";
  if (!fs::exists(gt)) return;
  const TrajectoryFile gt_file = LoadTrajectoryFile(gt.string(), "tum");
  const TrajectoryFile est_file = LoadTrajectoryFile(est.string(), "tum");
  if (est_file.poses.size() < 3) return;
  EvalOptions options;
  options.alignment = Alignment::kSe3;
  options.rpe_delta = 30;
  const EvalResult se3 = EvaluateTrajectoryFiles(gt_file, est_file, options);
  options.alignment = Alignment::kSim3;
  const EvalResult sim3 = EvaluateTrajectoryFiles(gt_file, est_file, options);
  row->ate_se3 = se3.ape.rmse;
  if (se3.rpe_trans.count > 0) row->rpe = se3.rpe_trans.rmse;  // none in a run under 31 poses
  row->ate_sim3 = sim3.ape.rmse;
  row->sim3_scale = sim3.gt_from_est.scale;
}

struct Spread {
  std::optional<double> mean, std, max;
};
Spread SpreadOf(const std::vector<double>& values) {
  if (values.empty()) return {};
  const ErrorStats s = ComputeStats(values);
  return {s.mean, s.std, s.max};
}

}  // namespace

size_t Collection::Count(const std::string& status) const {
  return static_cast<size_t>(std::count_if(runs.begin(), runs.end(),
                                           [&](const RunRow& r) { return r.status == status; }));
}

Collection CollectBatch(const Batch& batch, const std::set<std::string>& in_flight) {
  Collection c;
  for (const Task& t : batch.runs) {
    RunRow row;
    row.id = t.id;
    row.dataset = t.dataset;
    row.variant = t.variant;
    row.seed = t.seed;
    row.log = t.log.string();
    if (in_flight.count(t.id) != 0) {
      row.status = "running";
    } else if (IsComplete(t)) {
      row.status = "done";
      try {
        ScoreRun(t, &row);
      } catch (const std::exception& e) {
        ThrowInputError(t.out, std::string("cannot be scored: ") + e.what());
      }
    } else {
      // It ran if it left a log; otherwise it never started.
      row.status = fs::exists(t.log) ? "failed" : "missing";
    }
    c.runs.push_back(std::move(row));
  }
  // One group per dataset x variant, in plan order.
  std::vector<std::pair<std::string, std::string>> order;
  std::map<std::pair<std::string, std::string>, std::vector<const RunRow*>> groups;
  for (const RunRow& r : c.runs) {
    const auto key = std::make_pair(r.dataset, r.variant);
    if (groups.count(key) == 0) order.push_back(key);
    groups[key].push_back(&r);
  }
  for (const auto& key : order) {
    GroupRow g;
    g.dataset = key.first;
    g.variant = key.second;
    std::vector<double> se3, sim3, scale, rpe, keyframes, fps;
    bool first = true;
    for (const RunRow* r : groups[key]) {
      ++g.runs;
      if (r->status != "done") continue;
      ++g.done;
      if (first || r->tracked < g.worst_tracked) {
        g.worst_tracked = r->tracked;
        g.frames = r->frames;
      }
      first = false;
      if (r->ate_se3) se3.push_back(*r->ate_se3);
      if (r->ate_sim3) sim3.push_back(*r->ate_sim3);
      if (r->sim3_scale) scale.push_back(*r->sim3_scale);
      if (r->rpe) rpe.push_back(*r->rpe);
      keyframes.push_back(static_cast<double>(r->keyframes));
      fps.push_back(r->fps);
    }
    const Spread a = SpreadOf(se3), b = SpreadOf(sim3), s = SpreadOf(scale), p = SpreadOf(rpe);
    g.se3_mean = a.mean, g.se3_std = a.std, g.se3_max = a.max;
    g.sim3_mean = b.mean, g.sim3_std = b.std, g.sim3_max = b.max;
    g.scale_mean = s.mean;
    g.rpe_mean = p.mean, g.rpe_max = p.max;
    if (!keyframes.empty()) g.keyframes_mean = *SpreadOf(keyframes).mean;
    if (!fps.empty()) g.fps_mean = *SpreadOf(fps).mean;
    c.groups.push_back(g);
  }
  return c;
}

std::string ResultsCsv(const Collection& c) {
  std::string out =
      "dataset,variant,seed,status,frames,tracked,keyframes,ate_se3_m,ate_sim3_m,sim3_scale,"
      "rpe_30f_m,fps\n";
  for (const RunRow& r : c.runs) {
    const bool done = r.status == "done";
    out += r.dataset + "," + r.variant + "," + r.seed + "," + r.status + "," +
           (done ? std::to_string(r.frames) : "") + "," + (done ? std::to_string(r.tracked) : "") +
           "," + (done ? std::to_string(r.keyframes) : "") + "," + Fixed(r.ate_se3, 6) + "," +
           Fixed(r.ate_sim3, 6) + "," + Fixed(r.sim3_scale, 6) + "," + Fixed(r.rpe, 6) + "," +
           (done ? Fixed(r.fps, 2) : "") + "\n";
  }
  return out;
}

std::string ResultsMarkdown(const Collection& c) {
  std::string out =
      "| dataset | variant | seed | status | tracked | keyframes | ATE se3 (m) | ATE sim3 (m) | "
      "sim3 scale | RPE 30 f (m) | frames/s |\n|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const RunRow& r : c.runs) {
    const bool done = r.status == "done";
    out += "| " + r.dataset + " | " + r.variant + " | " + r.seed + " | " +
           (done ? r.status : r.status + " (" + r.log + ")") + " | " +
           (done ? std::to_string(r.tracked) + "/" + std::to_string(r.frames) : "") + " | " +
           (done ? std::to_string(r.keyframes) : "") + " | " + Fixed(r.ate_se3, 4) + " | " +
           Fixed(r.ate_sim3, 4) + " | " + Fixed(r.sim3_scale, 3) + " | " + Fixed(r.rpe, 4) +
           " | " + (done ? Fixed(r.fps, 1) : "") + " |\n";
  }
  return out;
}

std::string SummaryCsv(const Collection& c) {
  std::string out =
      "dataset,variant,runs,done,worst_tracked,frames,ate_se3_mean_m,ate_se3_std_m,"
      "ate_se3_max_m,ate_sim3_mean_m,ate_sim3_std_m,ate_sim3_max_m,sim3_scale_mean,"
      "rpe_30f_mean_m,rpe_30f_max_m,keyframes_mean,fps_mean\n";
  for (const GroupRow& g : c.groups) {
    const bool any = g.done > 0;
    out += g.dataset + "," + g.variant + "," + std::to_string(g.runs) + "," +
           std::to_string(g.done) + "," + (any ? std::to_string(g.worst_tracked) : "") + "," +
           (any ? std::to_string(g.frames) : "") + "," + Fixed(g.se3_mean, 6) + "," +
           Fixed(g.se3_std, 6) + "," + Fixed(g.se3_max, 6) + "," + Fixed(g.sim3_mean, 6) + "," +
           Fixed(g.sim3_std, 6) + "," + Fixed(g.sim3_max, 6) + "," + Fixed(g.scale_mean, 6) +
           "," + Fixed(g.rpe_mean, 6) + "," + Fixed(g.rpe_max, 6) + "," +
           (any ? Fixed(g.keyframes_mean, 1) : "") + "," + (any ? Fixed(g.fps_mean, 2) : "") +
           "\n";
  }
  return out;
}

std::string SummaryMarkdown(const Collection& c) {
  std::string out =
      "| dataset | variant | runs done | worst tracked | ATE se3 mean ± std (max) (m) | "
      "ATE sim3 mean ± std (max) (m) | sim3 scale | RPE 30 f mean (max) (m) | keyframes | "
      "frames/s |\n|---|---|---|---|---|---|---|---|---|---|\n";
  auto triple = [](const std::optional<double>& m, const std::optional<double>& s,
                   const std::optional<double>& x) {
    if (!m) return std::string();
    return Fixed(m, 4) + " ± " + Fixed(s, 4) + " (" + Fixed(x, 4) + ")";
  };
  for (const GroupRow& g : c.groups) {
    const bool any = g.done > 0;
    out += "| " + g.dataset + " | " + g.variant + " | " + std::to_string(g.done) + "/" +
           std::to_string(g.runs) + " | " +
           (any ? std::to_string(g.worst_tracked) + "/" + std::to_string(g.frames) : "") + " | " +
           triple(g.se3_mean, g.se3_std, g.se3_max) + " | " +
           triple(g.sim3_mean, g.sim3_std, g.sim3_max) + " | " + Fixed(g.scale_mean, 3) + " | " +
           (g.rpe_mean ? Fixed(g.rpe_mean, 4) + " (" + Fixed(g.rpe_max, 4) + ")" : "") + " | " +
           (any ? Fixed(g.keyframes_mean, 1) : "") + " | " + (any ? Fixed(g.fps_mean, 1) : "") +
           " |\n";
  }
  return out;
}

void WriteCollection(const Batch& batch, const Collection& c) {
  // Everything is rendered before anything is written.
  const std::string results_csv = ResultsCsv(c), summary_csv = SummaryCsv(c);
  const std::string markdown = "# " + batch.plan_name + "\n\nOver seeds:\n\n" +
                               SummaryMarkdown(c) + "\nEvery run:\n\n" + ResultsMarkdown(c);
  WriteTextFileAtomic(batch.dir / "results.csv", results_csv);
  WriteTextFileAtomic(batch.dir / "summary.csv", summary_csv);
  WriteTextFileAtomic(batch.dir / "results.md", markdown);
  std::vector<fs::path> dirs;
  std::vector<std::string> names;
  for (size_t i = 0; i < c.runs.size(); ++i) {
    if (c.runs[i].status != "done") continue;
    dirs.push_back(batch.runs[i].out);
    names.push_back(c.runs[i].id);
  }
  if (!dirs.empty()) WriteComparisonReport(dirs, names, ReportOptions(), batch.dir / "report.html");
}

}  // namespace ademono::batch
