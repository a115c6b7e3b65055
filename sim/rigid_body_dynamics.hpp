#pragma once
// Rigid-body dynamics of the arm, the mounted tool (the IMS) and the current payload through
// Orocos KDL: M(q) from ChainDynParam::JntToMass, the bias C(q, qd) qd + G(q) from one recursive
// Newton-Euler pass with qdd = 0. Link-side joint coordinates [rad], torques [N m].
// The potential energy is computed separately from our own forward kinematics (robot/), so the
// energy check of the simulator does not rely on KDL alone.
//
// References (docs/references.md): [KDL], [Featherstone2008] (recursive Newton-Euler, mass matrix).
#include <Eigen/Core>
#include <kdl/chain.hpp>
#include <kdl/chaindynparam.hpp>
#include <kdl/chainidsolver_recursive_newton_euler.hpp>
#include <memory>
#include <optional>

#include "robot/robot_description.hpp"

namespace imscal::sim {

using JointMatrix = Eigen::Matrix<double, calib::kJointCount, calib::kJointCount>;

class RigidBodyDynamics {
 public:
  // gravity_in_base_m_s2: gravity vector in R (zero for no gravity).
  RigidBodyDynamics(const calib::RobotDescription& robot,
                    const std::optional<calib::RigidBodyParameters>& payload,
                    const Eigen::Vector3d& gravity_in_base_m_s2);

  // Rebuilds the KDL solvers for another payload (in the tool frame T; nullopt = none).
  void set_payload(const std::optional<calib::RigidBodyParameters>& payload);

  JointMatrix mass_matrix(const calib::JointVector& q);
  // C(q, qd) qd + G(q).
  calib::JointVector bias_torque(const calib::JointVector& q, const calib::JointVector& qd);
  // Full inverse dynamics M qdd + C qd + G (one RNE pass).
  calib::JointVector inverse_dynamics(const calib::JointVector& q, const calib::JointVector& qd,
                                      const calib::JointVector& qdd);
  calib::JointVector gravity_torque(const calib::JointVector& q);

  // Potential energy of links, tool and payload in the gravity field [J] (zero at the base
  // origin), from calib::chain_poses.
  double potential_energy_j(const calib::JointVector& q) const;

 private:
  void rebuild();

  calib::RobotDescription robot_;
  std::optional<calib::RigidBodyParameters> payload_;
  Eigen::Vector3d gravity_;
  KDL::Chain chain_;
  std::unique_ptr<KDL::ChainDynParam> dyn_param_;
  std::unique_ptr<KDL::ChainIdSolver_RNE> rne_;
  KDL::JntArray q_, qd_, qdd_, torque_;
  KDL::JntSpaceInertiaMatrix mass_;
  KDL::Wrenches no_wrenches_;
};

}  // namespace imscal::sim
