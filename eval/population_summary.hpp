#pragma once
// The figures of a plant population (`imscal population`): a table with one row per plant, its
// draws and its figures, and the summary of one figure over the plants: median, 10th
// percentile, worst, and the draws that go with a low figure (Pearson correlation over the
// plants; with few plants it is only a pointer).
#include <string>
#include <vector>

#include "core/percentile.hpp"

namespace imscal::eval {

struct PopulationTable {
  std::vector<std::string> columns;       // the first is the seed
  std::vector<std::vector<double>> rows;  // one per plant, columns.size() values each
};

// Pearson correlation of two equally long series; 0 when either does not vary.
double correlation(const std::vector<double>& a, const std::vector<double>& b);

struct DrawCorrelation {
  std::string column;
  double r = 0.0;
};

// The `count` draw columns (all columns but the seed and those in `figures`) whose correlation
// with the figure column is largest in magnitude, largest first.
std::vector<DrawCorrelation> strongest_correlations(const PopulationTable& table,
                                                    const std::string& figure,
                                                    const std::vector<std::string>& figures,
                                                    std::size_t count);

// Text summary of one figure (a reduction in %, larger is better): plants, median, 10th
// percentile, worst (with its seed) and the strongest correlations.
std::string summarize_figure(const PopulationTable& table, const std::string& figure,
                             const std::vector<std::string>& figures);

}  // namespace imscal::eval
