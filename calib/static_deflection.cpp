#include "calib/static_deflection.hpp"

#include <cmath>

#include "robot/forward_kinematics.hpp"

namespace imscal::calib {
namespace {

// Adds the holding torque of a point mass m at c_R (moved by joints 0..last_joint) to tau:
// the drive must cancel the gravity moment about its axis, tau_j = -z_j . ((c - o_j) x m g).
void add_body(const ChainPoses<double>& chain, int last_joint, double mass_kg,
              const Eigen::Vector3d& com_R, const Eigen::Vector3d& gravity_R, JointVector& tau) {
  if (mass_kg == 0.0) return;
  const Eigen::Vector3d force = mass_kg * gravity_R;
  for (int j = 0; j <= last_joint; ++j) {
    const Eigen::Isometry3d& axis = chain.T_R_axis[j];
    const Eigen::Vector3d lever = com_R - axis.translation();
    tau(j) -= axis.linear().col(2).dot(lever.cross(force));
  }
}

}  // namespace

JointVector gravity_torques(const RobotDescription& robot, const RigidBodyParameters* payload,
                            const JointVector& q_rad, const Eigen::Vector3d& gravity_R_m_s2) {
  const ChainPoses<double> chain = chain_poses<double>(robot.kinematics, q_rad);
  JointVector tau = JointVector::Zero();
  for (int i = 0; i < kJointCount; ++i) {
    // Link i+1 is fixed to DH frame i+1 and moved by joints 0..i.
    const RigidBodyParameters& link = robot.joints[i].link;
    add_body(chain, i, link.mass_kg, chain.T_R_link[i + 1] * link.com_m, gravity_R_m_s2, tau);
  }
  const Eigen::Isometry3d T_R_T = chain.T_R_H * robot.tool.T_H_T;
  add_body(chain, kJointCount - 1, robot.tool.body.mass_kg, T_R_T * robot.tool.body.com_m,
           gravity_R_m_s2, tau);
  if (payload != nullptr) {
    add_body(chain, kJointCount - 1, payload->mass_kg, T_R_T * payload->com_m, gravity_R_m_s2, tau);
  }
  return tau;
}

StaticDeflection correct_static_deflection(const RobotDescription& robot,
                                           const RigidBodyParameters* payload,
                                           const JointVector& q_internal_rad,
                                           const StaticDeflectionOptions& options) {
  StaticDeflection out;
  out.q_link_rad = q_internal_rad;
  for (int iteration = 1; iteration <= options.max_iterations; ++iteration) {
    out.iterations = iteration;
    out.gravity_torque_nm = gravity_torques(robot, payload, out.q_link_rad, options.gravity_R_m_s2);
    JointVector next = q_internal_rad;
    for (int i = 0; i < kJointCount; ++i) {
      const DriveParameters& drive = robot.joints[i].drive;
      const double tau = out.gravity_torque_nm(i);
      // Rigid description (no stiffness): no wind-up and no play taken up.
      if (drive.stiffness_nm_per_rad <= 0.0) {
        out.loaded[i] = true;
        continue;
      }
      const double threshold =
          std::max(options.coulomb_factor * drive.coulomb_nm, options.min_loaded_torque_nm);
      out.loaded[i] = std::abs(tau) > threshold;
      const double windup = tau / drive.stiffness_nm_per_rad;
      const double play = out.loaded[i] ? std::copysign(0.5 * drive.backlash_rad, tau) : 0.0;
      next(i) -= windup + play;
      out.windup_rad(i) = windup;
      out.play_rad(i) = play;
    }
    const double change = (next - out.q_link_rad).cwiseAbs().maxCoeff();
    out.q_link_rad = next;
    if (change <= options.tolerance_rad) break;
  }
  out.deflection_rad = q_internal_rad - out.q_link_rad;
  for (int i = 0; i < kJointCount; ++i) {
    const double model = options.model_uncertainty_fraction * std::abs(out.deflection_rad(i));
    const double play = out.loaded[i] ? 0.0 : robot.joints[i].drive.backlash_rad / std::sqrt(12.0);
    out.q_link_sigma_rad(i) =
        std::sqrt(model * model + play * play + options.sigma_floor_rad * options.sigma_floor_rad);
  }
  return out;
}

}  // namespace imscal::calib
