// Speed of the kinematics used per sample by the calibration (FK, FK with Jets for Ceres,
// Jacobian) and by the joint-space error computation (IK per IMS sample).
#include <benchmark/benchmark.h>
#include <ceres/jet.h>

#include "calib/forward_kinematics.hpp"
#include "calib/inverse_kinematics.hpp"
#include "calib/jacobian.hpp"
#include "calib/robot_description.hpp"

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

}  // namespace

BENCHMARK_MAIN();
