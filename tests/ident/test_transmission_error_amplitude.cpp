// The transmission error's amplitude at the frequency the data hold it
// (ident/identified_structure.hpp, transmission_error_response), against three truths:
//  * the model's own periodic steady state: an ARX with known A, B, C and dead time driven by
//    sin(ΩkT), cos(ΩkT) over whole periods, solved as a circulant linear system (every index
//    modulo the period, so no transient), in the joint-error form and in the inverse form
//    (command held at 0, the link moving only by the error, the inputs P cycles ahead); the
//    joint error's sin/cos projection is the response;
//  * Ω -> 0: the static gains' √(g_s² + g_c²) and atan2(g_c, g_s) with their 1σ;
//  * a simulated joint with a known transmission error of 10″ (tests/ident/lagged_motor_record.hpp)
//    identified in the inverse form with more taps and orders than its structure needs.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <vector>

#include "ident/identified_structure.hpp"
#include "ident/joint_identification.hpp"
#include "tests/ident/lagged_motor_record.hpp"

namespace imscal::ident {
namespace {

constexpr double kDt = 0.002;
constexpr TableInput kPair[] = {TableInput::kTransmissionErrorSin,
                                TableInput::kTransmissionErrorCos};

// A(z) = 1 - 1.2 z^-1 + 0.5 z^-2 (poles of modulus 0.71), B with three taps, dead time 2, three
// taps of each of the pair.
ArxFitResult known_model(const Eigen::VectorXd& theta) {
  ArxStructure s{2, 3, 2, 2};
  s.nx = {3, 3};
  const ArxModel model(s, theta.head(2), theta.segment(2, 3), theta.tail(6), kDt);
  // A covariance with correlations: M Mᵀ of a fixed random M, scaled to ~1e-3 of θ's scale.
  std::mt19937_64 rng(3);
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::MatrixXd m(11, 11);
  for (Eigen::Index i = 0; i < m.size(); ++i) m(i) = normal(rng);
  const Eigen::VectorXd scale = theta.cwiseAbs() * 1e-3;
  const Eigen::MatrixXd covariance = scale.asDiagonal() * (m * m.transpose()) * scale.asDiagonal();
  return {model, covariance.diagonal().cwiseSqrt(), covariance};
}

Eigen::VectorXd known_theta() {
  Eigen::VectorXd theta(11);
  theta << -1.2, 0.5, 0.3, -0.1, 0.05, 2e-5, 1e-5, -5e-6, -1e-5, 4e-6, 3e-6;
  return theta;
}

// The joint error's periodic steady state over n cycles, Ω = 2π m / (n T), projected on
// sin(ΩkT), cos(ΩkT): [Re, Im] of the response (Im(R e^{iΩkT}) = Re R sin + Im R cos).
Eigen::Vector2d steady_state_response(const ArxFitResult& fit, FitForm form, int n, int m) {
  const ArxStructure& s = fit.model.structure();
  const double omega_t = 2.0 * std::numbers::pi * m / n;
  const int p = form.inverse ? form.preview_cycles : 0;
  const auto wrap = [n](int k) { return ((k % n) + n) % n; };
  // Unknowns [y; e]: rows 0..n-1 the command (inverse form: u = y + e = 0; joint-error form: the
  // link holds y = 0, the desired increments w are 0); rows n..2n-1 the ARX equation.
  Eigen::MatrixXd system = Eigen::MatrixXd::Zero(2 * n, 2 * n);
  Eigen::VectorXd right = Eigen::VectorXd::Zero(2 * n);
  for (int k = 0; k < n; ++k) {
    system(k, k) = 1.0;
    if (form.inverse) system(k, n + k) = 1.0;
    system(n + k, n + k) += 1.0;
    for (int i = 1; i <= s.na; ++i) system(n + k, n + wrap(k - i)) += fit.model.a()(i - 1);
    if (form.inverse)  // - Σ β_j w(k - δ - j), w(k) = y(k + P) - y(k + P - 1)
      for (int j = 0; j < s.nb; ++j) {
        system(n + k, wrap(k + p - s.dead_time - j)) -= fit.model.b()(j);
        system(n + k, wrap(k + p - s.dead_time - j - 1)) += fit.model.b()(j);
      }
    for (int l = 0; l < s.nx[0]; ++l) {
      const double phase = omega_t * (k + p - s.dead_time - l);
      right(n + k) +=
          fit.model.c()(l) * std::sin(phase) + fit.model.c()(s.nx[0] + l) * std::cos(phase);
    }
  }
  const Eigen::VectorXd solution = system.fullPivLu().solve(right);
  Eigen::Vector2d projection = Eigen::Vector2d::Zero();
  for (int k = 0; k < n; ++k) {
    projection(0) += 2.0 / n * solution(n + k) * std::sin(omega_t * k);
    projection(1) += 2.0 / n * solution(n + k) * std::cos(omega_t * k);
  }
  return projection;
}

TEST(TransmissionErrorAmplitude, IsTheModelsPeriodicSteadyStateInBothForms) {
  const ArxFitResult fit = known_model(known_theta());
  constexpr int kCycles = 64;
  for (const FitForm form : {FitForm{false, 0}, FitForm{true, 5}})
    for (const int m : {1, 3, 7}) {  // Ω T = 0.098, 0.29, 0.69 rad
      const double omega_rad_s = 2.0 * std::numbers::pi * m / (kCycles * kDt);
      const Eigen::Vector2d truth = steady_state_response(fit, form, kCycles, m);
      const PairResponse r = transmission_error_response(fit, kPair, omega_rad_s, form);
      // A linear solve of 128 unknowns against a closed form: rounding only, 1e-9 of the
      // amplitude (~5e-5 rad).
      EXPECT_NEAR(r.re_im_rad(0), truth(0), 1e-9 * truth.norm()) << form.inverse << " m " << m;
      EXPECT_NEAR(r.re_im_rad(1), truth(1), 1e-9 * truth.norm()) << form.inverse << " m " << m;
    }
}

TEST(TransmissionErrorAmplitude, AtZeroFrequencyIsTheStaticGainsHypotWithTheirSigma) {
  const ArxFitResult fit = known_model(known_theta());
  const StaticGains g = static_gains(fit, kPair);
  const double gs = g.gain(0), gc = g.gain(1), amplitude = std::hypot(gs, gc);
  const Eigen::Vector2d d_amplitude(gs / amplitude, gc / amplitude);
  const double sigma = std::sqrt(d_amplitude.dot(g.covariance * d_amplitude));
  for (const FitForm form : {FitForm{false, 0}, FitForm{true, 5}}) {
    IdentifiedStructure s;
    set_transmission_error(s, transmission_error_response(fit, kPair, 0.0, form));
    // The same sums in another order: 1e-12 relative.
    EXPECT_NEAR(s.transmission_error_amplitude_rad.value, amplitude, 1e-12 * amplitude);
    EXPECT_NEAR(s.transmission_error_amplitude_rad.sigma, sigma, 1e-12 * sigma);
    EXPECT_NEAR(s.transmission_error_phase_rad.value, std::atan2(gc, gs), 1e-12);
  }
}

TEST(TransmissionErrorAmplitude, CovarianceIsTheNumericalGradientsPropagation) {
  const Eigen::VectorXd theta = known_theta();
  const ArxFitResult fit = known_model(theta);
  const FitForm form{true, 5};
  constexpr double kOmegaRadS = 120.0;
  const PairResponse r = transmission_error_response(fit, kPair, kOmegaRadS, form);
  Eigen::MatrixXd jacobian(2, theta.size());
  for (Eigen::Index j = 0; j < theta.size(); ++j) {
    const double h = 1e-6 * std::abs(theta(j));
    Eigen::VectorXd up = theta, down = theta;
    up(j) += h;
    down(j) -= h;
    jacobian.col(j) =
        (transmission_error_response(known_model(up), kPair, kOmegaRadS, form).re_im_rad -
         transmission_error_response(known_model(down), kPair, kOmegaRadS, form).re_im_rad) /
        (2.0 * h);
  }
  const Eigen::Matrix2d numerical = jacobian * fit.covariance * jacobian.transpose();
  // Central differences of relative step 1e-6: truncation ~1e-12, rounding ~1e-10 of each
  // entry; 1e-6 of the largest entry leaves margin to both.
  const double scale = numerical.cwiseAbs().maxCoeff();
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b) EXPECT_NEAR(r.covariance(a, b), numerical(a, b), 1e-6 * scale);
}

// A joint whose motor follows the command with a one-cycle lag α and whose link sits a
// transmission error te = a sin(f θ_m + φ) off the motor (θ_m the motor angle without it), as in
// tests/ident/test_transmission_error_input.cpp, with measurement noise on the link.
constexpr double kAmplitudeRad = 10.0 / 3600.0 * std::numbers::pi / 180.0;  // 10″
constexpr double kRadPerRad = 160.0;
constexpr double kStiffnessNmPerRad = 4.5e5;

test_support::LaggedMotorRecord noisy_record() {
  constexpr std::size_t n = 15000;  // 30 s
  constexpr double kAlpha = 0.9, kPhaseRad = 0.7;
  std::vector<double> q(n + 1), tau(n + 1), theta(n + 1);
  for (std::size_t k = 0; k <= n; ++k) {
    const double t = std::min(double(k) * kDt, double(n) * kDt - 1.0);
    q[k] = 0.3 + 0.4 * std::sin(2.0 * std::numbers::pi * 0.2 * t) +
           0.1 * std::sin(2.0 * std::numbers::pi * 0.55 * t + 1.0);
    tau[k] = 400.0 + 300.0 * std::sin(2.0 * std::numbers::pi * 0.13 * t + 0.4);
    const double motor = q[k] + tau[k] / kStiffnessNmPerRad;
    theta[k] = motor + kAmplitudeRad * std::sin(kRadPerRad * motor + kPhaseRad);
  }
  test_support::LaggedMotorRecord r = test_support::record_from_motor_angle(theta, q, tau, kAlpha);
  std::mt19937_64 rng(11);
  std::normal_distribution<double> noise(0.0, 0.5 / 3600.0 * std::numbers::pi / 180.0);  // 0.5″
  for (double& y : r.q_link) y += noise(rng);
  return r;
}

TEST(TransmissionErrorAmplitude, IsTheSimulatedJointsErrorInTheInverseForm) {
  JointIdentificationOptions o;
  o.form = ArxModelForm::kInverse;
  o.preview_cycles = 5;
  o.grid = {0, 0, 1, 4, 0, 4};
  o.model_torque_input = true;
  o.input_taps = 2;
  o.transmission_error_input = true;
  o.transmission_error_taps = 8;
  o.transmission_error_rad_per_rad = kRadPerRad;
  o.transmission_error_compliance_rad_per_nm = 1.0 / kStiffnessNmPerRad;
  o.identify_backlash = false;
  o.min_rows_per_cell = 100;
  const JointIdentification id = test_support::identify_in_one_cell(noisy_record(), kDt, o);
  ASSERT_TRUE(id.cells.at(0).fit.has_value()) << id.cells[0].reason;
  const std::vector<TableInput> inputs = extra_inputs_of(o);
  const IdentifiedStructure s = identified_structure(id, inputs, {true, o.preview_cycles});
  const StaticGains g = static_gains(*id.cells[0].fit, inputs);
  const double static_amplitude = std::hypot(g.gain(1), g.gain(2));
  constexpr double kArcsec = std::numbers::pi / 180.0 / 3600.0;
  std::printf(
      "transmission error: %.2f +- %.2f arcsec at %.3f rad/s (%.1f Hz), static gains' "
      "hypot %.2f arcsec, plant 10 arcsec\n",
      s.transmission_error_amplitude_rad.value / kArcsec,
      s.transmission_error_amplitude_rad.sigma / kArcsec, s.transmission_error_joint_speed_rad_s,
      s.transmission_error_frequency_hz, static_amplitude / kArcsec);
  EXPECT_NEAR(s.transmission_error_joint_speed_rad_s, id.cells[0].rms_speed_rad_s, 1e-12);
  EXPECT_NEAR(s.transmission_error_frequency_hz,
              kRadPerRad * id.cells[0].rms_speed_rad_s / (2.0 * std::numbers::pi), 1e-9);
  // The record's structure is the model's (a FIR inverse of the lagged motor), so the response is
  // the plant's error at every speed; the fit's 1σ is 0.3 % of it (the 0.5″ noise): 3 % is 10σ.
  EXPECT_NEAR(s.transmission_error_amplitude_rad.value, kAmplitudeRad, 0.03 * kAmplitudeRad);
  // Read as if the error were the link's (the joint-error form), the command offset that cancels
  // the error at 11 Hz through the lag is |e^{iΩT} - α| / (1 - α) ≈ 1.6 times it: the loop's part
  // is what makes the figure the plant's.
  const IdentifiedStructure as_link = identified_structure(id, inputs, {false, 0});
  EXPECT_GT(as_link.transmission_error_amplitude_rad.value, 1.3 * kAmplitudeRad);
}

}  // namespace
}  // namespace imscal::ident
