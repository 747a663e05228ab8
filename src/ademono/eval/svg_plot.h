#pragma once
// A self-contained SVG report of one evaluation: the top view of the ground truth and the aligned
// estimate (the two axes along which the ground truth extends most), and the APE over time.

#include <string>
#include <vector>

#include "ademono/eval/trajectory_eval.h"

namespace ademono {

std::string RenderEvalSvg(const EvalResult& result, const std::string& title);

// Several estimates of one ground truth (evo_res style): each aligned estimate in its own colour
// in the top view and the APE panel, with its name and APE RMSE in the legend. The ground truth
// drawn is the matched ground truth of the estimate with the most matched poses.
struct NamedEvalResult {
  std::string name;
  const EvalResult* result = nullptr;
};
std::string RenderEvalSvg(const std::vector<NamedEvalResult>& results, const std::string& title);

}  // namespace ademono
