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

// What a precontrol the same in every cycle can reach at most on one verification (`prefix`:
// seed_line or iso100), from its columns <prefix>_before_mm, _scatter_floor_mm and
// _reduction_percent: per plant the ceiling 100 (1 - scatter floor / before) [%] (the floor is
// half the widest distance between two compensated cycles: docs/decisions/0082). Text: its
// median, 10th percentile and worst, and the plants whose ceiling lies below `goal_percent`,
// each with the reduction it reached (no table can bring them to the goal, whatever its
// structure). Plants without a measured floor (NaN, or 0 from a single cycle) are left out; ""
// when no plant is left or the table has no such columns.
std::string summarize_scatter_ceiling(const PopulationTable& table, const std::string& prefix,
                                      double goal_percent);

}  // namespace imscal::eval
