// Inverse kinematics of the UR class (robot/ur_inverse_kinematics.hpp) on the UR10 and UR10e
// URDFs: round trips q -> T_R_H(q) -> IK -> q over all 8 configurations, agreement with KDL's
// numeric ChainIkSolverPos_LMA built straight from the URDF's joints (not from our DH model),
// every failure status at a pose built to cause it, Newton on a calibrated (non-ideal) arm, and
// the factory's choice of solver by structure.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <kdl/chain.hpp>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainiksolverpos_lma.hpp>
#include <random>

#include "robot/forward_kinematics.hpp"
#include "robot/inverse_kinematics.hpp"
#include "robot/robot_description.hpp"
#include "robot/ur_inverse_kinematics.hpp"
#include "robot/urdf_robot.hpp"
#include "sim/kdl_chain.hpp"

namespace imscal::calib {
namespace {

const std::filesystem::path kRobots = std::filesystem::path(IMSCAL_SOURCE_DIR) / "datasets/robots";

// Away from singularities: wrist point >= 5 cm from the shoulder cylinder, |sin| of the elbow and
// wrist bends >= 0.05. Closer, J's condition number grows as 1 / measure and 1e-10 rad would no
// longer follow from 1e-16 pose rounding.
constexpr double kAway = 0.05;

// Fewer samples under sanitizers (5-10x slower); the checks stay the same.
int samples(int normal) {
  return std::getenv("IMSCAL_SANITIZED") ? normal / 5 : normal;
}

KinematicModel ur(const char* file) {
  return load_robot_description(kRobots / file).kinematics;
}

double angle_error(const JointVector& a, const JointVector& b) {
  double worst = 0.0;
  for (int i = 0; i < 6; ++i) {
    worst = std::max(worst, std::abs(std::remainder(a(i) - b(i), 2 * M_PI)));
  }
  return worst;
}

bool away(const IkSolver& ik, const JointVector& q) {
  const SingularityMeasures m = ik.singularity_measures(q);
  return m.shoulder_m > kAway && m.elbow > kAway && m.wrist > kAway;
}

JointVector random_q(std::mt19937& rng) {
  std::uniform_real_distribution<double> angle(-M_PI, M_PI);
  JointVector q;
  for (int i = 0; i < 6; ++i) q(i) = angle(rng);
  return q;
}

double pose_angle(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle();
}

class UrRoundTrip : public ::testing::TestWithParam<const char*> {};

// Random q: its own configuration gives q back; every other configuration that solves reaches
// the pose, carries its flag, and (away from singularities) round-trips itself.
TEST_P(UrRoundTrip, AllEightConfigurations) {
  const KinematicModel model = ur(GetParam());
  const UrInverseKinematics ik(model);
  std::mt19937 rng(23);
  IkOptions free;  // the 8 solutions of a pose need not lie within the joint limits
  free.enforce_joint_limits = false;
  int poses = 0, solutions = 0;
  std::array<int, 8> per_configuration{};
  double max_error_rad = 0.0;
  const auto configurations = IkSolver::all_configurations();
  while (poses < samples(500)) {
    const JointVector q = random_q(rng);
    if (!away(ik, q)) continue;
    ++poses;
    const Eigen::Isometry3d T_R_H = forward_kinematics<double>(model, q);
    const IkResult own = ik.solve(T_R_H, ik.configuration_of(q), free);
    EXPECT_TRUE(own.ok()) << own.reason;
    max_error_rad = std::max(max_error_rad, angle_error(own.q, q));
    const std::vector<IkResult> all = ik.solve_all(T_R_H, free);
    for (std::size_t k = 0; k < all.size(); ++k) {
      if (!all[k].ok()) {
        // Only a genuine reason may refuse a branch of a reachable pose, never no convergence.
        EXPECT_NE(all[k].status, IkStatus::kNotConverged) << all[k].reason;
        continue;
      }
      const JointVector& qk = all[k].q;
      EXPECT_EQ(ik.configuration_of(qk), configurations[k]) << to_string(configurations[k]);
      const Eigen::Isometry3d reached = forward_kinematics<double>(model, qk);
      // Newton stops below 1e-12 m / rad (IkOptions defaults).
      EXPECT_LT((reached.translation() - T_R_H.translation()).norm(), 1e-12);
      EXPECT_LT(pose_angle(reached, T_R_H), 1e-12);
      if (!away(ik, qk)) continue;
      const IkResult again = ik.solve(reached, configurations[k], free);
      EXPECT_TRUE(again.ok()) << again.reason;
      max_error_rad = std::max(max_error_rad, angle_error(again.q, qk));
      ++solutions;
      ++per_configuration[k];
    }
  }
  // 1e-10 rad: pose rounding (1e-16) times the condition number away from singularities.
  EXPECT_LT(max_error_rad, 1e-10);
  for (int count : per_configuration) EXPECT_GT(count, poses / 10) << "every branch is exercised";
  std::printf("%s: %d poses, %d other-branch solutions, max joint error %.3g rad\n", GetParam(),
              poses, solutions, max_error_rad);
}

// KDL's chain built from the URDF's joint origins and axes (independent of our DH conversion).
KDL::Chain urdf_kdl_chain(const std::filesystem::path& urdf) {
  const UrdfChain chain = read_urdf_chain(urdf, "", "tool0");
  KDL::Chain out;
  out.addSegment(
      KDL::Segment("origin", KDL::Joint(KDL::Joint::None), sim::to_kdl_frame(chain.fixed[0])));
  for (int i = 0; i < kJointCount; ++i) {
    const Eigen::Vector3d& a = chain.axis[i];
    out.addSegment(KDL::Segment(chain.joint_names[i],
                                KDL::Joint(chain.joint_names[i], KDL::Vector::Zero(),
                                           KDL::Vector(a.x(), a.y(), a.z()), KDL::Joint::RotAxis),
                                sim::to_kdl_frame(chain.fixed[i + 1])));
  }
  return out;
}

// Same pose, two solvers: KDL's Levenberg-Marquardt from a start 0.1 rad off, ours in the
// configuration KDL lands in. KDL's rotation difference (Rotation::GetRot: acos with a 1e-6
// epsilon) sees no error below a few 1e-7 rad, so LMA stops up to ~7e-7 rad off the target
// orientation (measured with our FK, equal to KDL's to 1e-16); through J^-1 at >= 0.05 from the
// singularities that is up to ~2e-5 rad in the joints (measured 1.4e-5). Hence 5e-5 rad, and
// ours, at 1e-12, must be the closer one.
TEST_P(UrRoundTrip, AgreesWithKdlLma) {
  const std::filesystem::path urdf = kRobots / GetParam();
  const KinematicModel model = ur(GetParam());
  const UrInverseKinematics ik(model);
  const KDL::Chain chain = urdf_kdl_chain(urdf);
  KDL::ChainFkSolverPos_recursive kdl_fk(chain);
  // Orientation weighted like position; eps bounds the squared weighted error (1e-24: 1e-12).
  const Eigen::Matrix<double, 6, 1> weights = Eigen::Matrix<double, 6, 1>::Ones();
  KDL::ChainIkSolverPos_LMA kdl_ik(chain, weights, 1e-24, 200, 1e-16);
  std::mt19937 rng(5);
  std::normal_distribution<double> start_noise(0.0, 0.1);
  int compared = 0;
  double worst_rad = 0.0, worst_lma_rad = 0.0, worst_ours_rad = 0.0;
  while (compared < samples(100)) {
    const JointVector q = random_q(rng);
    if (!away(ik, q)) continue;
    KDL::JntArray q_kdl(6), start(6), solution(6);
    for (int i = 0; i < 6; ++i) {
      q_kdl(i) = q(i);
      start(i) = q(i) + start_noise(rng);
    }
    KDL::Frame pose_kdl;
    ASSERT_GE(kdl_fk.JntToCart(q_kdl, pose_kdl), 0);
    if (kdl_ik.CartToJnt(start, pose_kdl, solution) < 0) continue;  // LMA may stall; skip
    ++compared;
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    for (int r = 0; r < 3; ++r) {
      pose.translation()(r) = pose_kdl.p(r);
      for (int c = 0; c < 3; ++c) pose.linear()(r, c) = pose_kdl.M(r, c);
    }
    JointVector q_lma;
    for (int i = 0; i < 6; ++i) q_lma(i) = solution(i);
    IkOptions free;
    free.enforce_joint_limits = false;
    const IkResult ours = ik.solve(pose, ik.configuration_of(q_lma), free);
    ASSERT_TRUE(ours.ok()) << ours.reason;
    worst_rad = std::max(worst_rad, angle_error(ours.q, q_lma));
    const double lma_rad = pose_angle(forward_kinematics<double>(model, q_lma), pose);
    const double ours_rad = pose_angle(forward_kinematics<double>(model, ours.q), pose);
    EXPECT_LE(ours_rad, lma_rad + 1e-12) << "ours is the closer solution";
    worst_lma_rad = std::max(worst_lma_rad, lma_rad);
    worst_ours_rad = std::max(worst_ours_rad, ours_rad);
  }
  EXPECT_LT(worst_rad, 5e-5);
  std::printf(
      "%s: %d poses, max |q_ours - q_LMA| %.3g rad; orientation error LMA %.3g, ours %.3g rad\n",
      GetParam(), compared, worst_rad, worst_lma_rad, worst_ours_rad);
}

INSTANTIATE_TEST_SUITE_P(UrUrdfs, UrRoundTrip, ::testing::Values("ur10.urdf", "ur10e.urdf"));

JointVector reachable_q() {
  JointVector q;
  q << 0.4, -1.1, 1.3, -0.9, 1.2, 0.3;
  return q;
}

TEST(UrInverseKinematics, ReportsEveryFailure) {
  const KinematicModel model = ur("ur10e.urdf");
  const UrInverseKinematics ik(model);
  const JointVector q = reachable_q();
  const ArmConfiguration configuration = ik.configuration_of(q);
  const Eigen::Isometry3d reachable = forward_kinematics<double>(model, q);
  ASSERT_TRUE(ik.solve(reachable, configuration).ok());

  Eigen::Isometry3d far = reachable;
  far.translation() += Eigen::Vector3d(2.0, 0, 0);
  IkResult r = ik.solve(far, configuration);
  EXPECT_EQ(r.status, IkStatus::kUnreachable);
  EXPECT_NE(r.reason.find("reach"), std::string::npos) << r.reason;

  // Wrist point moved onto the cylinder of radius |c| about axis 1 (the base z axis): there
  // its lateral distance from the singular cylinder, sqrt(r^2 - c^2), is 0. The URDF states
  // pi/2 to 9 digits, so c varies by ~6e-11 m with q and the built pose lands ~4e-6 m (sqrt(2 c
  // 6e-11)) from the cylinder: a tolerance of 1e-4 m (the planner uses 1e-2) catches it.
  const Eigen::Vector3d wrist = reachable * ik.wrist_point_H();
  const double lateral = ik.singularity_measures(q).shoulder_m;
  const Eigen::Vector3d radial(wrist.x(), wrist.y(), 0.0);
  const double offset = std::sqrt(radial.squaredNorm() - lateral * lateral);
  Eigen::Isometry3d shoulder = reachable;
  shoulder.translation() += radial.normalized() * offset - radial;
  IkOptions coarse;
  coarse.singularity_tolerance = 1e-4;
  r = ik.solve(shoulder, configuration, coarse);
  EXPECT_EQ(r.status, IkStatus::kShoulderSingular) << r.reason;

  JointVector stretched = q;
  stretched(2) = 0.0;  // UR zero elbow: upper arm and forearm in line
  ASSERT_LT(ik.singularity_measures(stretched).elbow, 1e-12);
  r = ik.solve(forward_kinematics<double>(model, stretched), configuration);
  EXPECT_EQ(r.status, IkStatus::kElbowSingular) << r.reason;

  JointVector wrist_straight = q;
  wrist_straight(4) = ik.wrist_singular_q5_rad();  // axis 6 parallel to axes 2..4
  r = ik.solve(forward_kinematics<double>(model, wrist_straight), configuration);
  EXPECT_EQ(r.status, IkStatus::kWristSingular) << r.reason;

  KinematicModel narrow = model;
  narrow.lower_limit_rad(0) = -0.2;  // q1 = 0.4 rad is outside
  narrow.upper_limit_rad(0) = 0.2;
  r = UrInverseKinematics(narrow).solve(reachable, configuration);
  EXPECT_EQ(r.status, IkStatus::kOutsideJointLimits);
  EXPECT_NE(r.reason.find("q1"), std::string::npos) << r.reason;

  KinematicModel calibrated = model;  // non-ideal: the closed form alone is not exact
  calibrated.dh[1].alpha_rad += 2e-3;
  IkOptions no_newton;
  no_newton.max_newton_iterations = 0;
  r = UrInverseKinematics(calibrated)
          .solve(forward_kinematics<double>(calibrated, q), configuration, no_newton);
  EXPECT_EQ(r.status, IkStatus::kNotConverged);
  EXPECT_NE(r.reason.find("Newton"), std::string::npos) << r.reason;
}

TEST(UrInverseKinematics, NewtonAbsorbsCalibratedDhDeviations) {
  // A "calibrated" UR10e: axis 3 tilted 2 mrad against axis 2, axes 5/6 missing each other by
  // 1 mm, joint offsets of ~1 mrad.
  KinematicModel model = ur("ur10e.urdf");
  model.dh[1].alpha_rad += 2e-3;
  model.dh[4].a_m += 1e-3;
  model.dh[0].offset_rad += 1e-3;
  model.dh[2].offset_rad -= 8e-4;
  const UrInverseKinematics ik(model);
  std::mt19937 rng(31);
  double max_error = 0.0;
  int max_iterations = 0;
  for (int n = 0; n < samples(200);) {
    const JointVector q = random_q(rng);
    if (!away(ik, q)) continue;
    ++n;
    IkOptions near;
    near.q_near = q;
    near.enforce_joint_limits = false;
    const IkResult r = ik.solve(forward_kinematics<double>(model, q), ik.configuration_of(q), near);
    ASSERT_TRUE(r.ok()) << r.reason;
    max_error = std::max(max_error, angle_error(r.q, q));
    max_iterations = std::max(max_iterations, r.newton_iterations);
  }
  EXPECT_LT(max_error, 1e-10);   // as in the round trips
  EXPECT_GE(max_iterations, 2);  // Newton did work
  std::printf("perturbed UR10e: max error %.3g rad, at most %d Newton steps\n", max_error,
              max_iterations);
}

TEST(UrInverseKinematics, EachSolverRefusesTheOtherClassAndTheFactoryPicks) {
  const KinematicModel kr16 = load_robot_description(kRobots / "kr16.yaml").kinematics;
  const KinematicModel ur10 = ur("ur10.urdf");
  EXPECT_THROW(UrInverseKinematics{kr16}, std::invalid_argument);
  EXPECT_THROW(InverseKinematics{ur10}, std::invalid_argument);
  EXPECT_STREQ(make_inverse_kinematics(kr16)->structure(), "spherical wrist");
  EXPECT_STREQ(make_inverse_kinematics(ur10)->structure(), "UR class");
  EXPECT_STREQ(make_inverse_kinematics(ur("ur10e.urdf"))->structure(), "UR class");
  KinematicModel neither = ur10;
  neither.dh[1].alpha_rad = 0.3;  // axis 3 no longer parallel to axis 2
  try {
    make_inverse_kinematics(neither);
    ADD_FAILURE() << "no throw";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("spherical-wrist"), std::string::npos) << what;
    EXPECT_NE(what.find("UR class"), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace imscal::calib
