// The gear mode as a filter with state (ident/gear_mode_filter.hpp, exogenous_values with an
// ExogenousFilterState) against an independent truth: the mode's ODE
// y'' + 2 ζ ω y' + ω² y = ω² e^{jφ(t)} integrated by RK4 at a step 200 times finer than the
// filter's, on chirps that sweep the error's frequency through the mode faster than its decay
// (the transient, where the steady-state response H(jΩ) e^{jφ} is wrong), and on a steady speed.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <complex>
#include <functional>
#include <numbers>
#include <vector>

#include "ident/exogenous_inputs.hpp"
#include "ident/gear_mode_filter.hpp"

namespace {
namespace ident = imscal::ident;
using ident::TableInput;
using Complex = std::complex<double>;

constexpr double kMode_rad_s = 2.0 * std::numbers::pi * 15.0;  // the KR 16's ~15 Hz
constexpr double kDamping = 0.05;
constexpr double kStep_s = 0.002;     // the robot's cycle
constexpr double kPhaseRate = 160.0;  // order 1 x gear ratio 160

// The ODE's y at every multiple of kStep_s up to t_end, from the steady state at t = 0
// (y = H(jΩ(0)) e^{jφ(0)}, y' = jΩ(0) y), under the input e^{jφ(t)}.
std::vector<Complex> ode_response(const std::function<double(double)>& phase,
                                  const std::function<double(double)>& frequency, double t_end_s) {
  const double w = kMode_rad_s, z = kDamping;
  constexpr int kSubsteps = 200;
  const double dt = kStep_s / kSubsteps;
  auto accel = [&](double t, Complex y, Complex v) {
    return w * w * (std::polar(1.0, phase(t)) - y) - 2.0 * z * w * v;
  };
  const double omega_0 = frequency(0.0);
  Complex y = w * w / Complex(w * w - omega_0 * omega_0, 2.0 * z * w * omega_0) *
              std::polar(1.0, phase(0.0));
  Complex v = Complex(0.0, omega_0) * y;
  std::vector<Complex> out{y};
  const long steps = std::lround(t_end_s / kStep_s);
  for (long k = 0; k < steps; ++k) {
    for (int i = 0; i < kSubsteps; ++i) {
      const double t = double(k) * kStep_s + double(i) * dt;
      const Complex k1y = v, k1v = accel(t, y, v);
      const Complex k2y = v + 0.5 * dt * k1v, k2v = accel(t + 0.5 * dt, y + 0.5 * dt * k1y, k2y);
      const Complex k3y = v + 0.5 * dt * k2v, k3v = accel(t + 0.5 * dt, y + 0.5 * dt * k2y, k3y);
      const Complex k4y = v + dt * k3v, k4v = accel(t + dt, y + dt * k3y, k4y);
      y += dt / 6.0 * (k1y + 2.0 * k2y + 2.0 * k3y + k4y);
      v += dt / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
    }
    out.push_back(y);
  }
  return out;
}

ident::ExogenousParameters mode_parameters() {
  ident::ExogenousParameters p;
  p.transmission_error_rad_per_rad = kPhaseRate;
  p.transmission_error_mode_rad_s = kMode_rad_s;
  p.transmission_error_mode_damping = kDamping;
  return p;
}

// A joint path x(t) = a t² / 2 + x0 (speed a t): the error's frequency kPhaseRate a t sweeps from
// 0 through the mode. Returns the largest |filter − ODE| and |steady state − ODE| over the path,
// both relative to the pair's unit amplitude.
std::array<double, 2> sweep_errors(double acceleration_rad_s2, double t_end_s) {
  const double x0 = 0.3;
  auto angle = [&](double t) { return x0 + 0.5 * acceleration_rad_s2 * t * t; };
  auto phase = [&](double t) { return kPhaseRate * angle(t); };
  auto frequency = [&](double t) { return kPhaseRate * acceleration_rad_s2 * t; };
  const std::vector<Complex> truth = ode_response(phase, frequency, t_end_s);
  const ident::ExogenousParameters p = mode_parameters();
  const std::array<TableInput, 2> inputs{TableInput::kTransmissionErrorModeSin,
                                         TableInput::kTransmissionErrorModeCos};
  ident::ExogenousFilterState state;
  ident::restart_exogenous_filter(state, p, kStep_s);
  double filter_error = 0.0, steady_error = 0.0;
  for (std::size_t k = 0; k < truth.size(); ++k) {
    const double t = double(k) * kStep_s;
    const ident::ExogenousSample s{angle(t), acceleration_rad_s2 * t, 0.0};
    std::array<double, 2> filtered{};
    ident::exogenous_values(inputs, p, s, state, filtered.data());
    std::array<double, 2> steady{};
    ident::exogenous_values(inputs, p, s, steady.data());
    filter_error = std::max(filter_error, std::abs(Complex(filtered[1], filtered[0]) - truth[k]));
    steady_error = std::max(steady_error, std::abs(Complex(steady[1], steady[0]) - truth[k]));
  }
  return {filter_error, steady_error};
}

TEST(GearModeFilter, FollowsTheModesTransientOnASweepThroughTheResonance) {
  // Through 0 → 2 ω_n in 0.1, 0.25 and 0.6 s (seed-line's A2 accelerates through the ~15 Hz mode
  // in well under the mode's 0.21 s decay), then on for half as long again. Tolerance 0.5 % of
  // the pair's unit amplitude: the filter holds Ω constant over each 2 ms step, a phase error of
  // ½ Ω̇ h² ≤ 0.004 rad at the fastest sweep (measured 0.19, 0.09, 0.05 %); the steady state
  // misses the transient by 8-9 times the amplitude there (the resonant gain the link never
  // reaches), so the test separates the two.
  for (const double sweep_s : {0.1, 0.25, 0.6}) {
    const double accel = 2.0 * kMode_rad_s / kPhaseRate / sweep_s;
    const std::array<double, 2> error = sweep_errors(accel, 1.5 * sweep_s);
    SCOPED_TRACE(sweep_s);
    EXPECT_LT(error[0], 0.005);
    EXPECT_GT(error[1], 1.0);
  }
}

TEST(GearModeFilter, SteadyStateIsTheModesResponseAndAtRestThePlainPair) {
  // At a constant speed from its steady state the filter stays on H(jΩ) e^{jφ}: the discretization
  // is exact for a complex exponential at a constant frequency (rounding only, 1e-9).
  const ident::ExogenousParameters p = mode_parameters();
  const std::array<TableInput, 2> inputs{TableInput::kTransmissionErrorModeSin,
                                         TableInput::kTransmissionErrorModeCos};
  for (const double ratio : {0.0, 0.5, 1.0, -1.3, 3.0}) {
    const double speed = ratio * kMode_rad_s / kPhaseRate;
    ident::ExogenousFilterState state;
    ident::restart_exogenous_filter(state, p, kStep_s);
    for (int k = 0; k < 500; ++k) {
      const ident::ExogenousSample s{0.2 + speed * kStep_s * k, speed, 0.0};
      std::array<double, 2> filtered{}, steady{};
      ident::exogenous_values(inputs, p, s, state, filtered.data());
      ident::exogenous_values(inputs, p, s, steady.data());
      EXPECT_NEAR(filtered[0], steady[0], 1e-9) << ratio << " " << k;
      EXPECT_NEAR(filtered[1], steady[1], 1e-9) << ratio << " " << k;
    }
  }
  // Without a mode the stateful values are the plain pair, sample for sample.
  ident::ExogenousParameters plain = p;
  plain.transmission_error_mode_rad_s = 0.0;
  ident::ExogenousFilterState state;
  ident::restart_exogenous_filter(state, plain, kStep_s);
  const ident::ExogenousSample s{0.7, 0.5, 0.0};
  std::array<double, 2> v{};
  ident::exogenous_values(inputs, plain, s, state, v.data());
  EXPECT_EQ(v[0], std::sin(kPhaseRate * 0.7));
  EXPECT_EQ(v[1], std::cos(kPhaseRate * 0.7));
}

TEST(GearModeFilter, SecondPairRunsItsOwnFilterAndIsZeroWithoutAnOrder) {
  // The second pair at twice the phase rate, on a sweep: the same as the first pair's filter fed
  // the doubled phase (one filter state per pair), and 0 when the joint has no second order.
  ident::ExogenousParameters p = mode_parameters();
  p.transmission_error_2_rad_per_rad = 2.0 * kPhaseRate;
  ident::ExogenousParameters doubled = mode_parameters();
  doubled.transmission_error_rad_per_rad = 2.0 * kPhaseRate;
  const std::array<TableInput, 4> inputs{
      TableInput::kTransmissionErrorModeSin, TableInput::kTransmissionErrorModeCos,
      TableInput::kTransmissionError2ModeSin, TableInput::kTransmissionError2ModeCos};
  ident::ExogenousFilterState both, reference;
  ident::restart_exogenous_filter(both, p, kStep_s);
  ident::restart_exogenous_filter(reference, doubled, kStep_s);
  for (int k = 0; k < 200; ++k) {
    const double t = k * kStep_s;
    const ident::ExogenousSample s{0.1 + 0.5 * t * t, t, 0.0};
    std::array<double, 4> v{};
    std::array<double, 4> r{};
    ident::exogenous_values(inputs, p, s, both, v.data());
    ident::exogenous_values(std::span(inputs.data(), 2), doubled, s, reference, r.data());
    EXPECT_EQ(v[2], r[0]);
    EXPECT_EQ(v[3], r[1]);
  }
  p.transmission_error_2_rad_per_rad = 0.0;
  ident::restart_exogenous_filter(both, p, kStep_s);
  std::array<double, 4> v{};
  ident::exogenous_values(inputs, p, ident::ExogenousSample{0.4, 0.3, 0.0}, both, v.data());
  EXPECT_EQ(v[2], 0.0);
  EXPECT_EQ(v[3], 0.0);
}

}  // namespace
