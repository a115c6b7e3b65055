// Speed of the kinematics used per sample by the calibration (FK, FK with Jets for Ceres,
// Jacobian) and by the joint-space error computation (IK per IMS sample): the KR 16's
// spherical-wrist solve and the UR10e's UR-class solve in the same run (ratio of the two), and
// KDL's numeric ChainIkSolverPos_LMA on the same UR10e pose as the numeric alternative.
#include <benchmark/benchmark.h>
#include <ceres/jet.h>

#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainiksolverpos_lma.hpp>

#include "robot/forward_kinematics.hpp"
#include "robot/inverse_kinematics.hpp"
#include "robot/jacobian.hpp"
#include "robot/robot_description.hpp"
#include "robot/ur_inverse_kinematics.hpp"
#include "sim/kdl_chain.hpp"

namespace {

using imscal::calib::JointVector;

const imscal::calib::RobotDescription& kr16() {
  static const imscal::calib::RobotDescription robot =
      imscal::calib::load_robot_description(IMSCAL_SOURCE_DIR "/datasets/robots/kr16.yaml");
  return robot;
}

JointVector sample_q() {
  JointVector q;
  q << 0.3, -1.2, 1.9, 0.4, 0.8, -0.5;
  return q;
}

void BM_ForwardKinematicsDouble(benchmark::State& state) {
  const JointVector q = sample_q();
  for (auto _ : state) {
    benchmark::DoNotOptimize(imscal::calib::forward_kinematics<double>(kr16().kinematics, q));
  }
}
BENCHMARK(BM_ForwardKinematicsDouble);

void BM_ForwardKinematicsJet6(benchmark::State& state) {
  using Jet = ceres::Jet<double, 6>;
  Eigen::Matrix<Jet, 6, 1> q;
  const JointVector q0 = sample_q();
  for (int i = 0; i < 6; ++i) q(i) = Jet(q0(i), i);
  for (auto _ : state) {
    benchmark::DoNotOptimize(imscal::calib::forward_kinematics<Jet>(kr16().kinematics, q));
  }
}
BENCHMARK(BM_ForwardKinematicsJet6);

void BM_GeometricJacobian(benchmark::State& state) {
  const JointVector q = sample_q();
  for (auto _ : state) {
    benchmark::DoNotOptimize(imscal::calib::geometric_jacobian(kr16().kinematics, q));
  }
}
BENCHMARK(BM_GeometricJacobian);

void BM_InverseKinematicsSolve(benchmark::State& state) {
  const imscal::calib::InverseKinematics ik(kr16().kinematics);
  const JointVector q = sample_q();
  const Eigen::Isometry3d pose = imscal::calib::forward_kinematics<double>(kr16().kinematics, q);
  const imscal::calib::ArmConfiguration configuration = ik.configuration_of(q);
  for (auto _ : state) benchmark::DoNotOptimize(ik.solve(pose, configuration));
}
BENCHMARK(BM_InverseKinematicsSolve);

const imscal::calib::RobotDescription& ur10e() {
  static const imscal::calib::RobotDescription robot =
      imscal::calib::load_robot_description(IMSCAL_SOURCE_DIR "/datasets/robots/ur10e.urdf");
  return robot;
}

// The same joint angles on the UR10e: closed form + Newton (the URDF's 9-digit pi/2 leaves the
// closed form 1e-9 off, so one Newton step runs, as in use).
void BM_InverseKinematicsSolveUr10e(benchmark::State& state) {
  const imscal::calib::UrInverseKinematics ik(ur10e().kinematics);
  const JointVector q = sample_q();
  const Eigen::Isometry3d pose = imscal::calib::forward_kinematics<double>(ur10e().kinematics, q);
  const imscal::calib::ArmConfiguration configuration = ik.configuration_of(q);
  for (auto _ : state) benchmark::DoNotOptimize(ik.solve(pose, configuration));
}
BENCHMARK(BM_InverseKinematicsSolveUr10e);

// The numeric alternative: KDL's Levenberg-Marquardt from a start 0.1 rad off in every joint,
// to its default accuracy (weights 1, 0.01 for rotation; eps 1e-5 on the squared error).
void BM_KdlLmaSolveUr10e(benchmark::State& state) {
  const KDL::Chain chain = imscal::sim::build_kdl_chain(ur10e());
  KDL::ChainFkSolverPos_recursive fk(chain);
  KDL::ChainIkSolverPos_LMA lma(chain);
  const JointVector q = sample_q();
  KDL::JntArray q_kdl(6), start(6), solution(6);
  for (int i = 0; i < 6; ++i) {
    q_kdl(i) = q(i);
    start(i) = q(i) + 0.1;
  }
  KDL::Frame pose;
  fk.JntToCart(q_kdl, pose);
  for (auto _ : state) benchmark::DoNotOptimize(lma.CartToJnt(start, pose, solution));
}
BENCHMARK(BM_KdlLmaSolveUr10e);

}  // namespace

BENCHMARK_MAIN();
