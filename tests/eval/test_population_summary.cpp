// The population's summary (eval/population_summary.hpp) against closed forms: the percentile
// of a few values by hand, the correlation of exactly linear and of unrelated series.
#include <gtest/gtest.h>

#include <limits>

#include "eval/population_summary.hpp"

namespace imscal::eval {
namespace {

TEST(PopulationSummary, PercentileInterpolatesBetweenSortedValues) {
  const std::vector<double> v{95.0, 80.0, 90.0, 85.0, 100.0};  // sorted 80 85 90 95 100
  EXPECT_DOUBLE_EQ(percentile(v, 50.0), 90.0);
  EXPECT_DOUBLE_EQ(percentile(v, 0.0), 80.0);
  EXPECT_DOUBLE_EQ(percentile(v, 100.0), 100.0);
  EXPECT_DOUBLE_EQ(percentile(v, 10.0), 82.0);  // position 0.4 between 80 and 85
  EXPECT_DOUBLE_EQ(percentile({7.0}, 10.0), 7.0);
  EXPECT_THROW(percentile({}, 50.0), std::invalid_argument);
}

TEST(PopulationSummary, CorrelationOfLinearAndConstantSeries) {
  EXPECT_NEAR(correlation({1, 2, 3, 4}, {3, 5, 7, 9}), 1.0, 1e-15);
  EXPECT_NEAR(correlation({1, 2, 3, 4}, {9, 7, 5, 3}), -1.0, 1e-15);
  EXPECT_EQ(correlation({1, 2, 3}, {4, 4, 4}), 0.0);
  // {1,2,3,4} against {1,-1,-1,1}: centred sums give 0 exactly.
  EXPECT_NEAR(correlation({1, 2, 3, 4}, {1, -1, -1, 1}), 0.0, 1e-15);
}

TEST(PopulationSummary, StrongestDrawsAndTheSummaryLine) {
  PopulationTable t;
  t.columns = {"seed", "stiffness", "noise", "reduction_percent"};
  t.rows = {{1, 0.7, 1, 85}, {2, 1.0, -1, 91}, {3, 1.3, -1, 97}, {4, 1.0, 1, 91}};
  const auto strongest = strongest_correlations(t, "reduction_percent", {"reduction_percent"}, 1);
  ASSERT_EQ(strongest.size(), 1u);
  EXPECT_EQ(strongest[0].column, "stiffness");
  EXPECT_NEAR(strongest[0].r, 1.0, 1e-12);
  const std::string text = summarize_figure(t, "reduction_percent", {"reduction_percent"});
  EXPECT_NE(text.find("4 plants, median 91.0, 10th percentile 86.8, worst 85.0 (seed 1)"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("stiffness +1.00"), std::string::npos) << text;
}

// The ceiling by hand: 100 (1 - floor / before) = 96, 90, 95 % for the three plants with both
// values (the fourth has no floor, the fifth a floor of 0 from one cycle: both left out); their
// median 95, 10th percentile 90 + 0.2 (95 - 90) = 91 (position 0.2 of the sorted 90, 95, 96), worst
// 90 (seed 2). Printed to one decimal, so the strings are exact.
TEST(PopulationSummary, ScatterCeilingNamesThePlantsNoTableBringsToTheGoal) {
  PopulationTable t;
  t.columns = {"seed", "seed_line_before_mm", "seed_line_scatter_floor_mm",
               "seed_line_reduction_percent"};
  const double nan = std::numeric_limits<double>::quiet_NaN();
  t.rows = {{1, 10.0, 0.4, 94.0},
            {2, 5.0, 0.5, 85.5},
            {3, 8.0, 0.4, 91.0},
            {4, 6.0, nan, 80.0},
            {5, 6.0, 0.0, 70.0}};
  const std::string text = summarize_scatter_ceiling(t, "seed_line", 93.0);
  EXPECT_NE(text.find("3 plants, median 95.0, 10th percentile 91.0, worst 90.0 (seed 2)"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("ceiling below 93: 1 of 3 plants: 2 (ceiling 90.0, reached 85.5);"),
            std::string::npos)
      << text;
  EXPECT_NE(summarize_scatter_ceiling(t, "seed_line", 80.0).find("below 80: 0 of 3 plants: none"),
            std::string::npos);
  EXPECT_EQ(summarize_scatter_ceiling(t, "iso100", 90.0), "");  // no such columns
  t.rows = {{5, 6.0, 0.0, 70.0}};
  EXPECT_EQ(summarize_scatter_ceiling(t, "seed_line", 93.0), "");  // no plant with a floor
}

}  // namespace
}  // namespace imscal::eval
