#pragma once
// Percentiles of a sample, as the population summary and the orientation error report them.
#include <vector>

namespace imscal {

// Percentile p in [0, 100] of `values` by linear interpolation between the sorted values
// (p = 50: the median). std::invalid_argument when empty.
double percentile(std::vector<double> values, double p);

}  // namespace imscal
