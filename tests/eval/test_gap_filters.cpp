// The filters the gap candidates are built from, against closed forms: the relay's memory on a
// known sequence, the orthonormality of the discrete Laguerre impulse responses, the run-wise
// derivative of a parabola (exact for central differences), and that no filter reaches across a
// time gap.
#include <gtest/gtest.h>

#include <cmath>

#include "eval/gap_filters.hpp"

namespace imscal::eval {
namespace {

GapSignals record(std::size_t n, std::vector<std::pair<std::size_t, std::size_t>> runs) {
  GapSignals s;
  s.cycle_s = 0.002;
  s.runs = std::move(runs);
  for (std::size_t k = 0; k < n; ++k) s.time_s.push_back(double(k) * s.cycle_s);
  return s;
}

TEST(GapFilters, RelayHoldsItsLastSideInsideTheThreshold) {
  const GapSignals s = record(9, {{0, 9}});
  Column z(9);
  z << 0.0, 0.05, 0.5, 0.05, -0.05, -0.5, 0.0, 0.09, 0.2;
  // Threshold 0.1: undecided until 0.5 (so the first decision, +1, back-fills), held through the
  // small values, -1 from -0.5 on, +1 again from 0.2.
  Column expected(9);
  expected << 1, 1, 1, 1, 1, -1, -1, -1, 1;
  EXPECT_EQ(relay(z, 0.1, s), expected);
  // Never decided: one flank all along.
  EXPECT_EQ(relay(Column::Constant(9, 0.05), 0.1, s), Column::Ones(9));
}

TEST(GapFilters, LaguerreImpulseResponsesAreOrthonormal) {
  // 3000 samples at 2 ms = 200 time constants of 30 ms: the responses have decayed to ~e^-150.
  const GapSignals s = record(3000, {{0, 3000}});
  Column impulse = Column::Zero(3000);
  impulse[1] = 1.0;  // the first sample sets the filters' rest state: 0 here
  const std::vector<Column> l = laguerre(impulse, 0.03, 5, s);
  for (std::size_t i = 0; i < l.size(); ++i)
    for (std::size_t j = 0; j < l.size(); ++j)
      EXPECT_NEAR(l[i].dot(l[j]), i == j ? 1.0 : 0.0, 1e-12) << i << "," << j;
}

TEST(GapFilters, RunDerivativeIsExactOnAParabolaAndStaysInsideItsRun) {
  const GapSignals s = record(20, {{0, 10}, {10, 20}});
  Column x(20);
  for (Eigen::Index k = 0; k < 20; ++k)
    x[k] = 3.0 * s.time_s[std::size_t(k)] * s.time_s[std::size_t(k)];
  const Column d = run_derivative(x, s);
  for (Eigen::Index k = 1; k < 9; ++k) EXPECT_NEAR(d[k], 6.0 * s.time_s[std::size_t(k)], 1e-12);
  // The ends of each run are one-sided (forward / backward differences: off by 3 dt).
  EXPECT_NEAR(d[0], 6.0 * 0.5 * s.cycle_s, 1e-12);
  EXPECT_NEAR(d[9], 6.0 * (s.time_s[9] - 0.5 * s.cycle_s), 1e-12);
  EXPECT_NEAR(d[10], 6.0 * (s.time_s[10] + 0.5 * s.cycle_s), 1e-12);
  // A first-order lag restarts at the second run from its first input: a step there passes.
  Column step = Column::Zero(20);
  step.tail(10).setOnes();
  const Column y = lag(step, 0.03, s);
  EXPECT_DOUBLE_EQ(y[10], 1.0);
  EXPECT_DOUBLE_EQ(y[9], 0.0);
}

}  // namespace
}  // namespace imscal::eval
