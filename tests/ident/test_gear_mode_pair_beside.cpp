// The gear-mode transmission-error pair beside the plain pair (ident/joint_identification.hpp,
// GearModePairs::kBeside) against an independent truth. The record is made by
// tests/ident/lagged_motor_record.hpp (a motor with a one-cycle lag, θ(k+1) =
// α θ(k) + (1 - α) u(k), driving the link through an elastic gear, the record made backwards
// from a smooth link path q), with two error terms on the motor side:
//   θ = m + A_p sin(φ + ψ_p) + A_m Im(e^{jψ_m} y),  m = q + τ / k_g,  φ = f m,
// the plain error and one passed through the gear mode, y'' + 2ζω_n y' + ω_n² y = ω_n² e^{jφ},
// integrated by RK4 at T / 50 from rest (not by the identification's filter). The joint error is
// then the inverse form with one cycle of preview and two taps on each input; the taps of each
// pair sum to (A cos ψ, A sin ψ).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <numbers>
#include <vector>

#include "ident/joint_identification.hpp"
#include "tests/ident/lagged_motor_record.hpp"

namespace {
namespace ident = imscal::ident;
using std::numbers::pi;

constexpr double kDt = 0.002;
constexpr double kAlpha = 0.9;
constexpr double kArcsecRad = pi / 180.0 / 3600.0;
constexpr double kPlainRad = 10.0 * kArcsecRad, kPlainPhaseRad = 0.7;
constexpr double kModeRad = 6.0 * kArcsecRad, kModePhaseRad = -1.1;
constexpr double kRadPerRad = 160.0;
constexpr double kStiffnessNmPerRad = 4.5e5;
constexpr double kModeRadS = 2.0 * pi * 15.0, kDamping = 0.05;

using Record = imscal::test_support::LaggedMotorRecord;

// Link path from rest (zero speed at t = 0, as the identification's filter starts) sweeping the
// error's frequency f q̇ through ω_n (q̇ up to ~0.9 rad/s, ω_n / f = 0.59 rad/s); still for the
// last second.
double link_angle(double t, double end_s) {
  t = std::min(t, end_s - 1.0);
  return 0.3 + 0.4 * (1.0 - std::cos(2.0 * pi * 0.2 * t)) +
         0.1 * (1.0 - std::cos(2.0 * pi * 0.55 * t));
}
double torque_nm(double t) {
  return 400.0 + 300.0 * std::sin(2.0 * pi * 0.13 * t + 0.4);
}
double motor_angle(double t, double end_s) {
  return link_angle(t, end_s) + torque_nm(t) / kStiffnessNmPerRad;
}

Record make_record() {
  const std::size_t n = 15000;  // 30 s
  const double end_s = double(n) * kDt;
  std::vector<double> theta(n + 1), q(n + 1), tau(n + 1);
  // The mode's state (y, ẏ), from its steady state at rest: y = e^{jφ(0)}.
  std::complex<double> y = std::polar(1.0, kRadPerRad * motor_angle(0.0, end_s)), v = 0.0;
  const auto accel = [&](double t, std::complex<double> yy, std::complex<double> vv) {
    const std::complex<double> drive = std::polar(1.0, kRadPerRad * motor_angle(t, end_s));
    return kModeRadS * kModeRadS * (drive - yy) - 2.0 * kDamping * kModeRadS * vv;
  };
  constexpr int kSub = 50;
  const double h = kDt / kSub;
  for (std::size_t k = 0; k <= n; ++k) {
    const double t = double(k) * kDt;
    q[k] = link_angle(t, end_s);
    tau[k] = torque_nm(t);
    const double m = motor_angle(t, end_s);
    theta[k] = m + kPlainRad * std::sin(kRadPerRad * m + kPlainPhaseRad) +
               kModeRad * (std::polar(1.0, kModePhaseRad) * y).imag();
    for (int i = 0; i < kSub; ++i) {
      const double s = t + i * h;
      const auto k1y = v, k1v = accel(s, y, v);
      const auto k2y = v + 0.5 * h * k1v, k2v = accel(s + 0.5 * h, y + 0.5 * h * k1y, k2y);
      const auto k3y = v + 0.5 * h * k2v, k3v = accel(s + 0.5 * h, y + 0.5 * h * k2y, k3y);
      const auto k4y = v + h * k3v, k4v = accel(s + h, y + h * k3y, k4y);
      y += h / 6.0 * (k1y + 2.0 * k2y + 2.0 * k3y + k4y);
      v += h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
    }
  }
  return imscal::test_support::record_from_motor_angle(theta, q, tau, kAlpha);
}

ident::JointIdentificationOptions options(ident::GearModePairs pairs) {
  ident::JointIdentificationOptions o;
  o.form = ident::ArxModelForm::kInverse;
  o.preview_cycles = 1;
  o.grid = {0, 0, 1, 1, 0, 0};  // FIR, one increment tap
  o.model_torque_input = true;
  o.input_taps = 2;
  o.transmission_error_input = true;
  o.transmission_error_taps = 2;
  o.transmission_error_mode_taps = 2;
  o.transmission_error_rad_per_rad = kRadPerRad;
  o.transmission_error_compliance_rad_per_nm = 1.0 / kStiffnessNmPerRad;
  o.transmission_error_mode_pairs = pairs;
  o.transmission_error_mode_rad_s = kModeRadS;
  o.transmission_error_mode_damping = kDamping;
  o.identify_backlash = false;
  o.min_rows_per_cell = 100;
  return o;
}

ident::JointIdentification identify(const Record& r, const ident::JointIdentificationOptions& o) {
  return imscal::test_support::identify_in_one_cell(r, kDt, o);
}

// The pair (A cos ψ, A sin ψ) of input pair number `pair` (0: sin/cos after the torque) as the sums
// of its taps.
std::complex<double> pair_sums(const ident::ArxModel& m, int first_input) {
  const auto& s = m.structure();
  const auto sum = [&](int e) {
    return m.c().segment(s.extra_offset(e), s.nx[std::size_t(e)]).sum();
  };
  return {sum(first_input), sum(first_input + 1)};
}

TEST(GearModePairBeside, RecoversThePlainAndTheFilteredErrorsAmplitudesAndPhases) {
  const Record r = make_record();
  const ident::JointIdentification id = identify(r, options(ident::GearModePairs::kBeside));
  ASSERT_TRUE(id.cells.at(0).fit.has_value()) << id.cells[0].reason;
  const ident::ArxModel& m = id.cells[0].fit->model;
  ASSERT_EQ(m.structure().extra_inputs, 5);  // torque, plain sin/cos, gear-mode sin/cos
  EXPECT_EQ(id.parameters.transmission_error_mode_rad_s, kModeRadS);
  const std::complex<double> plain = pair_sums(m, 1), mode = pair_sums(m, 3);
  std::printf(
      "plain pair %.4f arcsec at %.4f rad (truth 10, 0.7); gear-mode pair %.4f arcsec at "
      "%.4f rad (truth 6, -1.1); residual RMS %.3g rad\n",
      std::abs(plain) / kArcsecRad, std::arg(plain), std::abs(mode) / kArcsecRad, std::arg(mode),
      id.parameters.cells[0].figures.residual_rms_rad);
  // Tolerance: the filter holds the error's frequency over a step (its error against the ODE
  // < 0.5 % of the amplitude, tests/ident/test_gear_mode_filter.cpp), which the fit spreads over
  // the nearly collinear pairs (equal at low speed, where H(jΩ) -> 1): 2 % of each amplitude and
  // 0.02 rad of each phase.
  EXPECT_NEAR(std::abs(plain), kPlainRad, 0.02 * kPlainRad);
  EXPECT_NEAR(std::abs(mode), kModeRad, 0.02 * kModeRad);
  EXPECT_NEAR(std::arg(plain), kPlainPhaseRad, 0.02);
  EXPECT_NEAR(std::arg(mode), kModePhaseRad, 0.02);
}

// Without the gear-mode pair (or with it instead of the plain one) the record's error is not in
// the model's span: the residual stays far above the structure with both pairs.
TEST(GearModePairBeside, EitherPairAloneLeavesAResidual) {
  const Record r = make_record();
  const auto residual = [&](ident::GearModePairs pairs) {
    return identify(r, options(pairs)).parameters.cells.at(0).figures.residual_rms_rad;
  };
  const double both = residual(ident::GearModePairs::kBeside),
               plain = residual(ident::GearModePairs::kNone),
               instead = residual(ident::GearModePairs::kInstead);
  std::printf("residual RMS: both pairs %.3g, plain only %.3g, gear-mode only %.3g rad\n", both,
              plain, instead);
  // Each missing term is ~3e-5 rad / (1 - α) of joint error where the speed sweeps the mode;
  // both pairs leave the filter's step error only. A factor 10 separates them.
  EXPECT_LT(10.0 * both, plain);
  EXPECT_LT(10.0 * both, instead);
}

}  // namespace
