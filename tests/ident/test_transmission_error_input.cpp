// The transmission-error pair of the inverse form (ident/joint_identification.hpp) against a
// closed form. A joint whose motor angle θ follows the command u with a one-cycle first-order lag,
// θ(k+1) = α θ(k) + (1 - α) u(k), drives the link through an elastic gear with a periodic angle
// error: θ = q + τ / k_g + te, te = A sin(f (q + τ / k_g) + φ) (the motor sits τ / k_g ahead of
// the link under the torque τ). The record is made backwards from a smooth link path q, so it is
// the plant's exactly: u(k) = (θ(k+1) - α θ(k)) / (1 - α). The joint error e = u - q is then
//   e(k) = [q(k+1) - q(k)] / (1 - α) + (1 / k_g) [τ(k+1) - α τ(k)] / (1 - α)
//          + A cos φ [s(k+1) - α s(k)] / (1 - α) + A sin φ [c(k+1) - α c(k)] / (1 - α),
// s, c = sin, cos of f (q + τ / k_g): the inverse form with one cycle of preview, no
// autoregressive part, and two taps on the model torque and on each of the pair.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include "ident/joint_identification.hpp"
#include "tests/ident/lagged_motor_record.hpp"

namespace {
namespace ident = imscal::ident;

constexpr double kDt = 0.002;
constexpr double kAlpha = 0.9;  // the motor's lag per cycle
constexpr double kAmplitudeRad = 10.0 / 3600.0 * std::numbers::pi / 180.0;  // 10 arcsec
constexpr double kPhaseRad = 0.7;
constexpr double kRadPerRad = 160.0;          // harmonic 1 x gear ratio 160
constexpr double kStiffnessNmPerRad = 4.5e5;  // the KR 16's A2 gear

using Record = imscal::test_support::LaggedMotorRecord;

Record make_record() {
  const std::size_t n = 15000;  // 30 s
  std::vector<double> q(n + 1), tau(n + 1), theta(n + 1);
  for (std::size_t k = 0; k <= n; ++k) {
    // The path stands still over the last second: the fit holds its inputs at a run's end (the
    // robot stands there), so the record's last rows are then the plant's too.
    const double t = std::min(double(k) * kDt, double(n) * kDt - 1.0);
    q[k] = 0.3 + 0.4 * std::sin(2.0 * std::numbers::pi * 0.2 * t) +
           0.1 * std::sin(2.0 * std::numbers::pi * 0.55 * t + 1.0);
    tau[k] = 400.0 + 300.0 * std::sin(2.0 * std::numbers::pi * 0.13 * t + 0.4);  // N m
    const double motor = q[k] + tau[k] / kStiffnessNmPerRad;
    theta[k] = motor + kAmplitudeRad * std::sin(kRadPerRad * motor + kPhaseRad);
  }
  return imscal::test_support::record_from_motor_angle(theta, q, tau, kAlpha);
}

ident::JointIdentificationOptions options(bool transmission_error, bool compliance) {
  ident::JointIdentificationOptions o;
  o.form = ident::ArxModelForm::kInverse;
  o.preview_cycles = 1;
  o.grid = {0, 0, 1, 1, 0, 0};  // the closed form's structure: FIR, one increment tap
  o.model_torque_input = true;
  o.input_taps = 2;
  o.transmission_error_input = transmission_error;
  o.transmission_error_taps = 2;
  o.transmission_error_rad_per_rad = kRadPerRad;
  o.transmission_error_compliance_rad_per_nm = compliance ? 1.0 / kStiffnessNmPerRad : 0.0;
  o.identify_backlash = false;
  o.min_rows_per_cell = 100;
  return o;
}

ident::JointIdentification identify(const Record& r, const ident::JointIdentificationOptions& o) {
  return imscal::test_support::identify_in_one_cell(r, kDt, o);
}

TEST(TransmissionErrorInput, RecoversTheClosedFormCoefficients) {
  const Record r = make_record();
  const ident::JointIdentification id = identify(r, options(true, true));
  ASSERT_EQ(id.cells.size(), 1u);
  ASSERT_TRUE(id.cells[0].fit.has_value()) << id.cells[0].reason;
  const ident::ArxModel& m = id.cells[0].fit->model;
  ASSERT_EQ(m.structure().extra_inputs, 3);
  const double g = 1.0 / (1.0 - kAlpha);
  const double as = kAmplitudeRad * std::cos(kPhaseRad), ac = kAmplitudeRad * std::sin(kPhaseRad);
  const std::vector<double> expected{
      g / kStiffnessNmPerRad, -kAlpha * g / kStiffnessNmPerRad, as * g, -kAlpha * as * g, ac * g,
      -kAlpha * ac * g};
  ASSERT_EQ(m.c().size(), Eigen::Index(expected.size()));
  EXPECT_NEAR(m.b()(0), g, 1e-9 * g);
  // Exact data, a linear least-squares problem: rounding only. Relative 1e-6 of each coefficient
  // (the pair's columns are ~1e-5 of the increments' scale in the normal equations).
  for (std::size_t i = 0; i < expected.size(); ++i)
    EXPECT_NEAR(m.c()(Eigen::Index(i)), expected[i], 1e-6 * std::abs(expected[i])) << i;
  EXPECT_EQ(id.parameters.transmission_error_rad_per_rad, kRadPerRad);
  EXPECT_EQ(id.parameters.transmission_error_compliance_rad_per_nm, 1.0 / kStiffnessNmPerRad);
}

// The same record fitted without the pair, and with the pair's phase from the link angle alone
// (the gear's deflection τ / k_g left out: 300..700 N m turn the phase by 0.1..0.25 rad): both
// leave an equation error the exact structure does not (the fit's residual RMS).
TEST(TransmissionErrorInput, WithoutThePairOrTheDeflectionTheResidualStays) {
  const Record r = make_record();
  const auto residual = [&](bool te, bool compliance) {
    const ident::JointIdentification id = identify(r, options(te, compliance));
    return id.parameters.cells.at(0).figures.residual_rms_rad;
  };
  const double exact = residual(true, true), link_phase = residual(true, false),
               without = residual(false, false);
  std::printf(
      "residual RMS: exact structure %.3g rad, phase from the link angle %.3g rad, "
      "without the pair %.3g rad (A / (1 - alpha) = %.3g rad)\n",
      exact, link_phase, without, kAmplitudeRad / (1.0 - kAlpha));
  // Exact: rounding of ~1e-3 rad errors (1e-15); the others: a share of the error's 4.8e-4 rad
  // swing in the joint error. 1e-9 rad and 1e-6 rad leave decades to both sides.
  EXPECT_LT(exact, 1e-9);
  EXPECT_GT(link_phase, 1e-6);
  EXPECT_GT(without, 1e-6);
  EXPECT_GT(without, link_phase);
}

TEST(TransmissionErrorInput, APhaseRateOfZeroOrACompliancewithoutTheTorqueIsRefused) {
  const Record r = make_record();
  auto o = options(true, true);
  o.transmission_error_rad_per_rad = 0.0;
  EXPECT_THROW(identify(r, o), std::invalid_argument);
  o = options(true, true);
  const ident::CellGrid one_cell({{ident::OperatingQuantity::kSpeed, {0.0, 5.0}}});
  o.model_torque_input = false;
  EXPECT_THROW(ident::identify_joint("A2", r.q_desired, r.q_link, r.payload, r.segments, kDt,
                                     one_cell, o, {}),
               std::invalid_argument);
}

}  // namespace
