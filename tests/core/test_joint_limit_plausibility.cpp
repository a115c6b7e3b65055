// Joint angles against the robot's limits (core/joint_limit_plausibility.hpp): within the limits
// nothing; beyond a limit by less than the margin a warning and a count; further out an
// InputError naming the file, the line of the worst sample, the column, value and limit.
#include "core/joint_limit_plausibility.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "core/input_error.hpp"

namespace imscal {
namespace {

const std::vector<JointLimit> kLimits = {{"A1", -185 * kRadPerDeg, 185 * kRadPerDeg},
                                         {"A2", -155 * kRadPerDeg, 35 * kRadPerDeg}};

JointAngleSource source() {
  // Samples start on line 5 (four header lines).
  return {"robot.csv", [](std::size_t k) { return k + 5; }, "robot kr16 (kr16.yaml)"};
}

TEST(JointLimitPlausibility, WithinTheLimitsNothingIsCounted) {
  const std::vector<double> a1{0.0, 3.2, -3.2}, a2{-2.7, 0.6};  // 183 deg, 34.4 deg
  const std::vector<JointAngleColumn> columns{{"q_A1_rad", 0, a1}, {"q_A2_rad", 1, a2}};
  EXPECT_EQ(check_joint_limits(columns, kLimits, source()), 0u);
}

TEST(JointLimitPlausibility, WithinTheMarginAWarningAndACount) {
  // 0.65 rad = 37.24 deg: 2.24 deg beyond A2's 35 deg; 0.62 rad = 35.52 deg: 0.52 deg beyond.
  const std::vector<double> a2{0.1, 0.65, 0.62, 0.3};
  const std::vector<JointAngleColumn> columns{{"q_A2_rad", 1, a2}};
  EXPECT_EQ(check_joint_limits(columns, kLimits, source()), 2u);
}

TEST(JointLimitPlausibility, BeyondTheMarginRefusedNamingTheWorstSample) {
  // Degrees in a radian column: A1 at 90 "rad" on the third sample (line 7), 190 deg on the first.
  const std::vector<double> a1{190 * kRadPerDeg, 0.5, 90.0, 1.0};
  const std::vector<JointAngleColumn> columns{{"q_desired_A1_rad", 0, a1}};
  try {
    check_joint_limits(columns, kLimits, source());
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), "robot.csv");
    EXPECT_EQ(e.line(), 7u);
    EXPECT_EQ(e.field(), "q_desired_A1_rad");
    EXPECT_NE(std::string(e.what()).find("upper limit of 185 deg (robot kr16 (kr16.yaml))"),
              std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("another unit"), std::string::npos) << e.what();
  }
  // Just within the margin (4.9 deg beyond the lower limit) a warning.
  const std::vector<double> a2{-159.9 * kRadPerDeg};
  const std::vector<JointAngleColumn> at_margin{{"q_A2_rad", 1, a2}};
  EXPECT_EQ(check_joint_limits(at_margin, kLimits, source()), 1u);
}

}  // namespace
}  // namespace imscal
