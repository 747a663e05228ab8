#include "ademono/perception/detector_options.h"

#include "ademono/core/options_table.h"

namespace ademono {

const OptionsTable<DetectorOptions>& DetectorOptions::Table() {
  using D = DetectorOptions;
  static const auto table =
      OptionsTable<D>("detector")
          .Add("score_threshold", &D::score_threshold, Range::Closed(0, 1))
          .Add("nms_iou", &D::nms_iou, Range::OpenClosed(0, 1))
          .Add("class_ids", &D::class_ids, Range::AtLeast(0))  // [] = all 80 COCO classes
          .Add("class_agnostic_nms", &D::class_agnostic_nms)
          .Add("num_threads", &D::num_threads, Range::Closed(1, 64));
  return table;
}

void DetectorOptions::Check() const { Table().CheckRanges(*this); }

DetectorOptions DetectorOptions::FromYaml(const YAML::Node& node) {
  return ReadOptions<DetectorOptions>(node);
}

YAML::Node DetectorOptions::ToYaml() const { return Table().Write(*this); }

}  // namespace ademono
