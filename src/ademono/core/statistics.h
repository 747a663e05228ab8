#pragma once
// Small robust statistics shared by the estimators and the report.

#include <vector>

namespace ademono {

// The median (mean of the two middle values for an even count); 0 for an empty vector.
double Median(std::vector<double> values);

}  // namespace ademono
