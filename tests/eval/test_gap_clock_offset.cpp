// The clock offset common to all joints as a candidate of the gap diagnosis: one parameter, the
// offset dt of the measuring clock against the robot's, fitted from its linearised sensitivity
// q̇_d,j on every joint at once. Withheld together with a second effect (tests/eval/gap_cases.hpp:
// every joint's measurement delayed by 0.35..0.65 ms, and a backlash on A2), both are found: the
// clock offset as one candidate, not as per-joint time offsets that run the combination out of
// steps.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>

#include "eval/gap_diagnosis.hpp"
#include "tests/eval/gap_cases.hpp"

namespace imscal::eval {
namespace {

bool in_combination(const Diagnosis& d, const std::string& label) {
  return std::any_of(d.combination.begin(), d.combination.end(),
                     [&](const CombinationStep& c) { return c.label == label; });
}

void expect_both_found(const std::vector<test::WithheldEffect>& effects, std::uint64_t seed,
                       const std::string& second) {
  const test::GapWorld world;
  const auto c = world.make_case(effects, seed);
  const GapSignals s = make_gap_signals(c.real, c.sim_joint_error_rad, world.robot);
  const Diagnosis d = diagnose_gap(s);
  fmt::print("{}\n", d.verdict);
  ASSERT_TRUE(d.significant_gap);
  const auto clock = std::find_if(d.candidates.begin(), d.candidates.end(), [](const auto& r) {
    return r.fit.kind == EffectKind::kClockOffset;
  });
  ASSERT_NE(clock, d.candidates.end());
  EXPECT_TRUE(clock->supported);
  EXPECT_TRUE(in_combination(d, candidate_label(s, clock->fit))) << d.verdict;
  EXPECT_TRUE(in_combination(d, second)) << d.verdict;
  // The drawn offset lies in 0.5 ms x 0.7..1.3; the fit alone (with the second effect
  // unmodelled) within it, widened by 4 sigma.
  const double dt = clock->fit.parameters[0], sigma = clock->fit.sigma[0];
  EXPECT_GT(dt, 0.00035 - 4.0 * sigma);
  EXPECT_LT(dt, 0.00065 + 4.0 * sigma);
}

TEST(GapClockOffset, FoundWithABacklashOnA2) {
  expect_both_found({{"clock_offset", 0}, {"backlash", 1}}, 82, "A2 backlash");
}

}  // namespace
}  // namespace imscal::eval
