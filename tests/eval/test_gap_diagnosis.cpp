// Unit checks of the gap diagnosis against closed forms and known synthetic gaps: the Welch
// spectrum against Parseval and a sinusoid's frequency, motion phases of a known profile, a
// candidate's parameter against the value put in, the diagnosis of a synthetic time offset, and
// the block bootstrap on clear and on null cases.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "eval/gap_bounds.hpp"
#include "eval/gap_diagnosis.hpp"
#include "eval/gap_verdict.hpp"

namespace imscal::eval {
namespace {

// Six joints moving as sums of two sines (reversals every ~1-2 s), 20 s at 2 ms, no gap.
GapSignals synthetic(std::size_t n = 10000) {
  GapSignals s;
  s.cycle_s = 0.002;
  s.runs = {{0, n}};
  for (int j = 0; j < 6; ++j) {
    s.joint_names.push_back(std::string(1, 'A') + char('1' + j));
    s.gear_ratio.push_back(100.0);
    s.max_speed_rad_s.push_back(3.0);
  }
  s.q_desired_rad.assign(6, std::vector<double>(n));
  s.qd_desired_rad_s = s.qdd_desired_rad_s2 = s.q_internal_rad = s.gap_rad = s.torque_nm =
      s.gravity_torque_nm = s.unit_payload_nm_kg = s.q_desired_rad;
  for (std::size_t k = 0; k < n; ++k) {
    const double t = double(k) * s.cycle_s;
    s.time_s.push_back(t);
    s.payload_kg.push_back(5.0);
    for (std::size_t j = 0; j < 6; ++j) {
      const double w1 = 2.0 * M_PI * (0.3 + 0.05 * double(j)), w2 = 2.0 * M_PI * 0.71,
                   p = double(j);
      s.q_desired_rad[j][k] = 0.5 * std::sin(w1 * t + p) + 0.2 * std::sin(w2 * t + 2.0 * p);
      s.qd_desired_rad_s[j][k] =
          0.5 * w1 * std::cos(w1 * t + p) + 0.2 * w2 * std::cos(w2 * t + 2.0 * p);
      s.qdd_desired_rad_s2[j][k] =
          -0.5 * w1 * w1 * std::sin(w1 * t + p) - 0.2 * w2 * w2 * std::sin(w2 * t + 2.0 * p);
      s.q_internal_rad[j][k] = s.q_desired_rad[j][k];
      s.gravity_torque_nm[j][k] = 300.0 * std::cos(s.q_desired_rad[j][k]);
      s.torque_nm[j][k] = 100.0 * s.qdd_desired_rad_s2[j][k] + s.gravity_torque_nm[j][k];
      s.unit_payload_nm_kg[j][k] = 9.81 * std::cos(s.q_desired_rad[j][k]);
    }
  }
  return s;
}

void add_white_noise(GapSignals& s, double sigma, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n(0.0, sigma);
  for (auto& g : s.gap_rad)
    for (double& v : g) v += n(rng);
}

TEST(GapAnalysis, WelchSpectrumKeepsTheVarianceAndFindsTheSine) {
  const std::size_t n = 8192;
  // 6 bins of a 256-sample window at 2 ms (df = 1.953125 Hz): 11.71875 Hz lies on a bin.
  const double dt = 0.002, f = 6.0 / (256.0 * dt), amplitude = 3e-4;
  std::vector<double> x(n);
  for (std::size_t k = 0; k < n; ++k) x[k] = amplitude * std::sin(2.0 * M_PI * f * double(k) * dt);
  const Spectrum sp = welch_spectrum(x, {{0, n}}, dt, 256);
  double power = 0.0, peak = 0.0, f_peak = 0.0;
  const double df = sp.frequency_hz[1] - sp.frequency_hz[0];
  for (std::size_t i = 0; i < sp.density.size(); ++i) {
    power += sp.density[i] * df;
    if (sp.density[i] > peak) peak = sp.density[i], f_peak = sp.frequency_hz[i];
  }
  // Parseval: the integral of the one-sided PSD is the mean square A²/2; the Hann window's
  // power normalisation makes it exact up to the window's end effects (< 1 % here).
  EXPECT_NEAR(power, amplitude * amplitude / 2.0, 0.01 * amplitude * amplitude / 2.0);
  EXPECT_DOUBLE_EQ(f_peak, f);  // the sine lies on a bin: the peak is that bin
}

TEST(GapAnalysis, PhasesOfAKnownMotion) {
  GapSignals s = synthetic(2000);
  // Joint 0: rest 1 s, constant acceleration 0.5 s, constant speed 1 s, deceleration 0.5 s, rest.
  for (std::size_t k = 0; k < 2000; ++k) {
    const double t = double(k) * s.cycle_s;
    double v = 0.0, a = 0.0;
    if (t >= 1.0 && t < 1.5) v = 2.0 * (t - 1.0), a = 2.0;
    if (t >= 1.5 && t < 2.5) v = 1.0;
    if (t >= 2.5 && t < 3.0) v = 1.0 - 2.0 * (t - 2.5), a = -2.0;
    s.qd_desired_rad_s[0][k] = v;
    s.qdd_desired_rad_s2[0][k] = a;
  }
  const auto ph = motion_phases(s, 0);
  EXPECT_EQ(ph[250], MotionPhase::kRest);
  EXPECT_EQ(ph[625], MotionPhase::kAcceleration);
  EXPECT_EQ(ph[1000], MotionPhase::kConstantVelocity);
  EXPECT_EQ(ph[1375], MotionPhase::kDeceleration);
  EXPECT_EQ(ph[1750], MotionPhase::kRest);
  // A sine's velocity reverses: the samples at a reversal of joint 1 are marked.
  const auto ph1 = motion_phases(s, 1);
  int reversal = 0;
  for (auto p : ph1) reversal += p == MotionPhase::kReversal;
  EXPECT_GT(reversal, 0);
}

TEST(GapCandidates, BacklashParameterIsRecoveredWithinItsSigma) {
  GapSignals s = synthetic();
  const double l = 2.5e-4;  // rad: 52 arcsec
  for (std::size_t k = 0; k < s.sample_count(); ++k)
    s.gap_rad[2][k] = l * std::tanh(s.qd_desired_rad_s[2][k] / 0.005);
  add_white_noise(s, 2e-5, 3);
  const std::vector<bool> all(s.sample_count(), true);
  const auto fit = fit_candidate(EffectKind::kBacklash, s, 2, all);
  ASSERT_TRUE(fit.has_value());
  EXPECT_EQ(fit->shape, "sign(qd)");  // the data's own form wins the validation
  // White noise: sigma is the plain LS sigma, sigma_n / sqrt(n) = 2e-7; 4 sigma covers the draw.
  EXPECT_NEAR(fit->parameters[0], l, 4.0 * fit->sigma[0]);
  EXPECT_NEAR(fit->sigma[0], 2e-5 / std::sqrt(10000.0), 0.2 * 2e-7);
}

TEST(GapDiagnosis, SyntheticTimeOffsetIsNamedSizedAndShrinks) {
  GapSignals s = synthetic();
  const double dt = 0.006;  // s
  for (std::size_t k = 0; k < s.sample_count(); ++k)
    s.gap_rad[4][k] = dt * s.qd_desired_rad_s[4][k];
  add_white_noise(s, 1e-4, 5);
  const Diagnosis d = diagnose_gap(s);
  ASSERT_TRUE(d.significant_gap);
  const auto& top = d.candidates.front();
  EXPECT_EQ(top.fit.kind, EffectKind::kTimeOffset);
  EXPECT_EQ(top.fit.joint, 4u);
  EXPECT_NEAR(top.fit.parameters[0], dt, 4.0 * top.fit.sigma[0]);
  // Truth: once modelled only the white noise (1e-4 rad on every joint) is left on the held-out
  // rows: sqrt(6) * 1e-4 rad; the fitted model leaves that plus its own small error (< 3 %).
  EXPECT_NEAR(d.heldout_rms_modelled_rad, std::sqrt(6.0) * 1e-4, 0.03 * std::sqrt(6.0) * 1e-4);
}

TEST(GapDiagnosis, OffsetOnAJointWhoseTorqueKeepsItsSignIsAnAmbiguityWithBacklash) {
  GapSignals s = synthetic();
  // Joint 3's gear torque stays positive (a gravity load larger than its motion torque): a
  // backlash would hold its link on one flank, a constant offset of half the play.
  for (std::size_t k = 0; k < s.sample_count(); ++k)
    s.torque_nm[2][k] = 300.0 + 50.0 * std::sin(2.0 * M_PI * 0.4 * s.time_s[k]);
  const double offset = 1.5e-4;  // rad
  for (double& g : s.gap_rad[2]) g = offset;
  add_white_noise(s, 1e-5, 9);
  const Diagnosis d = diagnose_gap(s);
  ASSERT_TRUE(d.significant_gap);
  const std::vector<std::size_t> lead = leading_group(d);
  ASSERT_EQ(lead.size(), 2u);
  const CandidateFit& first = d.candidates[lead[0]].fit;
  const CandidateFit& second = d.candidates[lead[1]].fit;
  EXPECT_EQ(first.kind, EffectKind::kZeroOffset);  // of equal scores, the plain offset first
  EXPECT_EQ(second.kind, EffectKind::kBacklash);
  EXPECT_EQ(second.shape, kOneFlankShape);
  EXPECT_EQ(first.joint, 2u);
  EXPECT_EQ(second.joint, 2u);
  // Both carry the offset: 4 sigma of the white noise's mean over the 5000 training rows.
  EXPECT_NEAR(first.parameters[0], offset, 4.0 * 1e-5 / std::sqrt(5000.0));
  EXPECT_NEAR(std::abs(second.parameters[0]), offset, 4.0 * 1e-5 / std::sqrt(5000.0));
  EXPECT_NE(d.verdict.find("indistinguishable from it on these data"), std::string::npos)
      << d.verdict;
  ASSERT_FALSE(d.measure_next.empty());
  EXPECT_NE(d.measure_next.front().find("changes sign"), std::string::npos);
}

TEST(GapDiagnosis, PureNoiseIsNoSignificantGap) {
  GapSignals s = synthetic();
  add_white_noise(s, 1e-5, 7);
  const Diagnosis d = diagnose_gap(s);
  EXPECT_FALSE(d.significant_gap) << d.verdict;
  EXPECT_TRUE(d.combination.empty());
}

TEST(GapDiagnosis, BlockBootstrapSeparatesClearGainsFromNoise) {
  std::vector<double> clear(2000, 1.0);
  // Every resample has a positive mean: the p-value is its floor 1 / (resamples + 1).
  EXPECT_DOUBLE_EQ(block_bootstrap_p_value(clear, 100, 199, 1), 1.0 / 200.0);
  std::mt19937_64 rng(11);
  std::normal_distribution<double> n(0.0, 1.0);
  std::vector<double> null(2000);
  for (double& v : null) v = n(rng);
  // A zero-mean null gives p around 0.5; 0.05 is far in the tail for any reasonable draw.
  EXPECT_GT(block_bootstrap_p_value(null, 100, 199, 1), 0.05);
}

TEST(GapBounds, ActiveBoundGivesTheClosedFormConstrainedFit) {
  // y = -0.5 u + 2 v with u, v orthogonal (sin and cos over whole periods): the level of u is
  // the first parameter; with level >= 0 the constrained optimum is (0, 2) exactly, its residual
  // 0.5 u (RMS 0.5 / sqrt 2). Tolerances: rounding of the normal equations.
  const Eigen::Index n = 1000;
  Eigen::MatrixXd x(n, 2);
  std::vector<double> y(std::size_t(n), 0.0);
  for (Eigen::Index k = 0; k < n; ++k) {
    const double a = 2.0 * M_PI * 5.0 * double(k) / double(n);
    x(k, 0) = std::sin(a), x(k, 1) = std::cos(a);
    y[std::size_t(k)] = -0.5 * x(k, 0) + 2.0 * x(k, 1);
  }
  const std::vector<Eigen::MatrixXd> columns = {x};
  const std::vector<bool> use(std::size_t(n), true);
  LinearFit f = fit_joint_columns(columns, {y}, use);
  EXPECT_NEAR(f.parameters[0], -0.5, 1e-12);
  const LevelBound bound{0, 0, 2, x.col(0), 0.0};
  EXPECT_NEAR(bound_level(columns, bound, f.parameters, use), -0.5, 1e-12);
  EXPECT_TRUE(apply_level_bounds(columns, {y}, use, {bound}, f));
  EXPECT_NEAR(f.parameters[0], 0.0, 1e-12);
  EXPECT_NEAR(f.parameters[1], 2.0, 1e-12);
  EXPECT_NEAR(f.rms, 0.5 / std::sqrt(2.0), 1e-12);
  // A bound that holds leaves the fit alone.
  LinearFit g = fit_joint_columns(columns, {y}, use);
  EXPECT_FALSE(apply_level_bounds(columns, {y}, use, {{0, 0, 2, x.col(0), -1.0}}, g));
  EXPECT_NEAR(g.parameters[0], -0.5, 1e-12);
}

// A compliance of either sign on A3 (nominal model rigid): the physical sign is named with its
// size; the sign-flipped one, a negative compliance, is never reported with that size.
Diagnosis compliance_case(double compliance_rad_per_nm) {
  GapSignals s = synthetic(5000);  // 10 s: short for the sanitizer build
  for (std::size_t k = 0; k < s.sample_count(); ++k)
    s.gap_rad[2][k] = compliance_rad_per_nm * s.torque_nm[2][k];
  add_white_noise(s, 1e-5, 11);
  return diagnose_gap(s);
}

TEST(GapDiagnosis, ComplianceIsSizedWithinItsPhysicalBound) {
  const double c = 3e-7;  // rad/N m: ~1e-4 rad of deflection at the synthetic torques
  const Diagnosis positive = compliance_case(c);
  ASSERT_TRUE(positive.significant_gap);
  const CandidateFit& top = positive.candidates.front().fit;
  EXPECT_EQ(top.kind, EffectKind::kGearCompliance) << positive.verdict;
  EXPECT_FALSE(top.at_bound);
  // The level against the truth: white noise of 1e-5 rad on 2500 training rows, far below 1 %.
  EXPECT_NEAR(top.level, c, 0.01 * c);

  const Diagnosis flipped = compliance_case(-c);
  for (const CandidateResult& r : flipped.candidates) {
    if (r.fit.kind != EffectKind::kGearCompliance) continue;
    EXPECT_GE(r.fit.level, -1e-12 * c) << r.fit.size_text;  // rounding of the active bound
    EXPECT_EQ(r.fit.size_text.find("stiffness of -"), std::string::npos) << r.fit.size_text;
    EXPECT_EQ(r.fit.size_text.find("stiffness -"), std::string::npos) << r.fit.size_text;
    if (r.fit.joint != 2) continue;
    EXPECT_TRUE(r.fit.at_bound) << r.fit.size_text;
    EXPECT_LT(r.fit.unconstrained_level, -0.9 * c);  // the unconstrained fit: the negative truth
    EXPECT_FALSE(r.supported) << flipped.verdict;    // at its bound it explains nothing
  }
  EXPECT_EQ(flipped.verdict.find("cause: gear_compliance"), std::string::npos) << flipped.verdict;
}

// The verdict names the causes it models: the model starts from the cause ranked first, and every
// further candidate of the model is named as a cause before "Modelled with".
TEST(GapDiagnosis, VerdictModelsTheCausesItNames) {
  GapSignals s = synthetic(5000);  // 10 s: short for the sanitizer build
  for (std::size_t k = 0; k < s.sample_count(); ++k) {
    s.gap_rad[2][k] = 3e-7 * s.torque_nm[2][k];          // a compliance of A3, ~1e-4 rad
    s.gap_rad[4][k] = 0.004 * s.qd_desired_rad_s[4][k];  // a time offset of A5, ~1e-3 rad
  }
  add_white_noise(s, 1e-5, 12);
  const Diagnosis d = diagnose_gap(s);
  ASSERT_TRUE(d.significant_gap);
  ASSERT_FALSE(d.combination.empty());
  EXPECT_EQ(d.combination.front().candidate, 0u);
  const std::size_t modelled = d.verdict.find("Modelled with");
  ASSERT_NE(modelled, std::string::npos) << d.verdict;
  std::vector<EffectKind> kinds;
  for (const CombinationStep& step : d.combination) {
    const CandidateFit& f = d.candidates[step.candidate].fit;
    kinds.push_back(f.kind);
    EXPECT_LT(d.verdict.find(candidate_in_words(s, f)), modelled) << d.verdict;
    if (d.combination.size() > 1) {
      EXPECT_NE(d.verdict.find(step.label, modelled), std::string::npos) << d.verdict;
    }
  }
  // Both effects are in the model.
  EXPECT_NE(std::find(kinds.begin(), kinds.end(), EffectKind::kTimeOffset), kinds.end());
  EXPECT_NE(std::find(kinds.begin(), kinds.end(), EffectKind::kGearCompliance), kinds.end());
}

}  // namespace
}  // namespace imscal::eval
