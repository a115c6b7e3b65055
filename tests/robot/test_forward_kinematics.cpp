// Forward kinematics and the geometric Jacobian against independent truths:
// - Orocos KDL (its own DH formulas, Frame::DH and Frame::DH_Craig1989, its own FK and Jacobian
//   solvers) on the KR 16 description and on random standard and modified DH arms;
// - a hand-computed pose of the KR 16 (KUKA home position);
// - the derivative of the FK instantiated with ceres::Jet (automatic differentiation) against
//   the geometric Jacobian.
#include <ceres/jet.h>
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainjnttojacsolver.hpp>
#include <random>

#include "core/units.hpp"
#include "robot/forward_kinematics.hpp"
#include "robot/jacobian.hpp"
#include "robot/robot_description.hpp"
#include "sim/kdl_chain.hpp"

using imscal::kRadPerDeg;
using imscal::calib::DhConvention;
using imscal::calib::JointVector;
using imscal::calib::RobotDescription;

namespace {

RobotDescription kr16() {
  return imscal::calib::load_robot_description(IMSCAL_SOURCE_DIR "/datasets/robots/kr16.yaml");
}

KDL::JntArray to_kdl(const JointVector& q) {
  KDL::JntArray out(6);
  for (int i = 0; i < 6; ++i) out(i) = q(i);
  return out;
}

JointVector random_q(std::mt19937& rng) {
  std::uniform_real_distribution<double> angle(-M_PI, M_PI);
  JointVector q;
  for (int i = 0; i < 6; ++i) q(i) = angle(rng);
  return q;
}

// An arbitrary 6R arm (no special structure) in the given convention.
RobotDescription random_arm(DhConvention convention, std::mt19937& rng) {
  std::uniform_real_distribution<double> length(-0.8, 0.8);
  std::uniform_real_distribution<double> angle(-M_PI, M_PI);
  RobotDescription robot;
  robot.kinematics.convention = convention;
  robot.kinematics.T_R_0 = imscal::calib::pose_from_xyz_rpy({length(rng), length(rng), length(rng)},
                                                            {angle(rng), angle(rng), angle(rng)});
  robot.kinematics.T_6_H = imscal::calib::pose_from_xyz_rpy({length(rng), length(rng), length(rng)},
                                                            {angle(rng), angle(rng), angle(rng)});
  for (int i = 0; i < 6; ++i) {
    robot.kinematics.dh[i] = {length(rng), angle(rng), length(rng), angle(rng)};
    robot.joints[i].name = fmt::format("J{}", i + 1);
  }
  return robot;
}

struct Differences {
  double pose = 0.0;
  double jacobian = 0.0;
};

// Largest element-wise differences of T_R_H and of the Jacobian between ours and KDL's.
Differences compare_with_kdl(const RobotDescription& robot, int samples, std::mt19937& rng) {
  KDL::Chain chain = imscal::sim::build_kdl_chain(robot);
  KDL::ChainFkSolverPos_recursive fk(chain);
  KDL::ChainJntToJacSolver jac(chain);
  Differences max;
  for (int n = 0; n < samples; ++n) {
    const JointVector q = random_q(rng);
    KDL::Frame frame;
    KDL::Jacobian kdl_jacobian(6);
    EXPECT_GE(fk.JntToCart(to_kdl(q), frame), 0);
    EXPECT_GE(jac.JntToJac(to_kdl(q), kdl_jacobian), 0);
    const Eigen::Isometry3d pose = imscal::calib::forward_kinematics<double>(robot.kinematics, q);
    const imscal::calib::Jacobian jacobian = imscal::calib::geometric_jacobian(robot.kinematics, q);
    for (int r = 0; r < 3; ++r) {
      max.pose = std::max(max.pose, std::abs(pose.translation()(r) - frame.p(r)));
      for (int c = 0; c < 3; ++c) {
        max.pose = std::max(max.pose, std::abs(pose.linear()(r, c) - frame.M(r, c)));
      }
    }
    max.jacobian = std::max(max.jacobian, (jacobian - kdl_jacobian.data).cwiseAbs().maxCoeff());
  }
  return max;
}

}  // namespace

TEST(ForwardKinematics, Kr16AgreesWithKdlOver1000Configurations) {
  std::mt19937 rng(2024);
  const Differences max = compare_with_kdl(kr16(), 1000, rng);
  // Both sides multiply 8 transforms of lengths <= 0.7 m: rounding is a few 1e-16 m; the
  // issue's requirement is 1e-12.
  EXPECT_LT(max.pose, 1e-12);
  EXPECT_LT(max.jacobian, 1e-12);
  std::printf("KR16 vs KDL over 1000 q: max |dT_R_H| %.3g, max |dJ| %.3g\n", max.pose,
              max.jacobian);
}

TEST(ForwardKinematics, RandomStandardAndModifiedDhArmsAgreeWithKdl) {
  std::mt19937 rng(99);
  for (DhConvention convention : {DhConvention::kStandard, DhConvention::kModified}) {
    for (int arm = 0; arm < 5; ++arm) {
      const Differences max = compare_with_kdl(random_arm(convention, rng), 100, rng);
      EXPECT_LT(max.pose, 1e-12) << "arm " << arm;  // rounding only, as above
      EXPECT_LT(max.jacobian, 1e-12) << "arm " << arm;
    }
  }
}

TEST(ForwardKinematics, Kr16HomePoseByHand) {
  // KUKA home A2 = -90, A3 = +90 deg: upper arm vertical from the shoulder (0.26, 0, 0.675),
  // elbow at height 0.675 + 0.68, forearm horizontal forward 0.67 m and 0.035 m below it,
  // flange 0.158 m further, facing forward (z_H = x_R, x_H = -z_R).
  JointVector q;
  q << 0, -90 * kRadPerDeg, 90 * kRadPerDeg, 0, 0, 0;
  const Eigen::Isometry3d T_R_H = imscal::calib::forward_kinematics<double>(kr16().kinematics, q);
  const Eigen::Vector3d expected_position(0.26 + 0.67 + 0.158, 0, 0.675 + 0.68 - 0.035);
  EXPECT_LT((T_R_H.translation() - expected_position).norm(), 1e-14);  // rounding of sin(pi/2)
  EXPECT_LT((T_R_H.linear().col(2) - Eigen::Vector3d::UnitX()).norm(), 1e-14);
  EXPECT_LT((T_R_H.linear().col(0) + Eigen::Vector3d::UnitZ()).norm(), 1e-14);
}

TEST(ForwardKinematics, JetDerivativeEqualsTheGeometricJacobian) {
  using Jet = ceres::Jet<double, 6>;
  const RobotDescription robot = kr16();
  std::mt19937 rng(5);
  double max_difference = 0.0;
  for (int n = 0; n < 100; ++n) {
    const JointVector q = random_q(rng);
    Eigen::Matrix<Jet, 6, 1> q_jet;
    for (int i = 0; i < 6; ++i) q_jet(i) = Jet(q(i), i);
    const imscal::calib::Isometry3<Jet> pose =
        imscal::calib::forward_kinematics(robot.kinematics, q_jet.data());
    const imscal::calib::Jacobian jacobian = imscal::calib::geometric_jacobian(robot.kinematics, q);
    Eigen::Matrix3d rotation;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) rotation(r, c) = pose.linear()(r, c).a;
    }
    for (int i = 0; i < 6; ++i) {
      // Linear part: d p / d q_i. Angular part: (d R / d q_i) R^T = [w_i]x.
      Eigen::Vector3d dp;
      Eigen::Matrix3d dR;
      for (int r = 0; r < 3; ++r) {
        dp(r) = pose.translation()(r).v(i);
        for (int c = 0; c < 3; ++c) dR(r, c) = pose.linear()(r, c).v(i);
      }
      const Eigen::Matrix3d w_skew = dR * rotation.transpose();
      const Eigen::Vector3d w(w_skew(2, 1), w_skew(0, 2), w_skew(1, 0));
      max_difference = std::max(max_difference, (dp - jacobian.block<3, 1>(0, i)).norm());
      max_difference = std::max(max_difference, (w - jacobian.block<3, 1>(3, i)).norm());
      // The skew part must be exactly skew (R stays a rotation): symmetric part ~ rounding.
      EXPECT_LT((w_skew + w_skew.transpose()).norm(), 1e-13);
    }
  }
  // Two exact derivatives evaluated in floating point: they differ by rounding (~1e-16 x 2 m).
  EXPECT_LT(max_difference, 1e-12);
  std::printf("max |d FK(Jet)/dq - J| over 100 q: %.3g\n", max_difference);
}
