// Motion planning on the default robot (datasets/robots/kr16.yaml): PTP synchronisation and
// limits, LIN/CIRC geometry through FK (an independent check of the IK), the joint rates against
// the Cartesian profile and against finite differences, J_dot q_dot against a finite difference
// of the Jacobian, and the refusals (InputError naming the segment, the joint and the value).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <string>

#include "core/config_node.hpp"
#include "core/input_error.hpp"
#include "core/units.hpp"
#include "robot/forward_kinematics.hpp"
#include "robot/jacobian.hpp"
#include "robot/robot_description.hpp"
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

// test::kHeader's joint limits.
const MotionProgram& header_program() {
  static const MotionProgram p = program("  - rest: {duration_s: 1}\n");
  return p;
}

double rotation_angle(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle();
}

void expect_structure(const DesiredJointPath& path) {
  ASSERT_FALSE(path.samples.empty());
  for (std::size_t k = 0; k < path.samples.size(); ++k) {
    ASSERT_EQ(path.samples[k].t_s, static_cast<double>(k) * path.cycle_s);
  }
  EXPECT_EQ(path.segments.front().begin_s, 0.0);
  EXPECT_EQ(path.segments.back().end_s, path.samples.back().t_s);
  for (std::size_t i = 1; i < path.segments.size(); ++i) {
    EXPECT_EQ(path.segments[i].begin_s, path.segments[i - 1].end_s);
  }
  EXPECT_EQ(path.samples.front().qd_rad_s.norm(), 0.0);
  EXPECT_LT(path.samples.back().qd_rad_s.norm(), 1e-12);  // rest to rest, rounding only
}

TEST(MotionPlanner, PtpIsSynchronisedLimitedAndExact) {
  const MotionProgram p = program(R"(
  - rest: {duration_s: 0.5, label: r}
  - ptp: {joints_deg: [40, -30, 40, -60, 80, 120], profile: trapezoidal, label: move}
  - ptp: {joints_deg: [10, -60, 80, 20, 50, 30], velocity_scale: 0.5, acceleration_scale: 0.5,
          label: slow}
)");
  const DesiredJointPath path = plan_motion(robot(), p);
  expect_structure(path);
  EXPECT_NEAR(segment(path, "r").end_s, 0.5, 1e-15);
  const JointVector q0 = p.start_joints_rad;
  const JointVector target = *p.steps[1].target_joints_rad;
  const JointVector delta = target - q0;
  for (const auto& [label, v_scale, a_scale] :
       {std::tuple{"move", 1.0, 1.0}, std::tuple{"slow", 0.5, 0.5}}) {
    const auto [first, last] = range(path, segment(path, label));
    double usage = 0.0;  // largest fraction of a limit used by any joint
    for (std::size_t k = first; k <= last; ++k) {
      const DesiredJointSample& s = path.samples[k];
      const JointVector from = std::string(label) == "move" ? q0 : target;
      const JointVector d = std::string(label) == "move" ? delta : JointVector(-delta);
      // Synchronised: every joint at the same fraction of its move (rounding: 1e-13).
      const double fraction = (s.q_rad(0) - from(0)) / d(0);
      for (int i = 0; i < 6; ++i) {
        EXPECT_NEAR(s.q_rad(i), from(i) + fraction * d(i), 1e-13);
        const double v_max = robot().joints[i].max_velocity_rad_s * v_scale;
        const double a_max = p.max_acceleration_rad_s2(i) * a_scale;
        EXPECT_LE(std::abs(s.qd_rad_s(i)), v_max * (1 + 1e-9));  // rounding only
        EXPECT_LE(std::abs(s.qdd_rad_s2(i)), a_max * (1 + 1e-9));
        usage =
            std::max({usage, std::abs(s.qd_rad_s(i)) / v_max, std::abs(s.qdd_rad_s2(i)) / a_max});
      }
      if (k > first && k < last) {
        // Central difference of q vs qd: error <= a_max h / 2 (trapezoid: a jumps) or
        // j_max h^2 / 6 (S-curve); the first bound covers both here.
        for (int i = 0; i < 6; ++i) {
          const double fd =
              (path.samples[k + 1].q_rad(i) - path.samples[k - 1].q_rad(i)) / (2 * path.cycle_s);
          EXPECT_NEAR(fd, s.qd_rad_s(i), p.max_acceleration_rad_s2(i) * path.cycle_s / 2 + 1e-12);
        }
      }
    }
    // The slowest joint sets the time: some joint uses its velocity or acceleration limit, up
    // to the stretch to whole cycles (< 1 % for moves > 0.2 s) and the sampling of the peak.
    EXPECT_GT(usage, 0.98) << label;
  }
  const auto [first, last] = range(path, segment(path, "move"));
  EXPECT_EQ(path.samples[last].q_rad, target);  // exactly the target
  EXPECT_EQ(path.samples.back().q_rad, q0);
}

TEST(MotionPlanner, JacobianRateTimesJointRateMatchesFiniteDifference) {
  // Truth: central difference of the geometric Jacobian along q_dot, h = 1e-6 s: truncation
  // ~h^2 |J'''| ~ 1e-12, rounding ~1e-16 / h = 1e-10.
  std::srand(7);
  for (int trial = 0; trial < 50; ++trial) {
    const JointVector q = JointVector::Random() * 2.0;
    const JointVector qd = JointVector::Random() * 2.0;
    const double h = 1e-6;
    const calib::Jacobian dJ = (calib::geometric_jacobian(robot().kinematics, q + h * qd) -
                                calib::geometric_jacobian(robot().kinematics, q - h * qd)) /
                               (2 * h);
    const Eigen::Matrix<double, 6, 1> expected = dJ * qd;
    const Eigen::Matrix<double, 6, 1> got =
        jacobian_rate_times_joint_rate(robot().kinematics, q, qd);
    EXPECT_LT((got - expected).norm(), 1e-8) << trial;
  }
}

// Checks a Cartesian segment: positions through FK on the geometry (distance function),
// orientation, path speed from J qd against the profile, qd and qdd against finite differences,
// the joints within the program's acceleration and jerk limits.
template <typename Distance, typename Orientation>
void check_cartesian(const DesiredJointPath& path, const PathSegment& seg, double length,
                     const ProfileLimits& programmed, Distance distance_to_path,
                     Orientation expected_rotation) {
  const auto [first, last] = range(path, seg);
  // The planned profile, recomputed: the arc-length profile over `length` with the limits the
  // planner chose (the programmed ones unless a joint limit made it slow the segment down),
  // stretched to the segment's duration.
  ASSERT_TRUE(seg.timing.has_value());
  EXPECT_EQ(seg.timing->programmed.velocity, programmed.velocity);
  EXPECT_EQ(seg.timing->programmed.acceleration, programmed.acceleration);
  EXPECT_EQ(seg.timing->programmed.jerk, programmed.jerk);
  const ProfileLimits limits = seg.timing->planned;
  const MotionProfile profile = MotionProfile::plan(ProfileKind::kJerkLimited, length, limits)
                                    .stretched_to(seg.end_s - seg.begin_s);
  // Within the joint limits of test::kHeader (the planner's tolerance: 1e-6).
  const MeasuredLimitUse use = measured_limit_use(
      path, seg, header_program().max_acceleration_rad_s2, header_program().max_jerk_rad_s3);
  EXPECT_LE(use.acceleration, 1.0 + kJointLimitTolerance);
  EXPECT_LE(use.jerk, 1.0 + kJointLimitTolerance);
  double peak_speed = 0.0;
  for (std::size_t k = first; k <= last; ++k) {
    const DesiredJointSample& s = path.samples[k];
    const Eigen::Isometry3d pose = fk(s.q_rad);
    const double t = s.t_s - seg.begin_s;
    const ProfileState st = profile.at(t);
    // On the geometry within 1e-9 m (IK refines to 1e-12 m; FK rounding ~1e-15 m).
    EXPECT_LT(distance_to_path(pose.translation(), st.position), 1e-9) << "t=" << t;
    EXPECT_LT(rotation_angle(expected_rotation(st.position), pose.linear()), 1e-9) << "t=" << t;
    // Path speed: |v| of the flange from J qd = the profile's (J and J^-1 are consistent to
    // ~1e-15 relative; the IK pose error 1e-12 m does not enter).
    const Eigen::Matrix<double, 6, 1> twist =
        calib::geometric_jacobian(robot().kinematics, s.q_rad) * s.qd_rad_s;
    EXPECT_NEAR(twist.head<3>().norm(), st.velocity, 1e-9) << "t=" << t;
    peak_speed = std::max(peak_speed, twist.head<3>().norm());
    if (k > first && k < last) {
      // qd vs central differences of q (h = 2 ms): error = h^2 / 6 q'''(xi); qdd vs central
      // differences of qd: error <= h max|q'''| (q''' jumps with the path jerk). |q'''| is
      // bounded from the planned qdd of the neighbouring cycles (factor 2 for its variation
      // within a cycle). Floors: the IK error (1e-12 rad) over 2h gives 5e-10 rad/s; qd carries
      // ~1e-12 relative rounding over 2h -> 1e-8 rad/s^2.
      const double h = path.cycle_s;
      for (int i = 0; i < 6; ++i) {
        const double jerk =
            2.0 *
            std::max(std::abs(path.samples[k + 1].qdd_rad_s2(i) - s.qdd_rad_s2(i)),
                     std::abs(s.qdd_rad_s2(i) - path.samples[k - 1].qdd_rad_s2(i))) /
            h;
        const double fd_q = (path.samples[k + 1].q_rad(i) - path.samples[k - 1].q_rad(i)) / (2 * h);
        const double fd_qd =
            (path.samples[k + 1].qd_rad_s(i) - path.samples[k - 1].qd_rad_s(i)) / (2 * h);
        EXPECT_NEAR(fd_q, s.qd_rad_s(i), h * h / 6 * jerk + 2e-9) << "t=" << t << " joint " << i;
        EXPECT_NEAR(fd_qd, s.qdd_rad_s2(i), h * jerk + 1e-8) << "t=" << t << " joint " << i;
      }
    }
  }
  // Cruise reached (the lengths are long enough), up to the stretch to whole cycles (< 0.2 %).
  EXPECT_NEAR(peak_speed, limits.velocity, 2e-3 * limits.velocity);
  EXPECT_LE(peak_speed, limits.velocity * (1 + 1e-9));
}

TEST(MotionPlanner, LinFollowsTheLineWithConstantOrientation) {
  const MotionProgram p = program(R"(
  - lin: {by: {xyz_mm: [200, -300, 100]}, velocity_m_s: 0.5, acceleration_m_s2: 2,
          jerk_m_s3: 20, label: line}
)");
  const DesiredJointPath path = plan_motion(robot(), p);
  expect_structure(path);
  const Eigen::Isometry3d start = fk(p.start_joints_rad);
  const Eigen::Vector3d p0 = start.translation();
  const Eigen::Vector3d offset(0.2, -0.3, 0.1);
  const Eigen::Vector3d u = offset.normalized();
  check_cartesian(
      path, segment(path, "line"), offset.norm(), {0.5, 2.0, 20.0},
      [&](const Eigen::Vector3d& x, double s) {
        // Perpendicular distance from the line, and the position along it vs the profile.
        const Eigen::Vector3d r = x - p0;
        return std::max((r - r.dot(u) * u).norm(), std::abs(r.dot(u) - s));
      },
      [&](double) { return Eigen::Matrix3d(start.linear()); });
  EXPECT_LT((fk(path.samples.back().q_rad).translation() - (p0 + offset)).norm(), 1e-9);
}

TEST(MotionPlanner, LinSlerpTurnsProportionallyToTheDistance) {
  const MotionProgram p = program(R"(
  - lin: {to: {xyz_mm: [1200, 300, 900], rpy_deg: [150, 20, 30]}, orientation: slerp,
          velocity_m_s: 0.3, acceleration_m_s2: 1.5, jerk_m_s3: 15, label: turn}
)");
  const DesiredJointPath path = plan_motion(robot(), p);
  const Eigen::Isometry3d start = fk(p.start_joints_rad);
  const Eigen::Vector3d p0 = start.translation(), p1(1.2, 0.3, 0.9);
  const Eigen::Matrix3d R1 =
      calib::pose_from_xyz_rpy(Eigen::Vector3d::Zero(), Eigen::Vector3d(150, 20, 30) * kRadPerDeg)
          .linear();
  const double L = (p1 - p0).norm();
  // Truth: the geodesic R0 -> R1 via Eigen's quaternion slerp at sigma = s / L.
  const Eigen::Quaterniond qa(start.linear()), qb(R1);
  const Eigen::Vector3d u = (p1 - p0) / L;
  check_cartesian(
      path, segment(path, "turn"), L, {0.3, 1.5, 15.0},
      [&](const Eigen::Vector3d& x, double s) {
        const Eigen::Vector3d r = x - p0;
        return std::max((r - r.dot(u) * u).norm(), std::abs(r.dot(u) - s));
      },
      [&](double s) { return qa.slerp(s / L, qb).toRotationMatrix(); });
  const Eigen::Isometry3d end = fk(path.samples.back().q_rad);
  EXPECT_LT(rotation_angle(end.linear(), R1), 1e-9);
  EXPECT_LT((end.translation() - p1).norm(), 1e-9);
}

TEST(MotionPlanner, CircThroughViaPointAndFullCircle) {
  // Start p0; via p0 + (100, 100, 0) mm, target p0 + (200, 0, 0) mm: by construction the circle
  // is horizontal with centre p0 + (100, 0, 0) mm and radius 100 mm (half circle). Then a full
  // circle about a centre 80 mm further along y turning about +z.
  const Eigen::Isometry3d start =
      fk((JointVector() << 10, -60, 80, 20, 50, 30).finished() * kRadPerDeg);
  const Eigen::Vector3d p0 = start.translation();
  const Eigen::Vector3d via = p0 + Eigen::Vector3d(0.1, 0.1, 0),
                        to = p0 + Eigen::Vector3d(0.2, 0, 0);
  const Eigen::Vector3d centre1 = p0 + Eigen::Vector3d(0.1, 0, 0);
  const Eigen::Vector3d centre2 = to + Eigen::Vector3d(0, 0.08, 0);
  // 17 significant digits: the parsed numbers are these points up to the mm -> m rounding.
  auto mm = [](const Eigen::Vector3d& v) {
    return fmt::format("[{:.17g}, {:.17g}, {:.17g}]", v.x() * 1e3, v.y() * 1e3, v.z() * 1e3);
  };
  const MotionProgram p =
      program("  - circ: {via_mm: " + mm(via) + ", to: {xyz_mm: " + mm(to) +
              "}, velocity_m_s: 0.25, acceleration_m_s2: 2, jerk_m_s3: 20, label: arc}\n"
              "  - rest: {duration_s: 0.2}\n"
              "  - circle: {centre_mm: " +
              mm(centre2) +
              ", normal: [0, 0, 2], radius_mm: 80, velocity_m_s: 0.25, acceleration_m_s2: 2, "
              "jerk_m_s3: 20, label: full}\n");
  const DesiredJointPath path = plan_motion(robot(), p);
  expect_structure(path);
  const Eigen::Matrix3d R0 = start.linear();
  auto on_circle = [](const Eigen::Vector3d& c, double r, double z) {
    return [c, r, z](const Eigen::Vector3d& x, double) {
      return std::max(std::abs((x - c).norm() - r), std::abs(x.z() - z));
    };
  };
  const PathSegment& arc = segment(path, "arc");
  check_cartesian(path, arc, M_PI * 0.1, {0.25, 2.0, 20.0}, on_circle(centre1, 0.1, p0.z()),
                  [&](double) { return R0; });
  // Passes the via point: the closest sample is within half a cycle's travel (0.25 m/s * 1 ms).
  double closest = 1.0;
  const auto [a0, a1] = range(path, arc);
  for (std::size_t k = a0; k <= a1; ++k) {
    closest =
        std::min(closest, (fk(path.samples[k].q_rad).translation() - p.steps[0].via_m).norm());
  }
  EXPECT_LT(closest, 0.25 * path.cycle_s / 2 + 1e-9);
  EXPECT_LT((fk(path.samples[a1].q_rad).translation() - p.steps[0].target_m).norm(), 1e-9);

  const PathSegment& full = segment(path, "full");
  check_cartesian(path, full, 2 * M_PI * 0.08, {0.25, 2.0, 20.0},
                  on_circle(p.steps[2].centre_m, 0.08, p0.z()), [&](double) { return R0; });
  const auto [f0, f1] = range(path, full);
  const Eigen::Vector3d begin = fk(path.samples[f0].q_rad).translation();
  EXPECT_LT((fk(path.samples[f1].q_rad).translation() - begin).norm(), 1e-9);
  // Positive turn about +z: the first step moves along z x (start - centre).
  const Eigen::Vector3d step = fk(path.samples[f0 + 50].q_rad).translation() - begin;
  EXPECT_GT(step.dot(Eigen::Vector3d::UnitZ().cross(begin - p.steps[2].centre_m)), 0.0);
}

TEST(MotionPlanner, PayloadChangesAfterRest) {
  const MotionProgram p = program(R"(
  - rest: {duration_s: 1}
  - payload: {name: box16, mass_kg: 16, com_m: [0, 0, 0.1], inertia_kg_m2: [0.1, 0.1, 0.1, 0, 0, 0]}
  - ptp: {joints_deg: [20, -60, 80, 20, 50, 30], label: move}
)");
  const DesiredJointPath path = plan_motion(robot(), p);
  ASSERT_EQ(path.payloads.size(), 2u);
  EXPECT_EQ(path.payloads[0].body.mass_kg, 0.0);
  EXPECT_EQ(path.payloads[1].name, "box16");
  EXPECT_EQ(path.payloads[1].body.mass_kg, 16.0);
  EXPECT_EQ(path.payloads[1].body.com_m, Eigen::Vector3d(0, 0, 0.1));
  const auto [first, last] = range(path, segment(path, "move"));
  EXPECT_EQ(path.samples[first].payload_index, 0);  // the last rest sample: old load
  EXPECT_EQ(path.samples[first + 1].payload_index, 1);
  EXPECT_EQ(path.samples.back().payload_index, 1);
}

// The error names the program file, the segment and, in the problem, what is wrong.
void expect_refusal(const std::string& segments, const std::string& field_part,
                    const std::string& problem_part) {
  try {
    plan_motion(robot(), program(segments));
    ADD_FAILURE() << "not refused: " << segments;
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), "test.yaml");
    EXPECT_NE(e.field().find(field_part), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(problem_part), std::string::npos) << e.what();
    EXPECT_GT(e.line(), 0u);
  }
}

TEST(MotionPlanner, RefusesUnreachableSingularAndTooFast) {
  // 1.5 m further out: beyond the 1.61 m reach.
  expect_refusal(R"(
  - rest: {duration_s: 1}
  - lin: {by: {xyz_mm: [1500, 0, 0]}, velocity_m_s: 0.5, acceleration_m_s2: 2, jerk_m_s3: 20,
          label: too far}
)",
                 "segments[1] 'too far'", "unreachable");
  // A2 limit is [-155, 35] deg.
  expect_refusal("  - ptp: {joints_deg: [0, 50, 80, 0, 30, 0], label: bad}\n", "segments[0] 'bad'",
                 "A2 at 50.0000 deg");
  // Turning the flange by ~90 deg over 10 mm at 1 m/s needs ~150 rad/s at the wrist.
  expect_refusal(R"(
  - lin: {to: {xyz_mm: [1200, 300, 900], rpy_deg: [90, 0, 0]}, orientation: slerp,
          velocity_m_s: 1.0, acceleration_m_s2: 5, jerk_m_s3: 50, label: ok}
  - lin: {to: {xyz_mm: [1210, 300, 900], rpy_deg: [0, 90, 0]}, orientation: slerp,
          velocity_m_s: 1.0, acceleration_m_s2: 5, jerk_m_s3: 50, label: wrist spin}
)",
                 "segments[1] 'wrist spin'", "above its max velocity");
  // A PTP pose target out of reach.
  expect_refusal("  - ptp: {pose: {xyz_mm: [3000, 0, 500], rpy_deg: [180, 0, 0]}}\n",
                 "segments[0] 'ptp 0'", "no IK solution");
  // The start of a circle must lie on it.
  expect_refusal(
      "  - circle: {centre_mm: [0, 0, 0], normal: [0, 0, 1], radius_mm: 100, velocity_m_s: 0.1, "
      "acceleration_m_s2: 1, jerk_m_s3: 10}\n",
      "segments[0] 'circle 0'", "not on the circle");
}

TEST(MotionPlanner, RefusesCartesianMoveBeyondAJointLimit) {
  // A robot whose A1 stops at 12 deg; the start has q1 = 10 deg, and moving in -y turns A1
  // positively (axis 1 points down), so the line leaves the range after a few cm.
  calib::RobotDescription narrow = robot();
  narrow.kinematics.upper_limit_rad(0) = 12.0 * kRadPerDeg;
  try {
    plan_motion(narrow, program(R"(
  - lin: {by: {xyz_mm: [0, -300, 0]}, velocity_m_s: 0.2, acceleration_m_s2: 1, jerk_m_s3: 10,
          label: sideways}
)"));
    ADD_FAILURE() << "not refused";
  } catch (const InputError& e) {
    EXPECT_NE(e.field().find("segments[0] 'sideways'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("joint A1 would reach"), std::string::npos) << e.what();
  }
  // A start pose outside the limits is refused too.
  try {
    plan_motion(narrow, parse_motion_program(ConfigNode::load_string(
                            "name: x\nstart_joints_deg: [20, -60, 80, 20, 50, 30]\n"
                            "joint_acceleration_deg_s2: [1, 1, 1, 1, 1, 1]\nprofile: trapezoidal\n"
                            "segments:\n  - rest: {duration_s: 1}\n",
                            "start.yaml")));
    ADD_FAILURE() << "not refused";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "start_joints_deg");
    EXPECT_NE(std::string(e.what()).find("A1 at 20.0000 deg"), std::string::npos) << e.what();
  }
}

TEST(MotionPlanner, RefusesPassingThroughTheWristSingularity) {
  // With A4 = A6 = 0 the arm is planar and the flange pitch is q2 + q3 + q5: from
  // (0, -60, 80, 0, 10, 0) to (0, -40, 80, 0, -10, 0) the orientation is the same, so a constant-
  // orientation line between the two flange positions must take A5 through 0 (axes 4 and 6
  // aligned). Both ends are regular poses.
  const JointVector q_end = (JointVector() << 0, -40, 80, 0, -10, 0).finished() * kRadPerDeg;
  const Eigen::Vector3d target = fk(q_end).translation() * 1e3;
  const std::string segments = fmt::format(
      "  - ptp: {{joints_deg: [0, -60, 80, 0, 10, 0]}}\n"
      "  - lin: {{to: {{xyz_mm: [{:.17g}, {:.17g}, {:.17g}]}}, velocity_m_s: 0.2, "
      "acceleration_m_s2: 1, jerk_m_s3: 10, label: through wrist}}\n",
      target.x(), target.y(), target.z());
  expect_refusal(segments, "segments[1] 'through wrist'", "wrist singular");
}

TEST(MotionProgram, RefusesBadPrograms) {
  auto refused = [](const std::string& segments, const std::string& part) {
    try {
      program(segments);
      ADD_FAILURE() << "not refused: " << segments;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
    }
  };
  refused("  - ptp: {joints_deg: [0, 0, 0, 0, 0, 0]}\n  - payload: {name: x, mass_kg: 1}\n",
          "only at rest");
  refused("  - rest: {duration_s: 1, speed: 3}\n", "unknown key");
  refused("  - jump: {duration_s: 1}\n", "unknown segment kind");
  refused("  - ptp: {joints_deg: [0, 0, 0, 0, 0]}\n", "expected 6 numbers");
  refused("  - lin: {by: {xyz_mm: [1, 0, 0]}, velocity_m_s: 0.1, acceleration_m_s2: 1}\n",
          "jerk_m_s3 is required");
  refused(
      "  - lin: {by: {xyz_mm: [1, 0, 0]}, velocity_m_s: 0.1, acceleration_m_s2: 1,"
      " jerk_m_s3: 1, orientation: slerp}\n",
      "slerp needs");
}

}  // namespace
}  // namespace imscal::sim
