// Cartesian segments within the joints' acceleration and jerk limits (sim/cartesian_timing.hpp):
// the pieces against closed forms (the limit meter, the interpolated joint path, the timing
// search on judges whose answer is known), then the planner on the default robot: a circle
// that turns only A1 (q1 = s / r: the slowed timing known in closed form), a small circle that
// binds on the wrist and elbow joints (same geometry and orientation law, within the limits), and
// a segment that does not bind (bit for bit the programmed timing).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <string>

#include "core/config_node.hpp"
#include "core/units.hpp"
#include "robot/forward_kinematics.hpp"
#include "robot/robot_description.hpp"
#include "sim/cartesian_timing.hpp"
#include "sim/motion_planner.hpp"
#include "sim/motion_profile.hpp"
#include "sim/motion_program.hpp"
#include "tests/sim/joint_limit_use.hpp"
#include "tests/sim/planned_path_helpers.hpp"

namespace imscal::sim {
namespace {

using calib::JointVector;
using test::fk;
using test::program;
using test::range;
using test::robot;
using test::segment;

// The planned arc-length profile of a Cartesian segment, recomputed from its recorded limits.
MotionProfile planned_profile(const PathSegment& seg, double length) {
  return MotionProfile::plan(ProfileKind::kJerkLimited, length, seg.timing->planned)
      .stretched_to(seg.end_s - seg.begin_s);
}

TEST(JointLimitMeter, RatiosOfAccelerationAndOfItsChangePerCycle) {
  JointLimits limits;
  limits.acceleration_rad_s2 << 1, 2, 3, 4, 5, 6;
  limits.jerk_rad_s3 = JointVector::Constant(100.0);
  const JointVector before = JointVector::Zero();
  JointLimitMeter meter(limits, 0.01, before);
  JointVector a = JointVector::Zero();
  a(2) = -2.7;  // 0.9 of A3's limit; jerk 270 rad/s^3 over 0.01 s: 2.7 of the limit
  meter.add(a);
  a(2) = -2.6;
  a(4) = 4.8;  // 0.96 of A5's; jerk (4.8 - 0) / 0.01 = 480: 4.8
  meter.add(a);
  // Exact up to one rounding of each quotient.
  EXPECT_NEAR(meter.use().acceleration_ratio, 0.96, 1e-15);
  EXPECT_EQ(meter.use().acceleration_joint, 4);
  EXPECT_NEAR(meter.use().jerk_ratio, 4.8, 1e-13);
  EXPECT_EQ(meter.use().jerk_joint, 4);
  EXPECT_TRUE(meter.use().jerk_binds());
  EXPECT_EQ(meter.use().joint(), 4);
  // No jerk limits: jerk not counted.
  limits.jerk_rad_s3.reset();
  JointLimitMeter no_jerk(limits, 0.01, before);
  no_jerk.add(a);
  EXPECT_EQ(no_jerk.use().jerk_ratio, 0.0);
  EXPECT_EQ(no_jerk.use().jerk_joint, -1);
}

TEST(JointPathDerivatives, InterpolatesLinearlyAndCombinesWithThePathState) {
  // q'(s) = c + d s and q''(s) = e s are linear: interpolation is exact (rounding ~1e-16).
  const JointVector c = JointVector::LinSpaced(1, 6), d = JointVector::Constant(0.5),
                    e = JointVector::LinSpaced(-3, 2);
  JointPathDerivatives table;
  for (double s : {0.0, 0.1, 0.25, 0.25, 0.7, 1.0}) table.add(s, c + d * s, e * s);  // dup ignored
  std::size_t cursor = 0;
  for (double s : {0.0, 0.05, 0.25, 0.3, 0.99, 1.0, 0.2}) {  // last: the cursor walks back
    const ProfileState state{s, 0.4, -1.5};
    const JointVector expected = e * s * 0.16 + (c + d * s) * -1.5;
    EXPECT_LT((table.acceleration(state, cursor) - expected).norm(), 1e-14) << s;
  }
  EXPECT_THROW(table.add(0.5, c, e), std::invalid_argument);  // s decreasing
}

// A judge on a path of 1 m whose joint limits bind in a known way.
TimingJudge judge_of(const std::function<bool(const ProfileLimits&)>& within) {
  return {[](const ProfileLimits& l) {
            return MotionProfile::plan(ProfileKind::kJerkLimited, 1.0, l).duration();
          },
          within};
}

TEST(ChooseTiming, RampLimitKeepsTheSpeedAndStretchesTheRamps) {
  // Only the acceleration part binds: path acceleration <= 1.2 and jerk <= 9 (as a joint that
  // follows the path linearly, q = s / r). Closed form: k = 1, m = max(A / 1.2, sqrt(J / 9)) =
  // max(2.5, 1.49) = 2.5, to the search's 1e-4.
  const ProfileLimits programmed{0.5, 3.0, 20.0};
  JointLimitUse use;
  use.acceleration_ratio = 2.5;
  use.jerk_ratio = 20.0 / 9.0;
  const TimingChoice c = choose_timing(programmed, use, judge_of([](const ProfileLimits& l) {
                                         return l.acceleration <= 1.2 && l.jerk <= 9.0;
                                       }));
  EXPECT_EQ(c.speed_factor, 1.0);
  EXPECT_EQ(c.limits.velocity, 0.5);
  EXPECT_NEAR(c.ramp_factor, 2.5, 2.5 * 1e-4);
  EXPECT_LE(c.limits.acceleration, 1.2);
  EXPECT_NEAR(c.limits.acceleration, 1.2, 1.2 * 1e-4);
  EXPECT_NEAR(c.limits.jerk, 20.0 / (2.5 * 2.5), 20.0 / (2.5 * 2.5) * 3e-4);
}

TEST(ChooseTiming, VelocityLimitSlowsUniformly) {
  // Only the velocity part binds (a joint whose acceleration is q'' v^2, 4x its limit at the
  // programmed speed): nothing below the uniform k_u = sqrt(4) = 2 fits, k_u itself does.
  const ProfileLimits programmed{0.5, 3.0, 20.0};
  JointLimitUse use;
  use.acceleration_ratio = 4.0;
  const TimingChoice c = choose_timing(
      programmed, use, judge_of([](const ProfileLimits& l) { return l.velocity <= 0.25; }));
  EXPECT_EQ(c.speed_factor, 2.0);
  EXPECT_EQ(c.ramp_factor, 1.0);
  EXPECT_EQ(c.limits.velocity, 0.25);
  EXPECT_EQ(c.limits.acceleration, 0.75);
  EXPECT_EQ(c.limits.jerk, 2.5);
}

// A circle about axis 1 with the flange turning with it (slerp to Rz(150 deg) R0) moves A1 alone:
// q1 = q1(0) - s / r (axis 1 points down), so q1_ddot = -s_ddot / r: the acceleration part alone,
// A1's limit a1 binds when the path acceleration exceeds r a1. Closed form of the planned timing:
// the programmed velocity, the path acceleration r a1 (plateau of the profile stretched to whole
// cycles; to the search's 1e-4), the other joints still.
TEST(CartesianTiming, CircleAboutAxisOneRampsToTheAxisOneLimit) {
  const double r = 1.0, a1 = 200 * kRadPerDeg, j1 = 2000 * kRadPerDeg;
  // Path acceleration 1.5 r a1; jerk 1.5 r j1 (ramp stretch 1.5 leaves it at 2/3 of A1's jerk);
  // velocity 0.8 m/s (0.8 rad/s on A1, max 2.7) reaches the plateau (v j' >= a'^2).
  const double A = 1.5 * r * a1, J = 1.5 * r * j1, V = 0.8;
  const std::string segments = fmt::format(
      "  - ptp: {{pose: {{xyz_mm: [1000, 0, 800], rpy_deg: [180, 0, 0]}}, label: start}}\n"
      "  - circ: {{via_mm: [{:.17g}, {:.17g}, 800], to: {{xyz_mm: [{:.17g}, {:.17g}, 800], "
      "rpy_deg: [180, 0, 150]}}, orientation: slerp, velocity_m_s: {}, acceleration_m_s2: "
      "{:.17g}, jerk_m_s3: {:.17g}, label: arc}}\n",
      1e3 * std::cos(75 * kRadPerDeg), 1e3 * std::sin(75 * kRadPerDeg),
      1e3 * std::cos(150 * kRadPerDeg), 1e3 * std::sin(150 * kRadPerDeg), V, A, J);
  const MotionProgram p = program(segments);
  const DesiredJointPath path = plan_motion(robot(), p);
  const PathSegment& arc = segment(path, "arc");
  ASSERT_TRUE(arc.timing.has_value());
  const CartesianTiming& timing = *arc.timing;
  EXPECT_TRUE(timing.slowed);
  // Before: A1 at 1.5x its acceleration limit (the plateau), up to the whole-cycle stretch.
  EXPECT_NEAR(timing.programmed_use.acceleration_ratio, 1.5, 1.5 * 2e-3);
  EXPECT_EQ(timing.programmed_use.acceleration_joint, 0);
  EXPECT_EQ(timing.planned.velocity, V);  // k = 1 exactly: the speed is kept
  const double length = r * 150 * kRadPerDeg;
  const MotionProfile profile = planned_profile(arc, length);
  EXPECT_LE(profile.peak_acceleration(), r * a1 * (1 + kJointLimitTolerance));
  EXPECT_GE(profile.peak_acceleration(), r * a1 * (1 - 2e-4));
  // The velocity limit reached, up to the stretch to whole cycles (<= 1 cycle in the duration).
  EXPECT_EQ(timing.planned_peak_velocity_m_s, profile.peak_velocity());
  EXPECT_NEAR(timing.planned_peak_velocity_m_s, V, V * path.cycle_s / (arc.end_s - arc.begin_s));

  const auto [first, last] = range(path, arc);
  const JointVector q0 = path.samples[first].q_rad;
  double worst_q = 0.0, worst_still = 0.0, peak_qdd1 = 0.0;
  for (std::size_t k = first; k <= last; ++k) {
    const DesiredJointSample& s = path.samples[k];
    const ProfileState st = profile.at(s.t_s - arc.begin_s);
    // Joint angles from the closed form; IK refines to 1e-12 m, so 1e-9 rad is rounding only.
    worst_q = std::max(worst_q, std::abs(s.q_rad(0) - (q0(0) - st.position / r)));
    worst_still = std::max(worst_still, (s.q_rad - q0).tail<5>().cwiseAbs().maxCoeff());
    EXPECT_NEAR(s.qdd_rad_s2(0), -st.acceleration / r, 1e-9);
    peak_qdd1 = std::max(peak_qdd1, std::abs(s.qdd_rad_s2(0)));
  }
  EXPECT_LT(worst_q, 1e-9);
  EXPECT_LT(worst_still, 1e-9);
  EXPECT_LE(peak_qdd1, a1 * (1 + kJointLimitTolerance));
  EXPECT_GE(peak_qdd1, a1 * (1 - 2e-4));  // binding: slowed no more than needed
  const MeasuredLimitUse use =
      measured_limit_use(path, arc, p.max_acceleration_rad_s2, p.max_jerk_rad_s3);
  EXPECT_NEAR(use.acceleration, timing.planned_use.acceleration_ratio, 1e-12);
  EXPECT_NEAR(use.jerk, timing.planned_use.jerk_ratio, 1e-12);
  EXPECT_LT(use.jerk, 0.7);  // 2/3 of A1's jerk limit, others ~0
}

// The ISO 9283 small circle at 100 % (D 40 mm at 0.5 m/s, datasets/programs/iso9283.yaml) from
// the test pose: its programmed timing takes A3 to 5x its acceleration and 16x its jerk limit.
// The planned one: every joint within its limits, the same circle and orientation, only slower.
TEST(CartesianTiming, SmallCircleIsSlowedOntoTheSameCircle) {
  const Eigen::Isometry3d start =
      fk((JointVector() << 10, -60, 80, 20, 50, 30).finished() * kRadPerDeg);
  const Eigen::Vector3d p0 = start.translation();
  const Eigen::Vector3d centre = p0 + Eigen::Vector3d(0, 0.02, 0);
  const std::string segments = fmt::format(
      "  - circle: {{centre_mm: [{:.17g}, {:.17g}, {:.17g}], normal: [-1, 0, 1], radius_mm: 20, "
      "velocity_m_s: 0.5, acceleration_m_s2: 3, jerk_m_s3: 50, label: small}}\n",
      centre.x() * 1e3, centre.y() * 1e3, centre.z() * 1e3);
  // The start must lie on the circle: the normal (-1, 0, 1) is perpendicular to the +y radius.
  const MotionProgram p = program(segments);
  const DesiredJointPath path = plan_motion(robot(), p);
  const PathSegment& small = segment(path, "small");
  ASSERT_TRUE(small.timing.has_value());
  const CartesianTiming& timing = *small.timing;
  fmt::print(
      "small circle: programmed {:.3f} m/s, {:.3f} s, joint use acc {:.2f} (A{}) jerk {:.2f} "
      "(A{}); planned {:.3f} m/s (limits {:.3f} m/s, {:.2f} m/s^2, {:.1f} m/s^3), {:.3f} s, acc "
      "{:.3f} (A{}) jerk {:.3f} (A{})\n",
      timing.programmed_peak_velocity_m_s, timing.programmed_duration_s,
      timing.programmed_use.acceleration_ratio, timing.programmed_use.acceleration_joint + 1,
      timing.programmed_use.jerk_ratio, timing.programmed_use.jerk_joint + 1,
      timing.planned_peak_velocity_m_s, timing.planned.velocity, timing.planned.acceleration,
      timing.planned.jerk, small.end_s - small.begin_s, timing.planned_use.acceleration_ratio,
      timing.planned_use.acceleration_joint + 1, timing.planned_use.jerk_ratio,
      timing.planned_use.jerk_joint + 1);
  EXPECT_TRUE(timing.slowed);
  EXPECT_GT(timing.programmed_use.ratio(), 2.0);  // measured 5.1 (acceleration), 16.4 (jerk)
  EXPECT_LT(timing.planned_peak_velocity_m_s, timing.programmed_peak_velocity_m_s);

  // The tests' own measure of the limits: within, and the binding one reached (slowed no more
  // than needed: the chosen factors are within 1e-4 of the fastest that fit, measured 0.9999).
  const MeasuredLimitUse use =
      measured_limit_use(path, small, p.max_acceleration_rad_s2, p.max_jerk_rad_s3);
  EXPECT_LE(use.acceleration, 1.0 + kJointLimitTolerance);
  EXPECT_LE(use.jerk, 1.0 + kJointLimitTolerance);
  EXPECT_GT(std::max(use.acceleration, use.jerk), 0.99);
  EXPECT_NEAR(use.acceleration, timing.planned_use.acceleration_ratio, 1e-12);
  EXPECT_NEAR(use.jerk, timing.planned_use.jerk_ratio, 1e-12);

  // Geometry: on the circle (radius and plane) within 1e-9 m at the arc length of the planned
  // profile, orientation constant within 1e-9 rad (FK of IK solutions refined to 1e-12).
  const MotionProfile profile = planned_profile(small, 2 * M_PI * 0.02);
  const Eigen::Vector3d n = Eigen::Vector3d(-1, 0, 1).normalized();
  const Eigen::Vector3d e1 = (p0 - centre).normalized(), e2 = n.cross(e1);
  const auto [first, last] = range(path, small);
  double off_path = 0.0, off_orientation = 0.0;
  for (std::size_t k = first; k <= last; ++k) {
    const Eigen::Isometry3d pose = fk(path.samples[k].q_rad);
    const double phi = profile.at(path.samples[k].t_s - small.begin_s).position / 0.02;
    const Eigen::Vector3d expected = centre + 0.02 * (std::cos(phi) * e1 + std::sin(phi) * e2);
    off_path = std::max(off_path, (pose.translation() - expected).norm());
    off_orientation = std::max(
        off_orientation, Eigen::AngleAxisd(start.linear().transpose() * pose.linear()).angle());
  }
  EXPECT_LT(off_path, 1e-9);
  EXPECT_LT(off_orientation, 1e-9);
}

// A segment within the limits keeps the programmed timing bit for bit: the same program with
// joint limits 1000x higher (nothing can bind) plans the same samples.
TEST(CartesianTiming, SegmentWithinTheLimitsIsUnchangedBitForBit) {
  const char* loose = R"(
name: test
start_joints_deg: [10, -60, 80, 20, 50, 30]
profile: jerk_limited
joint_acceleration_deg_s2: [200000, 200000, 250000, 600000, 600000, 900000]
joint_jerk_deg_s3: [2000000, 2000000, 2500000, 6000000, 6000000, 9000000]
)";
  const std::string segments = R"(
  - lin: {by: {xyz_mm: [100, -150, 50]}, velocity_m_s: 0.1, acceleration_m_s2: 0.5,
          jerk_m_s3: 5, label: calm}
  - rest: {duration_s: 0.1}
  - lin: {by: {xyz_mm: [-100, 150, -50]}, velocity_m_s: 0.5, acceleration_m_s2: 5,
          jerk_m_s3: 100, label: hard}
)";
  const DesiredJointPath path = plan_motion(robot(), program(segments));
  const DesiredJointPath reference = plan_motion(robot(), program(segments, loose));
  const PathSegment& calm = segment(path, "calm");
  ASSERT_TRUE(calm.timing.has_value());
  EXPECT_FALSE(calm.timing->slowed);
  EXPECT_LE(calm.timing->programmed_use.ratio(), 1.0);
  EXPECT_EQ(calm.timing->planned.velocity, 0.1);
  EXPECT_EQ(calm.timing->planned.acceleration, 0.5);
  EXPECT_EQ(calm.timing->planned.jerk, 5.0);
  EXPECT_EQ(calm.end_s, segment(reference, "calm").end_s);
  const auto [first, last] = range(path, calm);
  for (std::size_t k = first; k <= last; ++k) {
    ASSERT_EQ(path.samples[k].q_rad, reference.samples[k].q_rad) << k;
    ASSERT_EQ(path.samples[k].qd_rad_s, reference.samples[k].qd_rad_s) << k;
    ASSERT_EQ(path.samples[k].qdd_rad_s2, reference.samples[k].qdd_rad_s2) << k;
  }
  // The hard one binds and is slowed (longer); the loose program keeps it.
  EXPECT_TRUE(segment(path, "hard").timing->slowed);
  EXPECT_FALSE(segment(reference, "hard").timing->slowed);
  EXPECT_GT(segment(path, "hard").end_s - segment(path, "hard").begin_s,
            segment(reference, "hard").end_s - segment(reference, "hard").begin_s);
}

}  // namespace
}  // namespace imscal::sim
