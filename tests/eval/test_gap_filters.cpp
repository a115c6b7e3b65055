// The filters the gap candidates are built from, against closed forms: the relay's memory on a
// known sequence, the orthonormality of the discrete Laguerre impulse responses, the step
// response of the second-order filter, the run-wise
// derivative of a parabola (exact for central differences), and that no filter reaches across a
// time gap.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <tuple>
#include <utility>

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

TEST(GapFilters, LaguerreIntoAMatrixGivesTheFiltersOfEveryLowerOrder) {
  // A lower order's filters are the first of a higher order's: filtered once at the highest order
  // into a matrix block, a time scale must give bit for bit what laguerre() gives for each lower
  // order, over two runs (each restarted at its first input).
  const GapSignals s = record(400, {{0, 150}, {150, 400}});
  Column u(400);
  for (Eigen::Index k = 0; k < 400; ++k) u[k] = std::sin(0.05 * double(k)) + 0.01 * double(k % 7);
  Eigen::MatrixXd pool = Eigen::MatrixXd::Constant(400, 12, -7.0);
  laguerre_into(u, 0.01, s, pool.middleCols(1, 4));
  laguerre_into(u, 0.03, s, pool.middleCols(5, 6));
  for (const auto& [tau_s, order, first] : {std::tuple{0.01, 4, 1}, std::tuple{0.01, 2, 1},
                                            std::tuple{0.03, 6, 5}, std::tuple{0.03, 3, 5}}) {
    const std::vector<Column> direct = laguerre(u, tau_s, order, s);
    for (int i = 0; i < order; ++i)
      EXPECT_EQ(pool.col(first + i), direct[std::size_t(i)]) << tau_s << " " << i;
  }
  // The columns outside the blocks are left as they were.
  EXPECT_TRUE((pool.col(0).array() == -7.0).all());
  EXPECT_TRUE((pool.col(11).array() == -7.0).all());
}

TEST(GapFilters, SecondOrderStepResponseFollowsTheClosedForm) {
  // A unit step at k = 1 into ω²/(s² + 2ζωs + ω²), 8 Hz, ζ = 0.05, held over each 2 ms cycle:
  // y(t) = 1 - e^(-ζωt) (cos ω_d t + ζ/sqrt(1 - ζ²) sin ω_d t), rate y' = ω/sqrt(1 - ζ²)
  // e^(-ζωt) sin ω_d t, t from the start of the cycle the step is held in (y[k] is the state at
  // the end of cycle k). Tolerance 1 % of the step: the integrator's stated accuracy (measured
  // 0.63 %: its phase error, ~(ωh)² / 24 per substep, adds up over the 16 periods).
  const std::size_t n = 1000;  // 2 s: 16 periods
  const GapSignals s = record(n, {{0, n}});
  Column step = Column::Ones(Eigen::Index(n));
  step[0] = 0.0;
  const double f = 8.0, zeta = 0.05, w = 2.0 * M_PI * f, wd = w * std::sqrt(1.0 - zeta * zeta);
  const auto [y, rate] = second_order(step, f, zeta, s);
  EXPECT_EQ(y[0], 0.0);  // at rest in its first input
  double worst = 0.0;
  for (std::size_t k = 1; k < n; ++k) {
    const double t = double(k) * s.cycle_s;
    const double decay = std::exp(-zeta * w * t);
    const double y_exact =
        1.0 - decay * (std::cos(wd * t) + zeta / std::sqrt(1.0 - zeta * zeta) * std::sin(wd * t));
    const double rate_exact = w / std::sqrt(1.0 - zeta * zeta) * decay * std::sin(wd * t) / w;
    worst = std::max({worst, std::abs(y[Eigen::Index(k)] - y_exact),
                      std::abs(rate[Eigen::Index(k)] - rate_exact)});
  }
  std::printf("second-order step response, 8 Hz, zeta 0.05: worst error %.2e of the step\n", worst);
  EXPECT_LT(worst, 0.01);
  // The one map per cycle is the 8 substeps composed: the substeps run one by one give the same
  // (rounding of ~1000 x 8 operations on values ~1: 1e-12).
  const double h = s.cycle_s / 8;
  double p = 0.0, v = 0.0;
  for (std::size_t k = 1; k < n; ++k) {
    for (int i = 0; i < 8; ++i) {
      v += h * (w * w * (1.0 - p) - 2.0 * zeta * w * v);
      p += h * v;
    }
    ASSERT_NEAR(y[Eigen::Index(k)], p, 1e-12) << k;
    ASSERT_NEAR(rate[Eigen::Index(k)], v / w, 1e-12) << k;
  }
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
