// Inverse kinematics: round trips q -> T_R_H(q) (our FK, itself checked against KDL and the URDF)
// -> IK -> q, for the KR 16 (standard DH) and Craig's PUMA 560 (modified DH, lateral offset),
// all 8 configurations, the configuration flags, the failures at singular and unreachable
// poses, and Newton refinement on an arm that departs from the ideal structure.
#include <gtest/gtest.h>

#include <cstdlib>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <random>

#include "core/units.hpp"
#include "robot/forward_kinematics.hpp"
#include "robot/inverse_kinematics.hpp"
#include "robot/robot_description.hpp"
#include "sim/kdl_chain.hpp"

using imscal::calib::ArmConfiguration;
using imscal::calib::DhConvention;
using imscal::calib::IkOptions;
using imscal::calib::IkResult;
using imscal::calib::IkStatus;
using imscal::calib::InverseKinematics;
using imscal::calib::JointVector;
using imscal::calib::KinematicModel;

using imscal::kRadPerDeg;

namespace {

// Away from singularities: wrist centre >= 5 cm from the shoulder singularity, |sin| of the
// elbow and wrist bends >= 0.05 (~3 deg). Closer, the condition number of J grows as 1/measure
// and 1e-10 rad would no longer follow from 1e-16 pose rounding.
constexpr double kAwayFromSingularity = 0.05;

// Fewer samples under sanitizers (5-10x slower); the checks stay the same.
int samples(int normal) {
  return std::getenv("IMSCAL_SANITIZED") ? normal / 5 : normal;
}

KinematicModel kr16() {
  return imscal::calib::load_robot_description(IMSCAL_SOURCE_DIR "/datasets/robots/kr16.yaml")
      .kinematics;
}

// Craig, Introduction to Robotics (3rd ed.), PUMA 560 in modified DH: rows
// (a_{i-1}, alpha_{i-1}, d_i, theta offset); lateral offset d3 = 0.15005 m.
KinematicModel puma560() {
  KinematicModel m;
  m.convention = DhConvention::kModified;
  m.dh[0] = {0, 0, 0, 0};
  m.dh[1] = {0, -M_PI / 2, 0, 0};
  m.dh[2] = {0.4318, 0, 0.15005, 0};
  m.dh[3] = {0.0203, -M_PI / 2, 0.4318, 0};
  m.dh[4] = {0, M_PI / 2, 0, 0};
  m.dh[5] = {0, -M_PI / 2, 0, 0};
  m.T_6_H.translation() << 0, 0, 0.0563;
  m.lower_limit_rad = JointVector::Constant(-M_PI);
  m.upper_limit_rad = JointVector::Constant(M_PI);
  return m;
}

double angle_error(const JointVector& a, const JointVector& b) {
  double worst = 0.0;
  for (int i = 0; i < 6; ++i)
    worst = std::max(worst, std::abs(std::remainder(a(i) - b(i), 2 * M_PI)));
  return worst;
}

bool away_from_singularities(const InverseKinematics& ik, const JointVector& q) {
  const auto m = ik.singularity_measures(q);
  return m.shoulder_m > kAwayFromSingularity && m.elbow > kAwayFromSingularity &&
         m.wrist > kAwayFromSingularity;
}

JointVector random_q_within_limits(const KinematicModel& model, std::mt19937& rng) {
  JointVector q;
  for (int i = 0; i < 6; ++i) {
    std::uniform_real_distribution<double> angle(std::max(model.lower_limit_rad(i), -M_PI),
                                                 std::min(model.upper_limit_rad(i), M_PI));
    q(i) = angle(rng);
  }
  return q;
}

struct RoundTripFigures {
  int poses = 0;
  int solutions = 0;
  double max_error_rad = 0.0;
};

// For random q: its own configuration must give q back; every other configuration that is
// valid and away from singularities must reach the pose, carry its flag, and round-trip itself.
RoundTripFigures round_trips(const KinematicModel& model, int count, unsigned seed) {
  const InverseKinematics ik(model);
  std::mt19937 rng(seed);
  RoundTripFigures figures;
  IkOptions free;  // the 8 solutions of a pose need not all lie within the joint limits
  free.enforce_joint_limits = false;
  while (figures.poses < count) {
    const JointVector q = random_q_within_limits(model, rng);
    if (!away_from_singularities(ik, q)) continue;
    ++figures.poses;
    const Eigen::Isometry3d T_R_H = imscal::calib::forward_kinematics<double>(model, q);
    IkOptions near = free;
    near.q_near = q;
    const IkResult own = ik.solve(T_R_H, ik.configuration_of(q), near);
    EXPECT_TRUE(own.ok()) << own.reason;
    figures.max_error_rad = std::max(figures.max_error_rad, angle_error(own.q, q));

    const std::vector<IkResult> all = ik.solve_all(T_R_H, free);
    const auto configurations = InverseKinematics::all_configurations();
    for (std::size_t k = 0; k < all.size(); ++k) {
      if (!all[k].ok()) {
        // Only a genuine reason may refuse a configuration of a reachable pose: a singular
        // branch of it (e.g. the flipped arm's elbow cannot reach) or no convergence never.
        EXPECT_NE(all[k].status, IkStatus::kNotConverged) << all[k].reason;
        continue;
      }
      const JointVector& qk = all[k].q;
      EXPECT_EQ(ik.configuration_of(qk), configurations[k]) << to_string(configurations[k]);
      const Eigen::Isometry3d reached = imscal::calib::forward_kinematics<double>(model, qk);
      // Newton stops below 1e-12 m / rad (IkOptions defaults).
      EXPECT_LT((reached.translation() - T_R_H.translation()).norm(), 1e-12);
      EXPECT_LT(Eigen::AngleAxisd(reached.linear().transpose() * T_R_H.linear()).angle(), 1e-12);
      if (!away_from_singularities(ik, qk)) continue;
      IkOptions near_k = free;
      near_k.q_near = qk;
      const IkResult again = ik.solve(reached, configurations[k], near_k);
      EXPECT_TRUE(again.ok()) << again.reason;
      figures.max_error_rad = std::max(figures.max_error_rad, angle_error(again.q, qk));
      ++figures.solutions;
    }
  }
  return figures;
}

}  // namespace

TEST(InverseKinematics, Kr16RoundTripsInAllEightConfigurations) {
  const RoundTripFigures f = round_trips(kr16(), samples(500), 17);
  // 1e-10 rad is the requirement; away from singularities the closed form plus Newton
  // reach rounding level (~1e-15 rad).
  EXPECT_LT(f.max_error_rad, 1e-10);
  EXPECT_GT(f.solutions, f.poses * 4);  // most poses have >= 4 valid non-singular branches
  std::printf("KR16: %d poses, %d further solutions, max round-trip error %.3g rad\n", f.poses,
              f.solutions, f.max_error_rad);
}

TEST(InverseKinematics, Kr16InvertsKdlsForwardKinematics) {
  // Target poses from KDL's forward kinematics (an implementation independent of ours).
  const imscal::calib::RobotDescription robot =
      imscal::calib::load_robot_description(IMSCAL_SOURCE_DIR "/datasets/robots/kr16.yaml");
  KDL::Chain chain = imscal::sim::build_kdl_chain(robot);
  KDL::ChainFkSolverPos_recursive fk(chain);
  const InverseKinematics ik(robot.kinematics);
  std::mt19937 rng(41);
  double max_error = 0.0;
  for (int n = 0; n < samples(300);) {
    const JointVector q = random_q_within_limits(robot.kinematics, rng);
    if (!away_from_singularities(ik, q)) continue;
    ++n;
    KDL::JntArray q_kdl(6);
    for (int i = 0; i < 6; ++i) q_kdl(i) = q(i);
    KDL::Frame frame;
    ASSERT_GE(fk.JntToCart(q_kdl, frame), 0);
    Eigen::Isometry3d T_R_H = Eigen::Isometry3d::Identity();
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) T_R_H.linear()(r, c) = frame.M(r, c);
      T_R_H.translation()(r) = frame.p(r);
    }
    IkOptions near;
    near.q_near = q;
    const IkResult r = ik.solve(T_R_H, ik.configuration_of(q), near);
    ASSERT_TRUE(r.ok()) << r.reason;
    max_error = std::max(max_error, angle_error(r.q, q));
  }
  EXPECT_LT(max_error, 1e-10);  // as in the round trips
  std::printf("KR16 from KDL poses: max error %.3g rad\n", max_error);
}

TEST(InverseKinematics, Puma560ModifiedDhWithLateralOffsetRoundTrips) {
  const RoundTripFigures f = round_trips(puma560(), samples(300), 23);
  EXPECT_LT(f.max_error_rad, 1e-10);  // as above
  EXPECT_GT(f.solutions, f.poses * 4);
  std::printf("PUMA 560: %d poses, %d further solutions, max round-trip error %.3g rad\n", f.poses,
              f.solutions, f.max_error_rad);
}

TEST(InverseKinematics, Kr16FlagsMatchThePhysicalPose) {
  const InverseKinematics ik(kr16());
  // Home pose with a bent wrist: shoulder front (wrist centre in front of A1), elbow up
  // (the elbow is above the shoulder-wrist line), A5 > 0: no flip.
  JointVector q;
  q << 0, -90 * kRadPerDeg, 90 * kRadPerDeg, 0, 30 * kRadPerDeg, 0;
  EXPECT_EQ(ik.configuration_of(q), (ArmConfiguration{true, true, false}));
  q(4) = -30 * kRadPerDeg;  // A5 < 0: flipped wrist
  EXPECT_EQ(ik.configuration_of(q), (ArmConfiguration{true, true, true}));
  q(2) = -10 * kRadPerDeg;  // forearm bent upwards past the stretched position: elbow down
  EXPECT_EQ(ik.configuration_of(q), (ArmConfiguration{true, false, true}));
  q << 0, -90 * kRadPerDeg, 90 * kRadPerDeg, 0, 30 * kRadPerDeg, 0;
  q(1) = -150 * kRadPerDeg;  // upper arm leaning back 60 deg past vertical and the forearm
  q(2) = 30 * kRadPerDeg;    // pointing up and back: wrist centre behind A1
  EXPECT_FALSE(ik.configuration_of(q).shoulder_front);
}

TEST(InverseKinematics, Kr16StatedReachIsTheStretchedWristCentre) {
  // Upper arm horizontal (A2 = 0) and the forearm's wrist centre on its line: the wrist centre
  // is a1 + a2 + sqrt(0.67^2 + 0.035^2) = 1.6109 m from axis 1; the file states 1.611 m.
  const imscal::calib::RobotDescription robot =
      imscal::calib::load_robot_description(IMSCAL_SOURCE_DIR "/datasets/robots/kr16.yaml");
  const InverseKinematics ik(robot.kinematics);
  JointVector q = JointVector::Zero();
  q(2) = -std::atan2(0.035, 0.67);
  const Eigen::Vector3d wrist =
      imscal::calib::forward_kinematics<double>(robot.kinematics, q) * ik.wrist_centre_H();
  EXPECT_NEAR(wrist.head<2>().norm(), robot.reach_m, 5e-4);  // the file rounds to 1 mm
}

TEST(InverseKinematics, Kr16WristCentreIsTheUrdfWristPoint) {
  // URDF: axes 4, 5, 6 meet 0.158 m behind the flange face, on the flange z axis.
  const InverseKinematics ik(kr16());
  EXPECT_LT((ik.wrist_centre_H() - Eigen::Vector3d(0, 0, -0.158)).norm(), 1e-14);
}

TEST(InverseKinematics, FailsClearlyAtUnreachableAndSingularPoses) {
  const KinematicModel model = kr16();
  const InverseKinematics ik(model);
  const ArmConfiguration front_up{true, true, false};
  JointVector q;
  q << 0.3, -70 * kRadPerDeg, 100 * kRadPerDeg, 0.5, 40 * kRadPerDeg, 0.2;
  const Eigen::Isometry3d reachable = imscal::calib::forward_kinematics<double>(model, q);

  Eigen::Isometry3d far = reachable;
  far.translation() += Eigen::Vector3d(2.0, 0, 0);
  IkResult r = ik.solve(far, front_up);
  EXPECT_EQ(r.status, IkStatus::kUnreachable);
  EXPECT_NE(r.reason.find("reach"), std::string::npos) << r.reason;

  JointVector wrist_straight = q;
  wrist_straight(4) = 0.0;  // A5 = 0: axes 4 and 6 aligned
  r = ik.solve(imscal::calib::forward_kinematics<double>(model, wrist_straight), front_up);
  EXPECT_EQ(r.status, IkStatus::kWristSingular) << r.reason;

  JointVector stretched = q;
  stretched(2) = -std::atan2(0.035, 0.67);  // wrist centre on the upper arm's line
  r = ik.solve(imscal::calib::forward_kinematics<double>(model, stretched), front_up);
  EXPECT_EQ(r.status, IkStatus::kElbowSingular) << r.reason;

  // Wrist centre on axis 1 (above the base): any A1 angle would do.
  Eigen::Isometry3d over_axis_1 = reachable;
  over_axis_1.translation() =
      Eigen::Vector3d(0, 0, 1.5) - over_axis_1.linear() * ik.wrist_centre_H();
  r = ik.solve(over_axis_1, front_up);
  EXPECT_EQ(r.status, IkStatus::kShoulderSingular) << r.reason;
  EXPECT_FALSE(r.reason.empty());
}

// The measured flange pose just across the wrist singularity from the encoders' reading (A5
// = +2 mrad on the encoders, -1 mrad in the pose, as an IMS pose error of a few microradians
// can make it): the encoders' own wrist branch is a different physical pose, A4 and A6 turned
// by ~pi; solve_nearest takes the other branch, which is the pose's true joint angles.
TEST(InverseKinematics, SolveNearestStaysOnThePhysicalBranchAcrossTheWristSingularity) {
  const KinematicModel model = kr16();
  const InverseKinematics ik(model);
  JointVector q_true, q_encoders;
  q_true << 0.3, -70 * kRadPerDeg, 100 * kRadPerDeg, 0.5, -1e-3, 0.2;
  q_encoders = q_true;
  q_encoders(4) = 2e-3;
  const Eigen::Isometry3d pose = imscal::calib::forward_kinematics<double>(model, q_true);
  IkOptions options;
  options.q_near = q_encoders;
  const IkResult own_branch = ik.solve(pose, ik.configuration_of(q_encoders), options);
  ASSERT_TRUE(own_branch.ok()) << own_branch.reason;
  EXPECT_GT((own_branch.q - q_true).cwiseAbs().maxCoeff(), 1.0) << "A4/A6 flipped by ~pi";
  const IkResult nearest = ik.solve_nearest(pose, q_encoders);
  ASSERT_TRUE(nearest.ok()) << nearest.reason;
  // 1e-9 rad: the pose is exact, but the wrist bend of 1 mrad amplifies rounding ~1e3 times.
  EXPECT_LT((nearest.q - q_true).cwiseAbs().maxCoeff(), 1e-9);
  // Away from the singularity both give the same, the encoders' branch.
  q_true(4) = q_encoders(4) = 40 * kRadPerDeg;
  const Eigen::Isometry3d away = imscal::calib::forward_kinematics<double>(model, q_true);
  EXPECT_LT((ik.solve_nearest(away, q_encoders).q - q_true).cwiseAbs().maxCoeff(), 1e-10);
}

TEST(InverseKinematics, ReportsPosesOutsideTheJointLimits) {
  const KinematicModel model = kr16();
  const InverseKinematics ik(model);
  JointVector q;
  q << 0.3, 60 * kRadPerDeg, 40 * kRadPerDeg, 0.5, 40 * kRadPerDeg,
      0.2;  // A2 = +60 deg > its +35 deg limit
  const Eigen::Isometry3d T_R_H = imscal::calib::forward_kinematics<double>(model, q);
  const IkResult limited = ik.solve(T_R_H, ik.configuration_of(q));
  EXPECT_EQ(limited.status, IkStatus::kOutsideJointLimits);
  EXPECT_NE(limited.reason.find("q2"), std::string::npos) << limited.reason;
  IkOptions free;
  free.enforce_joint_limits = false;
  const IkResult unlimited = ik.solve(T_R_H, ik.configuration_of(q), free);
  ASSERT_TRUE(unlimited.ok()) << unlimited.reason;
  EXPECT_LT(angle_error(unlimited.q, q), 1e-10);  // as in the round trips
}

TEST(InverseKinematics, NewtonRefinementAbsorbsSmallStructuralErrors) {
  // A "calibrated" KR 16: axis 3 tilted by 2 mrad against axis 2, a 1 mm wrist offset, joint
  // offsets of ~1 mrad. The closed form is then only a start; Newton must finish the job.
  KinematicModel model = kr16();
  model.dh[1].alpha_rad += 2e-3;
  model.dh[4].a_m += 1e-3;
  model.dh[0].offset_rad += 1e-3;
  model.dh[2].offset_rad -= 8e-4;
  const InverseKinematics ik(model);
  std::mt19937 rng(31);
  double max_error = 0.0;
  int max_iterations = 0;
  for (int n = 0; n < samples(200);) {
    const JointVector q = random_q_within_limits(model, rng);
    if (!away_from_singularities(ik, q)) continue;
    ++n;
    IkOptions near;
    near.q_near = q;
    const IkResult r =
        ik.solve(imscal::calib::forward_kinematics<double>(model, q), ik.configuration_of(q), near);
    ASSERT_TRUE(r.ok()) << r.reason;
    max_error = std::max(max_error, angle_error(r.q, q));
    max_iterations = std::max(max_iterations, r.newton_iterations);
  }
  EXPECT_LT(max_error, 1e-10);   // as in the round trips
  EXPECT_GE(max_iterations, 2);  // the closed form alone is not exact here: Newton did work
  std::printf("perturbed KR16: max error %.3g rad, at most %d Newton steps\n", max_error,
              max_iterations);
}

TEST(InverseKinematics, RefusesArmsOutsideItsClass) {
  KinematicModel model = kr16();
  model.dh[3].a_m = 0.1;  // axis 4 no longer meets axis 5: not a spherical wrist
  EXPECT_THROW(InverseKinematics{model}, std::invalid_argument);
  model = kr16();
  model.dh[1].alpha_rad = 0.3;  // axis 3 not parallel to axis 2
  EXPECT_THROW(InverseKinematics{model}, std::invalid_argument);
}
