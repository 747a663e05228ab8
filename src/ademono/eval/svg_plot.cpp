#include "ademono/eval/svg_plot.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <vector>

namespace ademono {

namespace {

constexpr double kPanel = 460;  // panel size in px
constexpr double kMargin = 50;

std::string Escape(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '&':
        out += "&amp;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string Num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.2f", v);
  return buf;
}

std::string Label(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.3g", v);
  return buf;
}

struct Box {
  double x0, y0, x1, y1;  // data bounds
};

// Maps data to a panel whose top-left is (ox, oy); `equal` keeps one scale for both axes.
struct Mapper {
  Box box;
  double ox, oy, sx, sy;
  Mapper(Box b, double ox_, double oy_, bool equal) : box(b), ox(ox_), oy(oy_) {
    const double w = std::max(box.x1 - box.x0, 1e-9), h = std::max(box.y1 - box.y0, 1e-9);
    sx = kPanel / w;
    sy = kPanel / h;
    if (equal) sx = sy = std::min(sx, sy);
  }
  double X(double x) const { return ox + (x - box.x0) * sx; }
  double Y(double y) const { return oy + kPanel - (y - box.y0) * sy; }
};

std::string Polyline(const std::vector<std::array<double, 2>>& pts, const Mapper& m,
                     const char* colour, double width) {
  std::string s = "<polyline fill=\"none\" stroke=\"" + std::string(colour) + "\" stroke-width=\"" +
                  Num(width) + "\" points=\"";
  for (const auto& p : pts) s += Num(m.X(p[0])) + "," + Num(m.Y(p[1])) + " ";
  s += "\"/>\n";
  return s;
}

std::string Axes(const Mapper& m, const std::string& xlabel, const std::string& ylabel) {
  std::string s;
  s += "<rect x=\"" + Num(m.ox) + "\" y=\"" + Num(m.oy) + "\" width=\"" + Num(kPanel) +
       "\" height=\"" + Num(kPanel) + "\" fill=\"none\" stroke=\"#999\"/>\n";
  s += "<text x=\"" + Num(m.ox + kPanel / 2) + "\" y=\"" + Num(m.oy + kPanel + 35) +
       "\" text-anchor=\"middle\">" + Escape(xlabel) + "</text>\n";
  s += "<text x=\"" + Num(m.ox - 38) + "\" y=\"" + Num(m.oy + kPanel / 2) +
       "\" text-anchor=\"middle\" transform=\"rotate(-90 " + Num(m.ox - 38) + " " +
       Num(m.oy + kPanel / 2) + ")\">" + Escape(ylabel) + "</text>\n";
  // Corner tick labels: the data range actually shown.
  const double x_max = m.box.x0 + kPanel / m.sx, y_max = m.box.y0 + kPanel / m.sy;
  s += "<text x=\"" + Num(m.ox) + "\" y=\"" + Num(m.oy + kPanel + 16) + "\">" + Label(m.box.x0) +
       "</text>\n";
  s += "<text x=\"" + Num(m.ox + kPanel) + "\" y=\"" + Num(m.oy + kPanel + 16) +
       "\" text-anchor=\"end\">" + Label(x_max) + "</text>\n";
  s += "<text x=\"" + Num(m.ox - 4) + "\" y=\"" + Num(m.oy + kPanel) + "\" text-anchor=\"end\">" +
       Label(m.box.y0) + "</text>\n";
  s += "<text x=\"" + Num(m.ox - 4) + "\" y=\"" + Num(m.oy + 10) + "\" text-anchor=\"end\">" +
       Label(y_max) + "</text>\n";
  return s;
}

}  // namespace

std::string RenderEvalSvg(const EvalResult& r, const std::string& title) {
  return RenderEvalSvg(std::vector<NamedEvalResult>{{"estimate (aligned)", &r}}, title);
}

std::string RenderEvalSvg(const std::vector<NamedEvalResult>& results, const std::string& title) {
  if (results.empty()) throw std::invalid_argument("RenderEvalSvg: no results");
  // Matplotlib's tab10, without the grey used for the ground truth.
  static constexpr const char* kColours[] = {"#d62728", "#1f77b4", "#2ca02c", "#ff7f0e", "#9467bd",
                                             "#8c564b", "#e377c2", "#bcbd22", "#17becf"};
  const EvalResult* longest = results.front().result;
  for (const auto& named : results)
    if (named.result->matched_poses > longest->matched_poses) longest = named.result;
  const auto& gt = longest->gt_matched.world_from_cam;
  // The two axes of largest ground-truth extent, in axis order (x-z for a forward-moving camera).
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  for (const auto& p : gt) {
    lo = lo.cwiseMin(p.topRightCorner<3, 1>());
    hi = hi.cwiseMax(p.topRightCorner<3, 1>());
  }
  const Eigen::Vector3d extent = hi - lo;
  int drop = 0;
  for (int a = 1; a < 3; ++a)
    if (extent[a] < extent[drop]) drop = a;
  const int ax = drop == 0 ? 1 : 0;
  const int ay = drop == 2 ? 1 : 2;
  const char* names = "xyz";

  Box box{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
          -std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
  auto add = [&](std::vector<std::array<double, 2>>& pts, const Eigen::Matrix4d& p) {
    const double x = p(ax, 3), y = p(ay, 3);
    pts.push_back({x, y});
    box = {std::min(box.x0, x), std::min(box.y0, y), std::max(box.x1, x), std::max(box.y1, y)};
  };
  std::vector<std::array<double, 2>> gt_pts;
  for (const auto& p : gt) add(gt_pts, p);
  std::vector<std::vector<std::array<double, 2>>> est_pts(results.size());
  for (size_t k = 0; k < results.size(); ++k)
    for (const auto& p : results[k].result->est_aligned.world_from_cam) add(est_pts[k], p);
  const double pad = 0.05 * std::max({box.x1 - box.x0, box.y1 - box.y0, 1e-6});
  box = {box.x0 - pad, box.y0 - pad, box.x1 + pad, box.y1 + pad};
  const Mapper top(box, kMargin, kMargin + 30, true);

  // APE over time (seconds from the first matched ground-truth pose of all estimates).
  double t0 = std::numeric_limits<double>::infinity();
  for (const auto& named : results)
    if (!named.result->gt_matched.timestamps.empty())
      t0 = std::min(t0, named.result->gt_matched.timestamps.front());
  if (!std::isfinite(t0)) t0 = 0.0;
  std::vector<std::vector<std::array<double, 2>>> err_pts(results.size());
  double t_max = 1e-9, e_max = 1e-9;
  for (size_t k = 0; k < results.size(); ++k) {
    const EvalResult& r = *results[k].result;
    for (size_t i = 0; i < r.ape_errors.size(); ++i) {
      const double t = r.gt_matched.timestamps[i] - t0;
      err_pts[k].push_back({t, r.ape_errors[i]});
      t_max = std::max(t_max, t);
      e_max = std::max(e_max, r.ape_errors[i]);
    }
  }
  const Mapper err(Box{0, 0, t_max, e_max * 1.05}, 2 * kMargin + kPanel + 40, kMargin + 30, false);

  const double width = 3 * kMargin + 2 * kPanel + 40, height = kPanel + 2 * kMargin + 60;
  std::string s;
  s += "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  s += "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + Num(width) + "\" height=\"" +
       Num(height) + "\" viewBox=\"0 0 " + Num(width) + " " + Num(height) +
       "\" font-family=\"sans-serif\" font-size=\"12\">\n";
  s += "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  char header[256];
  if (results.size() == 1) {
    const EvalResult& r = *results.front().result;
    std::snprintf(header, sizeof(header), " (alignment %s, %zu poses, APE rmse %.4f m)",
                  ToString(r.alignment).c_str(), r.matched_poses, r.ape.rmse);
  } else {
    std::snprintf(header, sizeof(header), " (%zu estimates, alignment %s)", results.size(),
                  ToString(results.front().result->alignment).c_str());
  }
  s += "<text x=\"" + Num(kMargin) + "\" y=\"24\" font-size=\"15\">" + Escape(title + header) +
       "</text>\n";
  s += Axes(top, std::string(1, names[ax]) + " (m)", std::string(1, names[ay]) + " (m)");
  s += Polyline(gt_pts, top, "#555555", 1.5);
  s += "<text x=\"" + Num(top.ox + 8) + "\" y=\"" + Num(top.oy + 16) +
       "\" fill=\"#555555\">ground truth</text>\n";
  s += Axes(err, "time (s)", "APE (m)");
  const size_t palette = sizeof(kColours) / sizeof(kColours[0]);
  for (size_t k = 0; k < results.size(); ++k) {
    const char* colour = kColours[k % palette];
    s += Polyline(est_pts[k], top, colour, 1.2);
    std::string label = results[k].name;
    if (results.size() > 1) {
      char rmse[64];
      std::snprintf(rmse, sizeof(rmse), " (APE rmse %.4f m)", results[k].result->ape.rmse);
      label += rmse;
    }
    s += "<text x=\"" + Num(top.ox + 8) + "\" y=\"" +
         Num(top.oy + 32 + 16 * static_cast<double>(k)) + "\" fill=\"" + colour + "\">" +
         Escape(label) + "</text>\n";
    s += Polyline(err_pts[k], err, results.size() == 1 ? "#1f77b4" : colour, 1.2);
  }
  s += "</svg>\n";
  return s;
}

}  // namespace ademono
