#pragma once
// Small robust statistics shared by the estimators and the report.

#include <vector>

namespace ademono {

// The median (mean of the two middle values for an even count); 0 for an empty vector.
double Median(std::vector<double> values);

// The robust spread of `values` about `centre`: 1.4826 x the median absolute deviation, which is
// the standard deviation for Gaussian values; 0 for an empty vector.
double RobustSpread(const std::vector<double>& values, double centre = 0.0);

}  // namespace ademono
