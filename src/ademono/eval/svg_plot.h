#pragma once
// A self-contained SVG report of one evaluation: the top view of the ground truth and the aligned
// estimate (the two axes along which the ground truth extends most), and the APE over time.

#include <string>

#include "ademono/eval/trajectory_eval.h"

namespace ademono {

std::string RenderEvalSvg(const EvalResult& result, const std::string& title);

}  // namespace ademono
