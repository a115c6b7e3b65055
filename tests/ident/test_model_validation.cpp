// Validation statistics: the fit percentages against the generator's own noise, the 99 % bands
// against their nominal false-alarm rate (Monte Carlo with white and coloured sequences), and
// both correlation tests detecting the model errors they are meant for (missing dynamics,
// wrong dead time).
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <cstdlib>
#include <random>
#include <span>
#include <vector>

#include "ident/arx_fit.hpp"
#include "ident/model_validation.hpp"
#include "tests/support/arx_systems.hpp"

using imscal::ident::ArxModel;
using imscal::ident::ArxStructure;
using imscal::ident::fit_arx;
using imscal::ident::fit_percent;
using imscal::ident::input_residual_test;
using imscal::ident::IoSegment;
using imscal::ident::residual_whiteness_test;
using imscal::ident::validate_arx;
using imscal::ident::ValidationOptions;

namespace {

bool sanitized() {
  return std::getenv("IMSCAL_SANITIZED") != nullptr;
}

using imscal::test_support::view;
using Record = imscal::test_support::ArxRecord;

// A fixed stable system: poles 0.8 ± 0.3i and 0.5, input lags 3..4 (d = 3, nb = 2).
ArxModel reference_system() {
  // (z² - 1.6 z + 0.73)(z - 0.5) = z³ - 2.1 z² + 1.53 z - 0.365
  Eigen::VectorXd a(3), b(2);
  a << -2.1, 1.53, -0.365;
  b << 0.4, -0.25;
  return ArxModel({3, 2, 3}, a, b);
}

// Input: an AR(1) sequence with pole input_pole driven by white noise (coloured when != 0).
Record simulate(const ArxModel& m, std::size_t n, double noise_std, std::mt19937_64& rng,
                double input_pole = 0.0) {
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<double> u(n), e(n);
  double previous = 0.0;
  for (auto& v : u) v = previous = input_pole * previous + normal(rng);
  for (auto& v : e) v = noise_std * normal(rng);
  return imscal::test_support::simulate_arx(m, std::move(u), std::move(e));
}

}  // namespace

TEST(ModelValidation, FitPercentClosedForm) {
  // measured 1,2,3,4 (mean 2.5, ‖y-ȳ‖² = 5), estimate off by 0.5 everywhere (‖error‖² = 1).
  const std::vector<double> measured{1, 2, 3, 4}, estimate{1.5, 2.5, 3.5, 4.5};
  EXPECT_NEAR(fit_percent(measured, estimate), 100.0 * (1.0 - std::sqrt(1.0 / 5.0)), 1e-12);
  EXPECT_DOUBLE_EQ(fit_percent(measured, measured), 100.0);
  const std::vector<double> constant{2, 2, 2, 2};
  EXPECT_THROW(fit_percent(constant, measured), std::invalid_argument);
}

TEST(ModelValidation, TrueModelFitsMatchTheGeneratorNoise) {
  std::mt19937_64 rng(7);
  const ArxModel truth = reference_system();
  const Record a = simulate(truth, 3000, 0.05, rng), b = simulate(truth, 2000, 0.05, rng);
  const std::vector<IoSegment> data{view(a), view(b)};
  const auto report = validate_arx(truth, data);
  // With the true model the one-step residual is exactly the equation noise e(k) drawn by the
  // generator, so the fit follows from e and y alone (same rows k >= max_lag = 4).
  std::vector<double> y_rows;
  double e_sq = 0.0;
  for (const Record* r : {&a, &b})
    for (std::size_t k = 4; k < r->y.size(); ++k)
      y_rows.push_back(r->y[k]), e_sq += r->e[k] * r->e[k];
  double mean = 0.0, spread = 0.0;
  for (double v : y_rows) mean += v;
  mean /= double(y_rows.size());
  for (double v : y_rows) spread += (v - mean) * (v - mean);
  EXPECT_EQ(report.sample_count, y_rows.size());
  EXPECT_NEAR(report.one_step_fit_percent, 100.0 * (1.0 - std::sqrt(e_sq / spread)), 1e-9);
  EXPECT_NEAR(report.residual_rms, std::sqrt(e_sq / double(y_rows.size())), 1e-12);
  // The true model's residual is white and independent of the input: both tests pass.
  EXPECT_TRUE(report.residual_whiteness.passed) << report.residual_whiteness.outside_count;
  EXPECT_TRUE(report.input_residual.passed) << report.input_residual.outside_count;
  // Simulation accumulates the noise through 1/A(z): its fit is lower than the one-step fit.
  EXPECT_LT(report.simulation_fit_percent, report.one_step_fit_percent);
}

TEST(ModelValidation, NoiseFreeSimulationFitIsPerfect) {
  std::mt19937_64 rng(8);
  const ArxModel truth = reference_system();
  const Record r = simulate(truth, 2000, 0.0, rng);
  const std::vector<IoSegment> data{view(r)};
  // Residuals are zero, so the correlation tests are undefined (refused); the fit is checked.
  EXPECT_THROW(validate_arx(truth, data), std::invalid_argument);
  std::vector<double> simulated(r.y.size());
  truth.simulate(r.u, r.y, simulated);
  EXPECT_NEAR(fit_percent(r.y, simulated), 100.0, 1e-9);
}

TEST(ModelValidation, BandsHoldTheirNominalFalseAlarmRate) {
  // For white residuals independent of the input, each lag falls outside the 2.58 band with
  // probability 0.99 %. Count over many realisations: expected count = 0.0099 × lags; allow
  // ±5 binomial standard deviations. The input is coloured (AR pole 0.9): the cross-correlation
  // band must widen for it, otherwise the outside rate would be several times too high.
  std::mt19937_64 rng(12);
  std::normal_distribution<double> normal(0.0, 1.0);
  const int realisations = sanitized() ? 60 : 200;  // lighter under ASan/UBSan
  const std::size_t n = 2000;
  const ValidationOptions options;  // 25 lags, z = 2.58
  int white_outside = 0, white_lags = 0, cross_outside = 0, cross_lags = 0, white_fail = 0,
      cross_fail = 0;
  for (int r = 0; r < realisations; ++r) {
    std::vector<double> e(n), u(n);
    double previous = 0.0;
    for (auto& v : e) v = normal(rng);
    for (auto& v : u) v = previous = 0.9 * previous + normal(rng);
    const std::vector<std::span<const double>> es{e}, us{u};
    const auto white = residual_whiteness_test(es, options);
    const auto cross = input_residual_test(es, us, options);
    white_outside += white.outside_count;
    white_lags += int(white.lags.size());
    cross_outside += cross.outside_count;
    cross_lags += int(cross.lags.size());
    white_fail += !white.passed;
    cross_fail += !cross.passed;
  }
  const double alpha = std::erfc(2.58 / std::sqrt(2.0));
  auto expect_rate = [&](int outside, int lags, const char* what) {
    const double expected = alpha * lags, sd = std::sqrt(lags * alpha * (1 - alpha));
    EXPECT_NEAR(outside, expected, 5.0 * sd) << what;
  };
  expect_rate(white_outside, white_lags, "whiteness");
  // Neighbouring cross-correlation lags are strongly correlated for a coloured input, so the
  // count is over-dispersed; 5 binomial σ still bounds it (a wrong band gives ~10× the rate).
  expect_rate(cross_outside, cross_lags, "cross-correlation");
  // A whole test fails for a correct model with probability < 2 % by construction (allowed_outside
  // and the family-wise band, 1 % each); allow up to 5 % of the realisations.
  EXPECT_LE(white_fail, realisations / 20);
  EXPECT_LE(cross_fail, realisations / 20);
}

TEST(ModelValidation, DetectsMissingDynamicsAndWrongDeadTime) {
  std::mt19937_64 rng(31);
  const ArxModel truth = reference_system();
  const Record est = simulate(truth, 4000, 0.05, rng), val = simulate(truth, 4000, 0.05, rng);
  const std::vector<IoSegment> est_data{view(est)}, val_data{view(val)};
  // Too few poles: the residual keeps the missing dynamics, it is coloured.
  const auto under = fit_arx(est_data, ArxStructure{1, 2, 3});
  const auto under_report = validate_arx(under.model, val_data);
  EXPECT_FALSE(under_report.residual_whiteness.passed);
  // Dead time 1 with nb = 2 covers input lags 1..2 only, missing the true lags 3..4: the
  // residual correlates with u at lags 3 and 4.
  const auto wrong_delay = fit_arx(est_data, ArxStructure{3, 2, 1});
  const auto delay_report = validate_arx(wrong_delay.model, val_data);
  EXPECT_FALSE(delay_report.input_residual.passed);
  int outside_at_true_lags = 0;
  const auto& c = delay_report.input_residual;
  for (std::size_t i = 0; i < c.lags.size(); ++i)
    if ((c.lags[i] == 3 || c.lags[i] == 4) && std::abs(c.correlation[i]) > c.band)
      ++outside_at_true_lags;
  EXPECT_GE(outside_at_true_lags, 1);
  // The correct structure passes both on the same validation data.
  const auto right = fit_arx(est_data, truth.structure());
  const auto right_report = validate_arx(right.model, val_data);
  EXPECT_TRUE(right_report.residual_whiteness.passed);
  EXPECT_TRUE(right_report.input_residual.passed);
  EXPECT_GT(right_report.one_step_fit_percent, under_report.one_step_fit_percent);
}

TEST(ModelValidation, AllowedOutsideIsTheBinomialQuantile) {
  // 25 lags at α = 0.99 %: P(X > 1) = 2.6 % ≥ α, P(X > 2) = 0.2 % < α, so 2 lags may stray.
  std::mt19937_64 rng(1);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<double> e(1000);
  for (auto& v : e) v = normal(rng);
  const std::vector<std::span<const double>> es{e};
  EXPECT_EQ(residual_whiteness_test(es).allowed_outside, 2);
  // Family-wise band: per-lag level 1 - (1 - α)^(1/25) (Šidák), expressed as the band whose
  // two-sided normal tail (σ = 1/√N for a white residual) equals that level.
  const double per_lag = 1.0 - std::pow(1.0 - std::erfc(2.58 / std::sqrt(2.0)), 1.0 / 25.0);
  EXPECT_NEAR(
      std::erfc(residual_whiteness_test(es).family_band * std::sqrt(1000.0) / std::sqrt(2.0)),
      per_lag, 1e-9);
  EXPECT_NEAR(residual_whiteness_test(es).band, 2.58 / std::sqrt(1000.0), 1e-15);
}
