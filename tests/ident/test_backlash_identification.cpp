// Backlash width l (paper, equation 3) recovered from direction reversals on simulated joints:
// a known ARX joint followed by a play element of known half width l
// (tests/ident/joint_simulation.hpp).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <utility>
#include <vector>

#include "ident/backlash_identification.hpp"
#include "tests/ident/joint_simulation.hpp"

namespace {
using imscal::ident::BacklashOptions;
using imscal::ident::identify_backlash;
using imscal::test_support::simulate_joint;
using imscal::test_support::SimulatedJoint;

constexpr double kDt = 0.002;
constexpr std::size_t kSamples = 60000;  // 120 s: ~80 direction reversals

BacklashOptions options() {
  BacklashOptions o;
  o.settle_s = 0.08;  // crossing a 2 mrad play at ~2 rad/s² takes ~45 ms, plus margin
  o.window_s = 0.15;
  return o;
}

struct Case {
  double l_rad;
  double pole_modulus;
  int dead_time;
};

class BacklashWidth : public ::testing::TestWithParam<Case> {};

TEST_P(BacklashWidth, RecoveredWithinTenPercent) {
  const Case c = GetParam();
  SimulatedJoint joint;
  joint.backlash_l_rad = c.l_rad;
  joint.pole_modulus = c.pole_modulus;
  joint.dead_time = c.dead_time;
  joint.measurement_noise_rad = 2e-5;  // ~4 arcsec, an IMS-chain level of noise
  const auto rec = simulate_joint(joint, kSamples, kDt, 7);
  const std::vector<std::pair<std::size_t, std::size_t>> segments{{0, kSamples}};
  const auto est = identify_backlash(rec.q_desired, rec.q_measured, segments, kDt, options());
  ASSERT_TRUE(est.identified) << est.reason;
  std::printf("backlash l: true %.4g rad, estimated %.4g rad (1 sigma %.2g, %d reversals)\n",
              c.l_rad, est.l_rad, est.l_sigma_rad, est.reversals_used);
  EXPECT_GE(est.reversals_used, 20);
  // The brief's goal: within 10 % of the true width.
  EXPECT_NEAR(est.l_rad, c.l_rad, 0.10 * c.l_rad)
      << "sigma " << est.l_sigma_rad << " reversals " << est.reversals_used;
  // The 1σ is honest: the error is within 4σ (4: a generous bound for a σ estimated from
  // ~40 reversals whose errors are not exactly Gaussian), and σ is not absurdly large.
  EXPECT_LE(std::abs(est.l_rad - c.l_rad), 4.0 * est.l_sigma_rad + 1e-6);
  EXPECT_LT(est.l_sigma_rad, 0.05 * c.l_rad);
}

INSTANTIATE_TEST_SUITE_P(Joints, BacklashWidth,
                         ::testing::Values(Case{0.5e-3, 0.92, 2}, Case{1.0e-3, 0.9, 0},
                                           Case{2.0e-3, 0.95, 4}));

TEST(Backlash, PlayFreeJointGivesNearZero) {
  SimulatedJoint joint;
  joint.measurement_noise_rad = 2e-5;
  const auto rec = simulate_joint(joint, kSamples, kDt, 11);
  const std::vector<std::pair<std::size_t, std::size_t>> segments{{0, kSamples}};
  const auto est = identify_backlash(rec.q_desired, rec.q_measured, segments, kDt, options());
  ASSERT_TRUE(est.identified) << est.reason;
  // No play: the estimate is only the residual of the local following-error model; it must be
  // far below the smallest play of interest (0.5 mrad above), 5 % of it.
  EXPECT_LT(std::abs(est.l_rad), 0.025e-3);
}

TEST(Backlash, LagOfTheJointFound) {
  // A pure delay of 30 samples (no dynamics): the velocity correlation must peak there.
  SimulatedJoint joint;
  const auto rec = simulate_joint(joint, 20000, kDt, 3);
  std::vector<double> delayed(rec.q_desired.size());
  for (std::size_t k = 0; k < delayed.size(); ++k) delayed[k] = rec.q_desired[k >= 30 ? k - 30 : 0];
  const std::vector<std::pair<std::size_t, std::size_t>> segments{{0, delayed.size()}};
  EXPECT_EQ(imscal::ident::joint_lag_samples(rec.q_desired, delayed, segments, 100), 30u);
}

TEST(Backlash, TooFewReversalsReported) {
  SimulatedJoint joint;
  joint.backlash_l_rad = 1e-3;
  const auto rec = simulate_joint(joint, 1000, kDt, 5);  // 2 s: a few reversals
  const std::vector<std::pair<std::size_t, std::size_t>> segments{{0, 1000}};
  auto o = options();
  o.min_reversals = 10;
  const auto est = identify_backlash(rec.q_desired, rec.q_measured, segments, kDt, o);
  EXPECT_LT(est.reversals_used, 10);
  EXPECT_FALSE(est.identified);
  EXPECT_EQ(est.l_rad, 0.0);
  EXPECT_NE(est.reason.find("usable direction reversals"), std::string::npos) << est.reason;
}

// The plausibility bound: per-reversal estimates beyond max_l_rad are refused and counted, and a
// joint with none left gets no backlash with the reason, instead of an absurd l reaching the
// table (7e3 rad was once "identified" on A5/A6 of the simulated KR 16). A 2 mrad play
// with the bound set to 1 mrad: every estimate (~2 mrad) is beyond it.
TEST(Backlash, ImplausibleWidthRefusedWithReason) {
  SimulatedJoint joint;
  joint.backlash_l_rad = 2e-3;
  const auto rec = simulate_joint(joint, kSamples, kDt, 11);
  const std::vector<std::pair<std::size_t, std::size_t>> segments{{0, kSamples}};
  BacklashOptions o = options();
  o.max_l_rad = 1e-3;
  const auto est = identify_backlash(rec.q_desired, rec.q_measured, segments, kDt, o);
  EXPECT_FALSE(est.identified);
  EXPECT_EQ(est.l_rad, 0.0);
  EXPECT_GE(est.reversals_implausible, 20);
  EXPECT_NE(est.reason.find("|l_r| >"), std::string::npos) << est.reason;
  // With the default bound (20 mrad) the same data give the play within 10 % (as above): the
  // refusal is the bound's doing, not a failed fit.
  const auto normal = identify_backlash(rec.q_desired, rec.q_measured, segments, kDt, options());
  ASSERT_TRUE(normal.identified) << normal.reason;
  EXPECT_EQ(normal.reversals_implausible, 0);
  EXPECT_NEAR(normal.l_rad, 2e-3, 0.2e-3);
}

// A reversal whose direction column is (nearly) a combination of [1, q̇_d, q̈_d] in its windows
// does not determine l: skipped and counted, never averaged in. Here every reversal's
// independence is below a threshold set above 1 (impossible to meet).
TEST(Backlash, IllConditionedReversalsSkipped) {
  SimulatedJoint joint;
  joint.backlash_l_rad = 2e-3;
  const auto rec = simulate_joint(joint, kSamples, kDt, 12);
  const std::vector<std::pair<std::size_t, std::size_t>> segments{{0, kSamples}};
  BacklashOptions o = options();
  o.min_direction_independence = 1.01;
  const auto est = identify_backlash(rec.q_desired, rec.q_measured, segments, kDt, o);
  EXPECT_FALSE(est.identified);
  EXPECT_EQ(est.reversals_used, 0);
  EXPECT_GT(est.reversals_ill_conditioned, 0);
  EXPECT_NE(est.reason.find("not determining l"), std::string::npos) << est.reason;
}

}  // namespace
