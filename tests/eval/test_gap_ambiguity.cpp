// Ambiguity groups (eval/gap_ambiguity.hpp) on hand-made candidate fits with known modelled gaps:
// the same constant as a zero offset and as a backlash held on one flank is one group; a drift
// that predicts nearly the same with more parameters, and a fit that differs by half of what it
// leaves, are not in it.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "eval/gap_ambiguity.hpp"

namespace imscal::eval {
namespace {

CandidateFit fit_of(EffectKind kind, std::size_t parameters, std::vector<double> modelled) {
  CandidateFit f;
  f.kind = kind;
  f.joint = 2;
  f.parameter_names.assign(parameters, "p");
  f.prediction.assign(6, {});
  f.prediction[2] = std::move(modelled);
  return f;
}

TEST(GapAmbiguity, SameModelledGapIsOneGroupOthersAreNot) {
  const std::size_t n = 2000;
  GapSignals s;
  s.cycle_s = 0.002;
  s.runs = {{0, n}};
  for (int j = 0; j < 6; ++j) s.joint_names.push_back(std::string(1, 'A') + char('1' + j));
  s.gap_rad.assign(6, std::vector<double>(n, 0.0));
  std::mt19937_64 rng(5);
  std::normal_distribution<double> white(0.0, 1e-5);
  const double offset = 2e-4;
  for (std::size_t k = 0; k < n; ++k) {
    s.time_s.push_back(double(k) * s.cycle_s);
    s.gap_rad[2][k] = offset + white(rng);
  }
  std::vector<std::size_t> heldout;
  for (std::size_t k = 0; k < n; k += 2) heldout.push_back(k);
  // The residual after the constant is the noise (1e-5 rad RMS): the drift differs from the
  // constant by 1e-7 rad RMS (1 % of it), the sine by 5e-6 rad RMS (half of it).
  std::vector<double> constant(n, offset), drift(n), sine(n);
  for (std::size_t k = 0; k < n; ++k) {
    const double x = double(k) / double(n) - 0.5;
    drift[k] = offset + std::sqrt(12.0) * 1e-7 * x;
    sine[k] = offset + 5e-6 * std::sqrt(2.0) * std::sin(0.05 * double(k));
  }
  const CandidateFit zero = fit_of(EffectKind::kZeroOffset, 1, constant);
  CandidateFit flank = fit_of(EffectKind::kBacklash, 1, constant);
  flank.shape = kOneFlankShape;
  const CandidateFit longer = fit_of(EffectKind::kThermalDrift, 3, drift);
  const CandidateFit other = fit_of(EffectKind::kGearCompliance, 1, sine);
  const std::vector<const CandidateFit*> ranked = {&zero, &flank, &longer, &other};
  const auto groups = ambiguity_groups(s, ranked, {true, true, true, true}, heldout);
  ASSERT_EQ(groups.size(), 1u);
  EXPECT_EQ(groups[0].members, (std::vector<std::size_t>{0, 1}));
  EXPECT_EQ(groups[0].difference_rms_rad, 0.0);
  // What they leave is the noise of joint 3, as an RMS over all six joints: 1e-5 / sqrt(6) rad;
  // 10 % covers the scatter of 1000 rows' RMS (~2 %).
  EXPECT_NEAR(groups[0].residual_rms_rad, 1e-5 / std::sqrt(6.0), 0.1e-5 / std::sqrt(6.0));
  EXPECT_NE(groups[0].separate_by.find("A3 changes sign"), std::string::npos);
  // Compared on another joint only (where none acts and the gap is zero) nothing is grouped: no
  // residual to be indistinguishable within.
  EXPECT_TRUE(ambiguity_groups(s, ranked, {true, true, true, true}, heldout, 0).empty());
  // Not eligible (e.g. explaining nothing): not grouped.
  EXPECT_TRUE(ambiguity_groups(s, ranked, {true, false, true, true}, heldout).empty());
}

}  // namespace
}  // namespace imscal::eval
