// The drive structure read from identified models (ident/identified_structure.hpp), against a
// synthetic error-form system whose coefficients are known: the static gains are the closed form
// C_e(1) / A(1), the transmission-error pair's response at a frequency is the closed form
// (C_s + i C_c)(e^{-iΩT}) / A(e^{-iΩT}), and their 1σ (delta method on the least-squares
// covariance) covers the truth as often as a normal 1σ should over repeated noise.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <numbers>
#include <random>
#include <vector>

#include "ident/arx_fit.hpp"
#include "ident/identified_structure.hpp"
#include "ident/joint_identification.hpp"

namespace imscal::ident {
namespace {

constexpr TableInput kInputs[] = {TableInput::kModelTorque, TableInput::kDirection,
                                  TableInput::kTransmissionErrorSin,
                                  TableInput::kTransmissionErrorCos};

// e(k) = 0.6 e(k-1) + 0.02 w(k) + 0.01 w(k-1) + Σ c x + noise: A(1) = 0.4, so the static gains
// are compliance 4e-6 / 0.4 = 1e-5 rad/(N m), direction 2e-5 / 0.4 = 5e-5 rad, transmission
// error sin 4e-5 / 0.4 = 1e-4 and cos -2e-5 / 0.4 = -5e-5 rad.
constexpr double kA1 = -0.6;
const std::vector<double> kTorqueTaps{1e-6, 2e-6, 1e-6}, kDirectionTaps{2e-5}, kSinTaps{3e-5, 1e-5},
    kCosTaps{-1e-5, -1e-5};
constexpr double kCompliance = 1e-5, kDirectionOffset = 5e-5;
constexpr double kSinGain = 1e-4, kCosGain = -5e-5;

ArxStructure synthetic_structure() {
  ArxStructure s{1, 2, 0, 4};
  s.nx = {3, 1, 2, 2, 0};
  return s;
}

struct SyntheticRecord {
  std::vector<double> w, e, torque, direction, te_sin, te_cos;
  IoSegment segment() const {
    IoSegment s{w, e, {}, 4};
    s.extra = {torque, direction, te_sin, te_cos, {}};
    return s;
  }
};

double lagged_sum(const std::vector<double>& taps, const std::vector<double>& x, std::size_t k) {
  double sum = 0.0;
  for (std::size_t l = 0; l < taps.size() && l <= k; ++l) sum += taps[l] * x[k - l];
  return sum;
}

// 12 s at 2 ms of a joint swinging through two sines, with a noisy torque and equation noise of
// 1e-6 rad (the noise draws differ by seed, the regressors do not).
SyntheticRecord synthetic_record(unsigned seed) {
  constexpr std::size_t kSamples = 6000;
  constexpr double dt = 0.002, two_pi = 2.0 * std::numbers::pi;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  SyntheticRecord r;
  double q_previous = 0.0;
  for (std::size_t k = 0; k < kSamples; ++k) {
    const double t = double(k) * dt;
    const double q = 0.5 * std::sin(two_pi * 0.3 * t) + 0.2 * std::sin(two_pi * 0.77 * t + 1.0);
    const double speed = 0.5 * two_pi * 0.3 * std::cos(two_pi * 0.3 * t) +
                         0.2 * two_pi * 0.77 * std::cos(two_pi * 0.77 * t + 1.0);
    r.w.push_back(k == 0 ? 0.0 : q - q_previous);
    q_previous = q;
    r.torque.push_back(200.0 * std::sin(two_pi * 0.4 * t) + 50.0 * std::cos(two_pi * 1.3 * t) +
                       20.0 * normal(rng));
    r.direction.push_back(std::tanh(speed / 0.01));
    r.te_sin.push_back(std::sin(40.0 * q));
    r.te_cos.push_back(std::cos(40.0 * q));
    double e =
        (k > 0 ? -kA1 * r.e[k - 1] : 0.0) + 0.02 * r.w[k] + (k > 0 ? 0.01 * r.w[k - 1] : 0.0);
    e += lagged_sum(kTorqueTaps, r.torque, k) + lagged_sum(kDirectionTaps, r.direction, k) +
         lagged_sum(kSinTaps, r.te_sin, k) + lagged_sum(kCosTaps, r.te_cos, k);
    r.e.push_back(e + 1e-6 * normal(rng));
  }
  return r;
}

// The transmission error's frequency the structure is read at [rad/s]: the record's sin(40 q) at
// about its rms speed of 1 rad/s.
constexpr double kErrorFrequencyRadS = 40.0;

// The true pair's response at Ω, by hand: (C_s + i C_c)(u) / (1 + a_1 u), u = e^{-iΩT}.
std::complex<double> true_pair_response(double frequency_rad_s) {
  const std::complex<double> u = std::polar(1.0, -frequency_rad_s * 0.002);
  const std::complex<double> c_s = kSinTaps[0] + kSinTaps[1] * u;
  const std::complex<double> c_c = kCosTaps[0] + kCosTaps[1] * u;
  return (c_s + std::complex<double>(0.0, 1.0) * c_c) / (1.0 + kA1 * u);
}

ArxFitResult fit_of_record(unsigned seed) {
  const SyntheticRecord record = synthetic_record(seed);
  const IoSegment segment = record.segment();
  return fit_arx({&segment, 1}, synthetic_structure());
}

IdentifiedStructure structure_of_record(unsigned seed) {
  const ArxFitResult fit = fit_of_record(seed);
  IdentifiedStructure s = structure_of_gains(static_gains(fit, kInputs), kInputs);
  set_transmission_error(s, transmission_error_response(fit, kInputs, kErrorFrequencyRadS));
  return s;
}

TEST(IdentifiedStructure, GainsAndPairResponseAreTheClosedFormOfTheCoefficients) {
  const ArxFitResult fit = fit_of_record(1);
  const StaticGains g = static_gains(fit, kInputs);
  EXPECT_NEAR(g.gain(2), kSinGain, 5 * std::sqrt(g.covariance(2, 2)));
  EXPECT_NEAR(g.gain(3), kCosGain, 5 * std::sqrt(g.covariance(3, 3)));
  const IdentifiedStructure s = structure_of_record(1);
  const std::complex<double> truth = true_pair_response(kErrorFrequencyRadS);
  // Tolerance 5σ of each estimate: the equation noise is the only error.
  EXPECT_NEAR(s.compliance_rad_per_nm.value, kCompliance, 5 * s.compliance_rad_per_nm.sigma);
  EXPECT_NEAR(s.stiffness_nm_per_rad.value, 1.0 / kCompliance, 5 * s.stiffness_nm_per_rad.sigma);
  EXPECT_NEAR(s.direction_offset_rad.value, kDirectionOffset, 5 * s.direction_offset_rad.sigma);
  EXPECT_NEAR(s.transmission_error_amplitude_rad.value, std::abs(truth),
              5 * s.transmission_error_amplitude_rad.sigma);
  EXPECT_NEAR(s.transmission_error_phase_rad.value, std::arg(truth),
              5 * s.transmission_error_phase_rad.sigma);
  // The σ are small against the values (a synthetic record rich in every input): under 2 %.
  EXPECT_LT(s.compliance_rad_per_nm.sigma, 0.02 * kCompliance);
  EXPECT_LT(s.direction_offset_rad.sigma, 0.02 * kDirectionOffset);
}

TEST(IdentifiedStructure, OneSigmaCoversTheTruthAsANormalOneShould) {
  // Over 400 noise draws a correct 2σ interval holds the truth in 95.45 % of them; the binomial
  // standard deviation is 1.04 %, so [92 %, 98.5 %] fails a correct σ with < 0.5 % probability
  // and a σ off by a factor 1.3 (coverage 87.5 % or 99.6 %) almost always.
  constexpr int kDraws = 400;
  std::vector<int> covered(5, 0);
  const auto within_two_sigma = [](const StructureEstimate& e, double truth) {
    return std::abs(e.value - truth) <= 2.0 * e.sigma;
  };
  for (int seed = 0; seed < kDraws; ++seed) {
    const IdentifiedStructure s = structure_of_record(unsigned(100 + seed));
    covered[0] += within_two_sigma(s.compliance_rad_per_nm, kCompliance);
    covered[1] += within_two_sigma(s.stiffness_nm_per_rad, 1.0 / kCompliance);
    covered[2] += within_two_sigma(s.direction_offset_rad, kDirectionOffset);
    const std::complex<double> truth = true_pair_response(kErrorFrequencyRadS);
    covered[3] += within_two_sigma(s.transmission_error_amplitude_rad, std::abs(truth));
    covered[4] += within_two_sigma(s.transmission_error_phase_rad, std::arg(truth));
  }
  for (std::size_t q = 0; q < covered.size(); ++q) {
    const double share = double(covered[q]) / kDraws;
    EXPECT_GE(share, 0.92) << "quantity " << q;
    EXPECT_LE(share, 0.985) << "quantity " << q;
  }
}

CellIdentification identified_cell(int cell, unsigned seed) {
  const SyntheticRecord record = synthetic_record(seed);
  const IoSegment segment = record.segment();
  CellIdentification c;
  c.cell = cell;
  c.fit = fit_arx({&segment, 1}, synthetic_structure());
  return c;
}

TEST(IdentifiedStructure, CellsCombineByInverseVariance) {
  JointIdentification joint;
  joint.cells = {identified_cell(0, 7), identified_cell(1, 8), CellIdentification{}};
  joint.cells[2].status = CellStatus::kFilled;  // no fit of its own: not counted
  const IdentifiedStructure s = identified_structure(joint, kInputs);
  EXPECT_EQ(s.cells, 2u);
  // Closed form of the weighted mean of two estimates and its σ = (1/σ1² + 1/σ2²)^-1/2.
  const StaticGains g0 = static_gains(*joint.cells[0].fit, kInputs);
  const StaticGains g1 = static_gains(*joint.cells[1].fit, kInputs);
  const double w0 = 1.0 / g0.covariance(0, 0), w1 = 1.0 / g1.covariance(0, 0);
  // Tolerance 1e-12 relative: the same arithmetic in another order.
  EXPECT_NEAR(s.compliance_rad_per_nm.value, (w0 * g0.gain(0) + w1 * g1.gain(0)) / (w0 + w1),
              1e-12 * kCompliance);
  EXPECT_NEAR(s.compliance_rad_per_nm.sigma, 1.0 / std::sqrt(w0 + w1), 1e-12 * kCompliance);
}

TEST(IdentifiedStructure, TransmissionErrorCombinesCellsEachAtItsSpeed) {
  JointIdentification joint;
  joint.parameters.transmission_error_rad_per_rad = 40.0;
  joint.cells = {identified_cell(0, 7), identified_cell(1, 8)};
  joint.cells[0].rms_speed_rad_s = 0.5;
  joint.cells[1].rms_speed_rad_s = 1.5;
  const IdentifiedStructure s = identified_structure(joint, kInputs);
  // Each cell's [Re, Im] at its own Ω = 40 v, weighted by its inverse variances; the speed by
  // the inverse of each cell's total variance.
  const PairResponse r0 = transmission_error_response(*joint.cells[0].fit, kInputs, 20.0);
  const PairResponse r1 = transmission_error_response(*joint.cells[1].fit, kInputs, 60.0);
  Eigen::Vector2d mean;
  for (int c = 0; c < 2; ++c) {
    const double w0 = 1.0 / r0.covariance(c, c), w1 = 1.0 / r1.covariance(c, c);
    mean(c) = (w0 * r0.re_im_rad(c) + w1 * r1.re_im_rad(c)) / (w0 + w1);
  }
  const double v0 = 1.0 / r0.covariance.trace(), v1 = 1.0 / r1.covariance.trace();
  const double speed = (0.5 * v0 + 1.5 * v1) / (v0 + v1);
  // The same arithmetic in another order: 1e-12 relative.
  EXPECT_NEAR(s.transmission_error_amplitude_rad.value, mean.norm(), 1e-12 * mean.norm());
  EXPECT_NEAR(s.transmission_error_phase_rad.value, std::atan2(mean(1), mean(0)), 1e-12);
  EXPECT_NEAR(s.transmission_error_joint_speed_rad_s, speed, 1e-12);
  EXPECT_NEAR(s.transmission_error_frequency_hz, 40.0 * speed / (2.0 * std::numbers::pi), 1e-12);
}

TEST(IdentifiedStructure, ARigidDriveHasNoStiffness) {
  // A compliance of 0.5σ: the data cannot tell it from a rigid drive, so 1 / c would be noise.
  StaticGains g{Eigen::Vector2d(0.5e-8, 5e-5), Eigen::Vector2d(1e-16, 1e-12).asDiagonal()};
  const IdentifiedStructure s = structure_of_gains(g, std::span(kInputs).first(2));
  EXPECT_DOUBLE_EQ(s.compliance_rad_per_nm.value, 0.5e-8);
  EXPECT_FALSE(s.stiffness_nm_per_rad.identified());
  EXPECT_DOUBLE_EQ(s.direction_offset_rad.value, 5e-5);
}

TEST(IdentifiedStructure, AJointWithoutTheseInputsHasNoStructure) {
  JointIdentification joint;
  joint.cells = {identified_cell(0, 7)};
  const IdentifiedStructure none = identified_structure(joint, {});
  EXPECT_EQ(none.cells, 0u);
  EXPECT_FALSE(none.compliance_rad_per_nm.identified());
  EXPECT_THROW(static_gains(*joint.cells[0].fit, std::span(kInputs).first(2)),
               std::invalid_argument);
}

}  // namespace
}  // namespace imscal::ident
