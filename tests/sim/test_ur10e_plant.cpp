// The UR10e plant's design statements (datasets/robots/ur10e.imscal.yaml), recomputed with KDL's
// mass matrix and recursive Newton-Euler on the URDF's inertials (independent of how the side
// file's numbers were chosen):
// - locked-motor first resonances f_i = sqrt(k_i / M_ii) / (2 pi) in the reference pose
//   q = (0, -90, 90, -90, -90, 0) deg with the IMS (5 kg) and a 4 kg load, as the file states;
// - gear damping 5 % of critical, 2 * 0.05 * sqrt(k_i M_ii);
// - velocity-loop bandwidths kp_velocity / (M_ii + N^2 J_m) of 30 (arm), 60 (wrists 1, 2) and
//   150 rad/s (wrist 3), each below its joint's locked-motor resonance;
// - every drive holds the rated 12.5 kg on the flange against gravity in every pose.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <kdl/chaindynparam.hpp>
#include <kdl/chainidsolver_recursive_newton_euler.hpp>
#include <random>

#include "calib/robot_description.hpp"
#include "core/units.hpp"
#include "sim/kdl_chain.hpp"

namespace imscal::sim {
namespace {

calib::RobotDescription ur10e() {
  return calib::load_robot_description(IMSCAL_SOURCE_DIR "/datasets/robots/ur10e.urdf");
}

KDL::JntArray to_kdl(const calib::JointVector& q) {
  KDL::JntArray out(6);
  for (int i = 0; i < 6; ++i) out(i) = q(i);
  return out;
}

KDL::Chain chain_with_payload(const calib::RobotDescription& robot, double payload_kg) {
  calib::RigidBodyParameters payload;
  payload.mass_kg = payload_kg;
  payload.com_m = {0, 0, 0.05};
  payload.inertia_kg_m2 = Eigen::Matrix3d::Identity() * 0.01;
  KdlChainOptions options;
  options.payload = payload;
  return build_kdl_chain(robot, options);
}

TEST(Ur10ePlant, ResonancesDampingAndBandwidthsAreAsStated) {
  const calib::RobotDescription robot = ur10e();
  const KDL::Chain chain = chain_with_payload(robot, 4.0);
  KDL::ChainDynParam dyn(chain, KDL::Vector(0, 0, -9.81));
  calib::JointVector reference;
  reference << 0, -90, 90, -90, -90, 0;
  reference *= kRadPerDeg;
  KDL::JntSpaceInertiaMatrix mass(6);
  ASSERT_GE(dyn.JntToMass(to_kdl(reference), mass), 0);
  // As the file's comments state them (rounded to 0.1 Hz; 83 Hz to 1 Hz).
  const double stated_hz[6] = {13.9, 10.8, 9.2, 17.0, 19.5, 83.0};
  const double stated_bandwidth_rad_s[6] = {30, 30, 30, 60, 60, 150};
  for (int i = 0; i < 6; ++i) {
    const calib::DriveParameters& drive = robot.joints[std::size_t(i)].drive;
    const double m = mass(i, i);
    const double f_hz = std::sqrt(drive.stiffness_nm_per_rad / m) / (2 * M_PI);
    const double reflected = drive.gear_ratio * drive.gear_ratio * drive.motor_inertia_kg_m2;
    const double bandwidth =
        robot.joints[std::size_t(i)].controller.kp_velocity_nm_s_per_rad / (m + reflected);
    const double damping_ratio =
        drive.damping_nm_s_per_rad / (2 * std::sqrt(drive.stiffness_nm_per_rad * m));
    std::printf(
        "joint %d: M_ii %.4g kg m^2, N^2 J_m %.3g, resonance %.1f Hz, damping %.3f, "
        "velocity bandwidth %.1f rad/s\n",
        i + 1, m, reflected, f_hz, damping_ratio, bandwidth);
    EXPECT_NEAR(f_hz, stated_hz[i], i == 5 ? 1.0 : 0.1) << "joint " << i + 1;
    // The damping values are rounded to two digits: 5 % within 0.5 pp.
    EXPECT_NEAR(damping_ratio, 0.05, 0.005) << "joint " << i + 1;
    // Gains are rounded to two digits: within 5 % of the stated bandwidth, below the resonance.
    EXPECT_NEAR(bandwidth, stated_bandwidth_rad_s[i], 0.05 * stated_bandwidth_rad_s[i])
        << "joint " << i + 1;
    EXPECT_LT(bandwidth, 2 * M_PI * f_hz) << "joint " << i + 1;
  }
}

TEST(Ur10ePlant, DrivesHoldTheRatedPayloadEverywhere) {
  const calib::RobotDescription robot = ur10e();
  const KDL::Chain chain =
      chain_with_payload(robot, robot.nominal_payload_kg - robot.tool.body.mass_kg);
  KDL::ChainIdSolver_RNE rne(chain, KDL::Vector(0, 0, -9.81));
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> angle(-M_PI, M_PI);
  calib::JointVector largest = calib::JointVector::Zero();
  const int poses = std::getenv("IMSCAL_SANITIZED") ? 400 : 2000;  // lighter under sanitizers
  for (int n = 0; n < poses; ++n) {
    calib::JointVector q;
    for (int i = 0; i < 6; ++i) q(i) = angle(rng);
    KDL::JntArray zero(6), torques(6);
    KDL::Wrenches no_wrench(chain.getNrOfSegments(), KDL::Wrench::Zero());
    ASSERT_GE(rne.CartToJnt(to_kdl(q), zero, zero, no_wrench, torques), 0);
    for (int i = 0; i < 6; ++i) largest(i) = std::max(largest(i), std::abs(torques(i)));
  }
  for (int i = 0; i < 6; ++i) {
    const double limit = robot.joints[std::size_t(i)].controller.torque_limit_nm;
    std::printf("joint %d: largest gravity torque %.1f N m (12.5 kg), limit %.0f N m\n", i + 1,
                largest(i), limit);
    EXPECT_LT(largest(i), limit) << "joint " << i + 1;
  }
}

}  // namespace
}  // namespace imscal::sim
