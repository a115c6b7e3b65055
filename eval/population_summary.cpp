#include "eval/population_summary.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>

namespace imscal::eval {
namespace {

std::optional<std::size_t> find_column(const PopulationTable& table, const std::string& name) {
  const auto it = std::find(table.columns.begin(), table.columns.end(), name);
  if (it == table.columns.end()) return std::nullopt;
  return static_cast<std::size_t>(it - table.columns.begin());
}

std::size_t column_index(const PopulationTable& table, const std::string& name) {
  const auto index = find_column(table, name);
  if (!index) throw std::invalid_argument("population: no column " + name);
  return *index;
}

// "N plants, median M, 10th percentile P, worst W (seed S)" of values (not empty), one per seed.
std::string distribution_in_words(const std::vector<double>& values,
                                  const std::vector<double>& seeds) {
  const auto worst =
      static_cast<std::size_t>(std::min_element(values.begin(), values.end()) - values.begin());
  return fmt::format("{} plants, median {:.1f}, 10th percentile {:.1f}, worst {:.1f} (seed {:.0f})",
                     values.size(), percentile(values, 50.0), percentile(values, 10.0),
                     values[worst], seeds[worst]);
}

std::vector<double> column_values(const PopulationTable& table, std::size_t index) {
  std::vector<double> values;
  for (const auto& row : table.rows) values.push_back(row.at(index));
  return values;
}

}  // namespace

double correlation(const std::vector<double>& a, const std::vector<double>& b) {
  const double n = static_cast<double>(a.size());
  double mean_a = 0.0, mean_b = 0.0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    mean_a += a[k] / n;
    mean_b += b[k] / n;
  }
  double ab = 0.0, aa = 0.0, bb = 0.0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    ab += (a[k] - mean_a) * (b[k] - mean_b);
    aa += (a[k] - mean_a) * (a[k] - mean_a);
    bb += (b[k] - mean_b) * (b[k] - mean_b);
  }
  return aa > 0.0 && bb > 0.0 ? ab / std::sqrt(aa * bb) : 0.0;
}

std::vector<DrawCorrelation> strongest_correlations(const PopulationTable& table,
                                                    const std::string& figure,
                                                    const std::vector<std::string>& figures,
                                                    std::size_t count) {
  const std::vector<double> target = column_values(table, column_index(table, figure));
  std::vector<DrawCorrelation> out;
  for (std::size_t c = 1; c < table.columns.size(); ++c) {
    if (std::find(figures.begin(), figures.end(), table.columns[c]) != figures.end()) continue;
    out.push_back({table.columns[c], correlation(column_values(table, c), target)});
  }
  std::stable_sort(out.begin(), out.end(), [](const DrawCorrelation& x, const DrawCorrelation& y) {
    return std::abs(x.r) > std::abs(y.r);
  });
  if (out.size() > count) out.resize(count);
  return out;
}

std::string summarize_figure(const PopulationTable& table, const std::string& figure,
                             const std::vector<std::string>& figures) {
  const std::size_t index = column_index(table, figure);
  const std::vector<double> values = column_values(table, index);
  if (values.empty()) return figure + ": no plants\n";
  std::string text =
      fmt::format("{}: {}\n", figure, distribution_in_words(values, column_values(table, 0)));
  if (values.size() < 3) return text;
  text +=
      "  draws correlated with it (Pearson r over the plants; a low figure goes with the\n"
      "  draw when r > 0 and the draw is low, or r < 0 and the draw is high):";
  for (const DrawCorrelation& c : strongest_correlations(table, figure, figures, 5))
    text += fmt::format(" {} {:+.2f};", c.column, c.r);
  return text + "\n";
}

std::string summarize_scatter_ceiling(const PopulationTable& table, const std::string& prefix,
                                      double goal_percent) {
  const auto i_before = find_column(table, prefix + "_before_mm");
  const auto i_floor = find_column(table, prefix + "_scatter_floor_mm");
  const auto i_reached = find_column(table, prefix + "_reduction_percent");
  if (!i_before || !i_floor || !i_reached) return "";
  std::vector<double> ceilings, seeds, reductions;
  for (const auto& row : table.rows) {
    // One cycle has no scatter to measure (floor 0): such a plant has no ceiling to report.
    if (!(row.at(*i_floor) > 0.0 && row.at(*i_before) > 0.0)) continue;
    ceilings.push_back(100.0 * (1.0 - row.at(*i_floor) / row.at(*i_before)));
    seeds.push_back(row.front());
    reductions.push_back(row.at(*i_reached));
  }
  if (ceilings.empty()) return "";
  std::string text = fmt::format(
      "{} scatter ceiling (100 (1 - scatter floor / before), the most a precontrol the same in "
      "every cycle can reach): {}\n",
      prefix, distribution_in_words(ceilings, seeds));
  std::string below;
  std::size_t count = 0;
  for (std::size_t k = 0; k < ceilings.size(); ++k) {
    if (ceilings[k] >= goal_percent) continue;
    ++count;
    below += fmt::format(" {:.0f} (ceiling {:.1f}, reached {:.1f});", seeds[k], ceilings[k],
                         reductions[k]);
  }
  return text + fmt::format("  ceiling below {:.0f}: {} of {} plants:{}\n", goal_percent, count,
                            ceilings.size(), count == 0 ? " none" : below);
}

}  // namespace imscal::eval
