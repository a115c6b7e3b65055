// The model-error model of the gap (eval/gap_model_error.hpp) against a known linear system: a
// FIR with known taps driven by white input, whose frequency response and parameter covariance
// have closed forms; and a gap that does not depend on the input at all (no significant
// frequency).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <random>

#include "eval/gap_model_error.hpp"

namespace imscal::eval {
namespace {

constexpr double kCycle = 0.002;  // s
constexpr std::size_t kSamples = 20000;

// Alternating 500-sample blocks (1 s at 2 ms), as the diagnosis's training / held-out design.
std::vector<bool> alternating_blocks(std::size_t n) {
  std::vector<bool> training(n);
  for (std::size_t k = 0; k < n; ++k) training[k] = (k / 500) % 2 == 0;
  return training;
}

TEST(GapModelError, KnownFirIsRecoveredWithItsClosedFormResponseAndCovariance) {
  // g(k) = 0.02 + 0.5 u(k) - 0.3 u(k-1) + 0.1 u(k-3) + n(k), u ~ N(0, 1), n ~ N(0, 0.05²).
  const double b[4] = {0.5, -0.3, 0.0, 0.1}, offset = 0.02, noise = 0.05;
  std::mt19937_64 rng(42);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<double> u(kSamples), g(kSamples, 0.0);
  for (double& v : u) v = normal(rng);
  for (std::size_t k = 0; k < kSamples; ++k) {
    g[k] = offset + noise * normal(rng);
    for (std::size_t i = 0; i < 4; ++i)
      if (k >= i) g[k] += b[i] * u[k - i];
  }
  const std::vector<bool> training = alternating_blocks(kSamples);
  ModelErrorOptions options;
  options.taps = 4;
  options.tap_spacing = 1;
  const ModelErrorModel m = fit_model_error_model(u, g, {{0, kSamples}}, kCycle, training, options);
  ASSERT_EQ(m.taps.size(), 4);
  EXPECT_DOUBLE_EQ(m.tap_period_s, kCycle);
  // Closed-form covariance of LS taps with white unit input and white noise:
  // sigma_b = sigma_n / sqrt(N_train). 10 %: the sample variance of u over ~10000 rows (1.4 %)
  // and the autocorrelation inflation of a white residual (a few %, it sums positive lags only).
  const double n_train = double(std::count(training.begin() + 3, training.end(), true));
  for (Eigen::Index i = 0; i < 4; ++i) {
    EXPECT_NEAR(m.tap_sigma[i], noise / std::sqrt(n_train), 0.1 * noise / std::sqrt(n_train));
    // 4 sigma: a normal draw beyond it has probability 6e-5.
    EXPECT_NEAR(m.taps[i], b[i], 4.0 * m.tap_sigma[i]);
  }
  EXPECT_NEAR(m.offset_rad, offset, 4.0 * noise / std::sqrt(n_train));
  // The response against G(f) = sum b_i exp(-j 2 pi f i T) at every grid frequency, within 4
  // sigma of |G| (first order is exact enough here: sigma_|G| ~ 1e-3 << |G| >= 0.3).
  ASSERT_EQ(m.response.size(), options.frequencies);
  for (const auto& p : m.response) {
    std::complex<double> truth = 0.0;
    for (int i = 0; i < 4; ++i)
      truth +=
          b[i] * std::exp(std::complex<double>(0.0, -2.0 * M_PI * p.frequency_hz * i * kCycle));
    EXPECT_NEAR(p.magnitude, std::abs(truth), 4.0 * p.magnitude_sigma) << p.frequency_hz << " Hz";
    EXPECT_NEAR(p.phase_rad, std::arg(truth), 4.0 * p.magnitude_sigma / std::abs(truth));
    EXPECT_TRUE(p.significant);  // |G| >= 0.3 at >= 300 sigma
    EXPECT_LE(p.lower, p.magnitude);
    EXPECT_GE(p.upper, p.magnitude);
  }
  EXPECT_TRUE(m.significant);
  // Held-out share explained: 100 (1 - sigma_n / RMS(g)), RMS(g)² = 0.5² + 0.3² + 0.1² +
  // 0.05² + 0.02²; the RMS estimates over ~10000 rows are good to ~1 % of the 8 % remainder.
  const double rms_g = std::sqrt(0.25 + 0.09 + 0.01 + noise * noise + offset * offset);
  EXPECT_NEAR(m.heldout_explained_percent, 100.0 * (1.0 - noise / rms_g), 0.5);
}

TEST(GapModelError, GapIndependentOfTheInputHasNoSignificantFrequency) {
  // A smooth input (sum of sines, like a desired joint path) and a gap of white noise: the
  // Bonferroni level 0.01 over the grid makes a false detection a 1 % event; this seed is fixed.
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal(0.0, 1e-5);
  std::vector<double> u(kSamples), g(kSamples);
  for (std::size_t k = 0; k < kSamples; ++k) {
    const double t = double(k) * kCycle;
    u[k] = 0.5 * std::sin(2.0 * M_PI * 0.3 * t) + 0.2 * std::sin(2.0 * M_PI * 1.7 * t) +
           0.01 * std::sin(2.0 * M_PI * 11.0 * t);
    g[k] = normal(rng);
  }
  const ModelErrorModel m =
      fit_model_error_model(u, g, {{0, kSamples}}, kCycle, alternating_blocks(kSamples));
  EXPECT_FALSE(m.significant);
  for (const auto& p : m.response) EXPECT_FALSE(p.significant) << p.frequency_hz << " Hz";
  // Nothing to explain: the held-out share is about 0 (negative: the fit's own noise).
  EXPECT_LT(m.heldout_explained_percent, 1.0);
}

TEST(GapModelError, RefusesMismatchedSizes) {
  EXPECT_THROW(fit_model_error_model({1.0, 2.0}, {1.0}, {{0, 2}}, kCycle, {true, true}),
               std::invalid_argument);
}

}  // namespace
}  // namespace imscal::eval
