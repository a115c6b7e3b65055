// ident::frequency_response against two independent truths: the closed form of a first-order
// lag, and the steady-state sinusoid that ArxModel::simulate (the time-domain recursion the
// precontrol runs) produces for a higher-order model with dead time.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <complex>
#include <numbers>
#include <vector>

#include "ident/arx_frequency_response.hpp"

namespace {
namespace ident = imscal::ident;
constexpr double kT = 0.002;

TEST(ArxFrequencyResponse, FirstOrderLagMatchesClosedForm) {
  const double p = 0.9;
  const ident::ArxModel model({1, 1, 0}, Eigen::VectorXd::Constant(1, -p),
                              Eigen::VectorXd::Constant(1, 1.0 - p), kT);
  const std::vector<double> f = {0.0, 1.0, 10.0, 100.0, 250.0};
  const auto r = ident::frequency_response(model, f);
  for (std::size_t i = 0; i < f.size(); ++i) {
    const double w = 2.0 * std::numbers::pi * f[i] * kT;
    const std::complex<double> expected = (1.0 - p) / (1.0 - p * std::polar(1.0, -w));
    // Same formula evaluated two ways: only rounding differs.
    EXPECT_NEAR(std::abs(r.joint[i] - expected), 0.0, 1e-13) << f[i];
    EXPECT_NEAR(std::abs(r.joint_error[i] - (1.0 - expected)), 0.0, 1e-13) << f[i];
  }
  EXPECT_NEAR(std::abs(r.joint[0]), 1.0, 1e-14);  // unit static gain: B(1)/A(1) = 1
}

TEST(ArxFrequencyResponse, MatchesSteadyStateOfSimulatedSinusoid) {
  // Poles 0.8 ± 0.3j and 0.5, three input taps, dead time 3 samples.
  const std::complex<double> p1(0.8, 0.3);
  const double p2 = 0.5;
  // A(z) = (z - p1)(z - conj p1)(z - p2) = z^3 + a1 z^2 + a2 z + a3.
  const double s = 2.0 * p1.real(), q = std::norm(p1);
  Eigen::VectorXd a(3);
  a << -(s + p2), q + s * p2, -q * p2;
  Eigen::VectorXd b(3);
  b << 0.05, 0.03, 0.01;
  const ident::ArxModel model({3, 3, 3}, a, b, kT);
  for (double f_hz : {2.0, 12.5, 50.0, 125.0}) {
    // Integer number of periods in the fit window; 4000 settling samples: |pole| <= 0.855,
    // 0.855^4000 is far below double precision, so the transient is gone.
    const int settle = 4000, window = 2000;
    const int n = settle + window;
    std::vector<double> u(n), y(n);
    const double w = 2.0 * std::numbers::pi * f_hz * kT;
    for (int k = 0; k < n; ++k) u[std::size_t(k)] = std::sin(w * k);
    const std::vector<double> initial(std::size_t(model.structure().max_lag()), 0.0);
    model.simulate(u, initial, y);
    // Least-squares fit y = c sin(wk) + d cos(wk) over the window: G = c + j d.
    Eigen::MatrixXd m(window, 2);
    Eigen::VectorXd rhs(window);
    for (int i = 0; i < window; ++i) {
      const int k = settle + i;
      m(i, 0) = std::sin(w * k);
      m(i, 1) = std::cos(w * k);
      rhs(i) = y[std::size_t(k)];
    }
    const Eigen::Vector2d cd = m.colPivHouseholderQr().solve(rhs);
    const std::complex<double> simulated(cd(0), cd(1));
    const double fs[] = {f_hz};
    const auto r = ident::frequency_response(model, fs);
    // The simulated sinusoid is exact up to rounding in 6000 recursion steps and the fit.
    EXPECT_NEAR(std::abs(r.joint[0] - simulated), 0.0, 1e-9 * std::max(1.0, std::abs(simulated)))
        << f_hz << " Hz";
  }
}

TEST(ArxFrequencyResponse, RefusesFrequenciesBeyondNyquist) {
  const ident::ArxModel model({1, 1, 0}, Eigen::VectorXd::Constant(1, -0.5),
                              Eigen::VectorXd::Constant(1, 0.5), kT);
  const double beyond[] = {251.0};
  EXPECT_THROW(ident::frequency_response(model, beyond), std::invalid_argument);
  const auto grid = ident::log_spaced_frequencies_hz(0.1, 250.0, 50);
  EXPECT_EQ(grid.size(), 50u);
  EXPECT_DOUBLE_EQ(grid.front(), 0.1);
  EXPECT_DOUBLE_EQ(grid.back(), 250.0);
  EXPECT_NO_THROW(ident::frequency_response(model, grid));
}

}  // namespace
