#pragma once
// The report's web assets, compiled in from the pinned npm packages in .deps/web and from
// src/ademono/report/web/ (cmake/EmbedText.cmake), so a report needs no file at run time.

#include <string_view>

namespace ademono::web {

extern const std::string_view kUplotJs;    // uPlot 1.6.32, uPlot.iife.min.js (MIT)
extern const std::string_view kUplotCss;   // uPlot 1.6.32, uPlot.min.css
extern const std::string_view kReglJs;     // regl 2.1.1, regl.min.js (MIT)
extern const std::string_view kUplotLicense;  // their licence texts, copied into every page
extern const std::string_view kReglLicense;
extern const std::string_view kReportJs;   // web/report.js: draws the report from its JSON data
extern const std::string_view kReportCss;  // web/report.css

}  // namespace ademono::web
