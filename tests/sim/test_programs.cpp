// The shipped motion programs (datasets/programs/*.yaml) plan on their robot (the default robot;
// the UR10e for ur10e-*.yaml) within its limits and do what their comments promise: seed-line is
// the paper's test path; identification, mounting and iso9283 have the moves, rests, payloads and
// geometry their briefs ask for. Positions are checked through forward kinematics (independent of
// the IK the planner used).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <string>

#include "calib/forward_kinematics.hpp"
#include "calib/jacobian.hpp"
#include "calib/robot_description.hpp"
#include "sim/motion_planner.hpp"
#include "sim/motion_program.hpp"
#include "tests/sim/joint_limit_use.hpp"
#include "tests/sim/planned_path_helpers.hpp"

namespace imscal::sim {
namespace {

using calib::JointVector;
using test::fk;
using test::range;
using test::robot;
using test::segment;
namespace fs = std::filesystem;

fs::path programs_dir() {
  return fs::path(IMSCAL_SOURCE_DIR) / "datasets" / "programs";
}

struct Planned {
  MotionProgram program;
  DesiredJointPath path;
};

// The robot a program is written for: the UR10e's programs are named ur10e-*.
const calib::RobotDescription& robot_for(const std::string& program) {
  static const calib::RobotDescription ur10e =
      calib::load_robot_description(std::string(IMSCAL_SOURCE_DIR) + "/datasets/robots/ur10e.urdf");
  return program.rfind("ur10e-", 0) == 0 ? ur10e : robot();
}

// Each program is planned once for all tests.
const Planned& planned(const std::string& name) {
  static std::map<std::string, Planned> cache;
  auto it = cache.find(name);
  if (it == cache.end()) {
    Planned p;
    p.program = load_motion_program(programs_dir() / (name + ".yaml"));
    p.path = plan_motion(robot_for(name), p.program);
    it = cache.emplace(name, std::move(p)).first;
  }
  return it->second;
}

double path_speed(const JointVector& q, const JointVector& qd) {
  return (calib::geometric_jacobian(robot().kinematics, q) * qd).head<3>().norm();
}

TEST(ShippedPrograms, EveryProgramPlansWithinTheLimits) {
  int count = 0;
  for (const auto& entry : fs::directory_iterator(programs_dir())) {
    if (entry.path().extension() != ".yaml") continue;
    ++count;
    const std::string name = entry.path().stem().string();
    SCOPED_TRACE(name);
    const Planned& p = planned(name);
    const DesiredJointPath& path = p.path;
    const calib::RobotDescription& r = robot_for(name);
    const auto& k = r.kinematics;
    ASSERT_GT(path.samples.size(), 1u);
    EXPECT_EQ(path.cycle_s, r.controller_cycle_s);
    EXPECT_EQ(path.segments.front().begin_s, 0.0);
    EXPECT_EQ(path.segments.back().end_s, path.samples.back().t_s);
    for (std::size_t i = 1; i < path.segments.size(); ++i) {
      EXPECT_EQ(path.segments[i].begin_s, path.segments[i - 1].end_s);
    }
    EXPECT_EQ(path.segments.front().kind, SegmentKind::kRest);  // the IMS needs rest first
    EXPECT_EQ(path.segments.back().kind, SegmentKind::kRest);
    // Counted with plain code and asserted once per program: a per-sample gtest assertion would
    // dominate the run time (200 000 samples), above all under the sanitizers.
    int bad_time = 0, bad_payload = 0, outside_limits = 0, too_fast = 0;
    for (std::size_t n = 0; n < path.samples.size(); ++n) {
      const DesiredJointSample& s = path.samples[n];
      bad_time += s.t_s != static_cast<double>(n) * path.cycle_s;
      bad_payload +=
          s.payload_index < 0 || s.payload_index >= static_cast<int>(path.payloads.size());
      for (int i = 0; i < 6; ++i) {
        outside_limits += s.q_rad(i) < k.lower_limit_rad(i) || s.q_rad(i) > k.upper_limit_rad(i);
        // Rounding slack only: the planner checks the same limit.
        too_fast += std::abs(s.qd_rad_s(i)) > r.joints[i].max_velocity_rad_s * (1 + 1e-9);
      }
    }
    EXPECT_EQ(bad_time, 0);
    EXPECT_EQ(bad_payload, 0);
    EXPECT_EQ(outside_limits, 0);
    EXPECT_EQ(too_fast, 0);
    int rest_moving = 0, ptp_too_hard = 0;
    for (const PathSegment& seg : path.segments) {
      const auto [first, last] = range(path, seg);
      for (std::size_t n = first; n <= last; ++n) {
        const DesiredJointSample& s = path.samples[n];
        if (seg.kind == SegmentKind::kRest) {
          rest_moving += s.q_rad != path.samples[first].q_rad || s.qd_rad_s.norm() > 1e-12;
        }
        if (seg.kind == SegmentKind::kPtp) {
          for (int i = 0; i < 6; ++i) {
            ptp_too_hard +=
                std::abs(s.qdd_rad_s2(i)) > p.program.max_acceleration_rad_s2(i) * (1 + 1e-9);
          }
        }
      }
    }
    EXPECT_EQ(rest_moving, 0);
    EXPECT_EQ(ptp_too_hard, 0);
    // Cartesian moves too (the planner slows those whose programmed timing would not be): the
    // acceleration and, for jerk_limited moves, the jerk per cycle within the planner's tolerance.
    for (const PathSegment& seg : path.segments) {
      if (seg.kind != SegmentKind::kLinear && seg.kind != SegmentKind::kCircular) continue;
      const MeasuredLimitUse use = measured_limit_use(path, seg, p.program.max_acceleration_rad_s2,
                                                      p.program.max_jerk_rad_s3);
      EXPECT_LE(use.acceleration, 1.0 + kJointLimitTolerance) << seg.label;
      EXPECT_LE(use.jerk, 1.0 + kJointLimitTolerance) << seg.label;
    }
  }
  // seed-line, identification, mounting, iso9283, campaign; and each for the UR10e
  EXPECT_EQ(count, 10);
}

TEST(ShippedPrograms, SeedLineIsThePapersTestPath) {
  const Planned& p = planned("seed-line");
  const DesiredJointPath& path = p.path;
  // Rest >= 5 s at the start (IMS alignment).
  EXPECT_EQ(path.segments.front().kind, SegmentKind::kRest);
  EXPECT_GE(path.segments.front().end_s, 5.0);
  // Payload 5 kg throughout.
  for (const auto& s : path.samples) ASSERT_EQ(path.payloads[s.payload_index].body.mass_kg, 5.0);

  const PathSegment& out = segment(path, "line -y");
  const PathSegment& pause = segment(path, "pause");
  const PathSegment& back = segment(path, "line +y");
  EXPECT_EQ(out.kind, SegmentKind::kLinear);
  EXPECT_EQ(pause.begin_s, out.end_s);
  EXPECT_NEAR(pause.end_s - pause.begin_s, 1.0, 1e-12);  // 1 s pause (500 cycles)
  EXPECT_EQ(back.begin_s, pause.end_s);

  const auto [o0, o1] = range(path, out);
  const auto [b0, b1] = range(path, back);
  const Eigen::Isometry3d start = fk(path.samples[o0].q_rad);
  const Eigen::Vector3d p0 = start.translation();
  // 800 mm in -y; back at the start. FK of IK solutions: 1e-9 m (IK refines to 1e-12 m).
  EXPECT_LT((fk(path.samples[o1].q_rad).translation() - (p0 - Eigen::Vector3d(0, 0.8, 0))).norm(),
            1e-9);
  EXPECT_LT((fk(path.samples[b1].q_rad).translation() - p0).norm(), 1e-9);
  // On the line, constant orientation, peak path speed 0.4 m/s.
  double peak = 0.0;
  for (auto [a, b] : {std::pair{o0, o1}, std::pair{b0, b1}}) {
    for (std::size_t n = a; n <= b; ++n) {
      const Eigen::Isometry3d pose = fk(path.samples[n].q_rad);
      const Eigen::Vector3d d = pose.translation() - p0;
      EXPECT_LT(std::hypot(d.x(), d.z()), 1e-9);
      EXPECT_LT(Eigen::AngleAxisd(start.linear().transpose() * pose.linear()).angle(), 1e-9);
      peak = std::max(peak, path_speed(path.samples[n].q_rad, path.samples[n].qd_rad_s));
    }
  }
  // Cruise at 0.4 m/s, slowed at most by the stretch to whole cycles (< 0.1 % of ~2.3 s).
  EXPECT_NEAR(peak, 0.4, 1e-3 * 0.4);
  EXPECT_LE(peak, 0.4 * (1 + 1e-9));
  // At the outer limits of the workspace: the wrist centre (origin of DH frame 4) is 90-97 % of
  // the stretched arm's distance from axis 2 (origin of DH frame 1) somewhere on the line.
  auto arm_extension = [](const JointVector& q) {
    const auto chain = calib::chain_poses<double>(robot().kinematics, q);
    return (chain.T_R_link[4].translation() - chain.T_R_link[1].translation()).norm();
  };
  const double stretched = arm_extension(JointVector::Zero());  // q = 0: arm stretched
  double max_extension = 0.0;
  for (std::size_t n = o0; n <= o1; ++n) {
    max_extension = std::max(max_extension, arm_extension(path.samples[n].q_rad) / stretched);
  }
  EXPECT_GT(max_extension, 0.90);
  EXPECT_LT(max_extension, 0.97);
}

TEST(ShippedPrograms, IdentificationHasSingleJointAndMixedMovesWithTwoPayloads) {
  const Planned& p = planned("identification");
  const DesiredJointPath& path = p.path;
  const double total = path.samples.back().t_s;
  EXPECT_GE(total, 120.0);  // brief: 2-3 minutes
  EXPECT_LE(total, 180.0);
  EXPECT_GE(path.segments.front().end_s, 5.0);
  ASSERT_EQ(path.payloads.size(), 2u);
  EXPECT_NE(path.payloads[0].body.mass_kg, path.payloads[1].body.mass_kg);
  std::array<int, 6> plus{}, minus{};
  std::array<double, 6> peak_acceleration{};
  std::vector<double> mixed_speed_fractions;
  for (const PathSegment& seg : path.segments) {
    if (seg.kind != SegmentKind::kPtp) continue;
    const auto [a, b] = range(path, seg);
    const JointVector delta = path.samples[b].q_rad - path.samples[a].q_rad;
    int moving = 0, joint = -1;
    for (int i = 0; i < 6; ++i) {
      if (std::abs(delta(i)) > 1e-9) {
        ++moving;
        joint = i;
      }
    }
    double speed_fraction = 0.0;
    for (std::size_t n = a; n <= b; ++n) {
      for (int i = 0; i < 6; ++i) {
        speed_fraction = std::max(speed_fraction, std::abs(path.samples[n].qd_rad_s(i)) /
                                                      robot().joints[i].max_velocity_rad_s);
        if (moving == 1 && i == joint) {
          peak_acceleration[i] =
              std::max(peak_acceleration[i], std::abs(path.samples[n].qdd_rad_s2(i)));
        }
      }
    }
    if (moving == 1) {
      (delta(joint) > 0 ? plus : minus)[joint]++;
    } else {
      mixed_speed_fractions.push_back(speed_fraction);
    }
  }
  for (int i = 0; i < 6; ++i) {
    EXPECT_GE(plus[i], 1) << "joint " << i;
    EXPECT_GE(minus[i], 1) << "joint " << i;
    // At the highest acceleration: the trapezoid's plateau is the program's max (exactly, up
    // to the stretch to whole cycles: < 1 % for moves > 0.4 s).
    EXPECT_GT(peak_acceleration[i], 0.99 * p.program.max_acceleration_rad_s2(i)) << i;
  }
  // Mixed moves at low, medium and high joint speed (fraction of the fastest joint's limit).
  auto has = [&](double lo, double hi) {
    return std::any_of(mixed_speed_fractions.begin(), mixed_speed_fractions.end(),
                       [&](double f) { return f >= lo && f <= hi; });
  };
  EXPECT_TRUE(has(0.1, 0.3));
  EXPECT_TRUE(has(0.4, 0.6));
  EXPECT_TRUE(has(0.9, 1.0 + 1e-9));
}

// The rest poses of a frame-calibration program: at least `min_rests`, each >= `min_rest_s`, the
// first >= 10 s (IMS alignment), turned about every flange axis and seeing gravity along each.
void expect_rests_turned_about_all_flange_axes(const DesiredJointPath& path, double min_rest_s,
                                               std::size_t min_rests) {
  EXPECT_GE(path.segments.front().end_s - path.segments.front().begin_s, 10.0);
  std::vector<Eigen::Matrix3d> rotations;
  for (const PathSegment& seg : path.segments) {
    if (seg.kind != SegmentKind::kRest) continue;
    EXPECT_GE(seg.end_s - seg.begin_s, min_rest_s - 1e-9) << seg.label;
    rotations.push_back(fk(path.samples[range(path, seg).first].q_rad).linear());
  }
  EXPECT_GE(rotations.size(), min_rests);
  // Rotation of each pose relative to the first, as a rotation vector in the flange axes H:
  // some pose turns by >= 60 deg about each of x_H, y_H, z_H.
  Eigen::Vector3d largest = Eigen::Vector3d::Zero();
  // Gravity (-z of R) seen in H: must point along +-x_H, +-y_H, +-z_H in some pose (>= 0.7).
  Eigen::Vector3d most_positive = Eigen::Vector3d::Constant(-1),
                  most_negative = Eigen::Vector3d::Constant(1);
  for (const Eigen::Matrix3d& R : rotations) {
    const Eigen::AngleAxisd turn(rotations.front().transpose() * R);
    largest = largest.cwiseMax((turn.angle() * turn.axis()).cwiseAbs());
    const Eigen::Vector3d g = R.transpose() * Eigen::Vector3d(0, 0, -1);
    most_positive = most_positive.cwiseMax(g);
    most_negative = most_negative.cwiseMin(g);
  }
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_GE(largest(axis), 60.0 * M_PI / 180.0) << "axis " << axis;
    EXPECT_GE(most_positive(axis), 0.7) << "axis " << axis;
    EXPECT_LE(most_negative(axis), -0.7) << "axis " << axis;
  }
}

TEST(ShippedPrograms, MountingHasManyRestPosesTurnedAboutAllFlangeAxes) {
  expect_rests_turned_about_all_flange_axes(planned("mounting").path, 5.0, 12);
}

// The default campaign (datasets/campaign/): the mounting poses for the frame calibration, with
// moves at full joint speed for the identification, and the wrist kept away from A5 = 0 so that
// the inverse kinematics of the measured flange path stays well determined.
TEST(ShippedPrograms, CampaignHasRestPosesFastMovesAndNoWristSingularity) {
  const DesiredJointPath& path = planned("campaign").path;
  expect_rests_turned_about_all_flange_axes(path, 4.0, 13);
  calib::JointVector peak_speed = calib::JointVector::Zero();
  std::array<int, 6> reversals{};
  std::array<double, 6> last_sign{};
  double lowest_a5 = 1e9, highest_a5 = -1e9;
  for (const DesiredJointSample& s : path.samples) {
    lowest_a5 = std::min(lowest_a5, s.q_rad(4));
    highest_a5 = std::max(highest_a5, s.q_rad(4));
    for (int i = 0; i < 6; ++i) {
      peak_speed(i) = std::max(peak_speed(i), std::abs(s.qd_rad_s(i)));
      if (std::abs(s.qd_rad_s(i)) < 1e-3) continue;
      const double sign = s.qd_rad_s(i) > 0 ? 1.0 : -1.0;
      reversals[std::size_t(i)] += last_sign[std::size_t(i)] == -sign;
      last_sign[std::size_t(i)] = sign;
    }
  }
  // A5 within 45..100 deg everywhere: |sin(A5)| >= 0.7, far from the singular wrist.
  EXPECT_GE(lowest_a5, 45.0 * M_PI / 180.0 - 1e-9);
  EXPECT_LE(highest_a5, 100.0 * M_PI / 180.0 + 1e-9);
  for (int i = 0; i < 6; ++i) {
    // Every joint reverses (identification needs both directions) and, on its longest move,
    // reaches at least a third of its maximum speed (trapezoidal at full velocity).
    EXPECT_GE(reversals[std::size_t(i)], 3) << "A" << i + 1;
    EXPECT_GE(peak_speed(i), robot().joints[std::size_t(i)].max_velocity_rad_s / 3.0)
        << "A" << i + 1;
  }
}

TEST(ShippedPrograms, Iso9283PathSetLiesOnTheCubesDiagonalPlane) {
  const Planned& p = planned("iso9283");
  const DesiredJointPath& path = p.path;
  // Cube: edge 500 mm, centre (1100, 0, 800) mm; plane through the centre with normal
  // (-1, 0, 1)/sqrt2 (from the comment at the top of iso9283.yaml).
  const Eigen::Vector3d centre(1.1, 0.0, 0.8);
  const Eigen::Vector3d normal = Eigen::Vector3d(-1, 0, 1).normalized();
  const double edge = 0.5;
  std::map<std::string, double> peak_speed;
  for (const char* pct : {"100%", "50%", "10%"}) {
    for (const std::string kind : {"line ", "large circle ", "small circle "}) {
      const PathSegment& seg = segment(path, kind + pct);
      const auto [a, b] = range(path, seg);
      // Largest departures over the segment (one assertion each, see above): off the plane,
      // off the circle's radius or off the diagonal. FK of IK solutions: 1e-9 m.
      double peak = 0.0, off_plane = 0.0, off_path = 0.0;
      const Eigen::Vector3d diagonal = Eigen::Vector3d(1, 1, 1).normalized();
      for (std::size_t n = a; n <= b; ++n) {
        const Eigen::Vector3d r = fk(path.samples[n].q_rad).translation() - centre;
        off_plane = std::max(off_plane, std::abs(r.dot(normal)));
        if (kind == "large circle ") {
          off_path = std::max(off_path, std::abs(r.norm() - 0.8 * edge / 2));  // D = 80 % edge
        } else if (kind == "small circle ") {
          off_path = std::max(off_path, std::abs(r.norm() - 0.1 * 0.8 * edge / 2));  // 10 %
        } else {
          // On the diagonal of the plane's rectangle, through the cube centre.
          off_path = std::max(off_path, (r - r.dot(diagonal) * diagonal).norm());
        }
        peak = std::max(peak, path_speed(path.samples[n].q_rad, path.samples[n].qd_rad_s));
      }
      EXPECT_LT(off_plane, 1e-9) << seg.label;
      EXPECT_LT(off_path, 1e-9) << seg.label;
      peak_speed[kind + pct] = peak;
      if (kind == "line ") {
        // Length 80 % of the diagonal (866 mm): P2 and P4 at 10 % from the corners.
        const Eigen::Vector3d d =
            fk(path.samples[b].q_rad).translation() - fk(path.samples[a].q_rad).translation();
        EXPECT_NEAR(d.norm(), 0.8 * std::sqrt(3.0) * edge, 1e-9);
      }
    }
  }
  // 100 %, 50 %, 10 % of the rated 0.5 m/s, programmed and reached by the programmed profile on
  // every path (cruise; stretch < 0.5 %). The planner keeps these speeds (longer ramps) except
  // on the small circle at 100 % and 50 %, whose joints cannot follow them (A3's jerk limit:
  // Iso9283CartesianSegmentsWithinTheJointLimits): there the speed reached is the planned one.
  for (const std::string kind : {"line ", "large circle ", "small circle "}) {
    for (const auto& [pct, speed] : {std::pair{"100%", 0.5}, {"50%", 0.25}, {"10%", 0.05}}) {
      const CartesianTiming& timing = *segment(path, kind + pct).timing;
      EXPECT_NEAR(timing.programmed_peak_velocity_m_s, speed, 5e-3 * speed) << kind << pct;
      EXPECT_NEAR(peak_speed[kind + pct], timing.planned_peak_velocity_m_s, 1e-9) << kind << pct;
      const bool slower = kind == "small circle " && speed > 0.1;
      EXPECT_EQ(peak_speed[kind + pct] < 0.95 * speed, slower) << kind << pct;
      if (!slower) {
        EXPECT_NEAR(peak_speed[kind + pct], speed, 5e-3 * speed) << kind << pct;
      }
    }
  }
}

// Every Cartesian segment of the ISO 9283 program within the joints' acceleration and jerk limits
// (the tests' own measure of the planned samples), and which of them the planner slowed: prints
// per segment the programmed and the planned speed, duration and path limits and the largest
// joint acceleration and jerk ratios before and after.
// Print: build/tests/sim_test_programs --gtest_filter='*Iso9283Cartesian*'
TEST(ShippedPrograms, Iso9283CartesianSegmentsWithinTheJointLimits) {
  const Planned& p = planned("iso9283");
  const DesiredJointPath& path = p.path;
  auto joint = [](int i) { return i < 0 ? std::string("-") : fmt::format("A{}", i + 1); };
  std::printf("%-22s %13s %17s %13s %12s %14s %14s %12s\n", "segment", "speed m/s", "duration s",
              "acc m/s^2", "jerk m/s^3", "joint acc", "joint jerk", "limited by");
  int slowed = 0;
  for (const PathSegment& seg : path.segments) {
    if (seg.kind != SegmentKind::kLinear && seg.kind != SegmentKind::kCircular) continue;
    ASSERT_TRUE(seg.timing.has_value()) << seg.label;
    const CartesianTiming& t = *seg.timing;
    const MeasuredLimitUse use =
        measured_limit_use(path, seg, p.program.max_acceleration_rad_s2, p.program.max_jerk_rad_s3);
    std::string limited_by = "not slowed";
    if (t.slowed) {
      limited_by = joint(t.planned_use.joint());
      limited_by += t.planned_use.jerk_binds() ? " jerk" : " acceleration";
    }
    std::printf(
        "%-22s %5.3f->%5.3f %7.3f->%7.3f %5.2f->%5.2f %5.1f->%4.1f %4.2f->%4.2f %-3s "
        "%5.2f->%4.2f %-3s %s\n",
        seg.label.c_str(), t.programmed_peak_velocity_m_s, t.planned_peak_velocity_m_s,
        t.programmed_duration_s, seg.end_s - seg.begin_s, t.programmed.acceleration,
        t.planned.acceleration, t.programmed.jerk, t.planned.jerk,
        t.programmed_use.acceleration_ratio, use.acceleration,
        joint(use.acceleration_joint).c_str(), t.programmed_use.jerk_ratio, use.jerk,
        joint(use.jerk_joint).c_str(), limited_by.c_str());
    // Within the limits (the planner's tolerance), as the planner recorded it.
    EXPECT_LE(use.acceleration, 1.0 + kJointLimitTolerance) << seg.label;
    EXPECT_LE(use.jerk, 1.0 + kJointLimitTolerance) << seg.label;
    EXPECT_NEAR(use.acceleration, t.planned_use.acceleration_ratio, 1e-12) << seg.label;
    EXPECT_NEAR(use.jerk, t.planned_use.jerk_ratio, 1e-12) << seg.label;
    // Slowed exactly when the programmed timing was beyond a limit; never faster than programmed.
    EXPECT_EQ(t.slowed, t.programmed_use.ratio() > 1.0 + kJointLimitTolerance) << seg.label;
    EXPECT_LE(t.planned.velocity, t.programmed.velocity) << seg.label;
    EXPECT_LE(t.planned.acceleration, t.programmed.acceleration) << seg.label;
    EXPECT_GE(seg.end_s - seg.begin_s, t.programmed_duration_s - 1e-12) << seg.label;
    slowed += t.slowed;
  }
  // Measured: the 12 test paths (lines, circles) are beyond A3's jerk limit as programmed (path
  // jerk 50 m/s^3), the moves between them (10 m/s^3) are not.
  EXPECT_EQ(slowed, 12);
}

}  // namespace
}  // namespace imscal::sim
