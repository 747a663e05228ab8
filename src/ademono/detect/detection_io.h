#pragma once
// Moved to perception/ (no ONNX Runtime there); this forwarder keeps includes of the old path
// building until every module includes the new one.
#include "ademono/perception/detection_io.h"
