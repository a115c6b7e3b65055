// The population's summary (eval/population_summary.hpp) against closed forms: the percentile
// of a few values by hand, the correlation of exactly linear and of unrelated series.
#include <gtest/gtest.h>

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

}  // namespace
}  // namespace imscal::eval
