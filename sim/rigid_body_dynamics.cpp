#include "sim/rigid_body_dynamics.hpp"

#include <stdexcept>

#include "robot/forward_kinematics.hpp"
#include "sim/kdl_chain.hpp"

namespace imscal::sim {
namespace {

constexpr int kN = calib::kJointCount;

void to_kdl(const calib::JointVector& v, KDL::JntArray& out) {
  for (int i = 0; i < kN; ++i) out(i) = v(i);
}

calib::JointVector from_kdl(const KDL::JntArray& a) {
  calib::JointVector out;
  for (int i = 0; i < kN; ++i) out(i) = a(i);
  return out;
}

}  // namespace

RigidBodyDynamics::RigidBodyDynamics(const calib::RobotDescription& robot,
                                     const std::optional<calib::RigidBodyParameters>& payload,
                                     const Eigen::Vector3d& gravity_in_base_m_s2)
    : robot_(robot),
      payload_(payload),
      gravity_(gravity_in_base_m_s2),
      q_(kN),
      qd_(kN),
      qdd_(kN),
      torque_(kN),
      mass_(kN) {
  rebuild();
}

void RigidBodyDynamics::set_payload(const std::optional<calib::RigidBodyParameters>& payload) {
  payload_ = payload;
  rebuild();
}

void RigidBodyDynamics::rebuild() {
  KdlChainOptions options;
  options.payload = payload_;
  chain_ = build_kdl_chain(robot_, options);
  if (static_cast<int>(chain_.getNrOfJoints()) != kN) {
    throw std::logic_error("rigid-body dynamics: the KDL chain must have 6 joints");
  }
  const KDL::Vector gravity(gravity_.x(), gravity_.y(), gravity_.z());
  dyn_param_ = std::make_unique<KDL::ChainDynParam>(chain_, gravity);
  rne_ = std::make_unique<KDL::ChainIdSolver_RNE>(chain_, gravity);
  no_wrenches_.assign(chain_.getNrOfSegments(), KDL::Wrench::Zero());
}

JointMatrix RigidBodyDynamics::mass_matrix(const calib::JointVector& q) {
  to_kdl(q, q_);
  if (dyn_param_->JntToMass(q_, mass_) < 0) {
    throw std::runtime_error("rigid-body dynamics: KDL JntToMass failed");
  }
  return mass_.data;
}

calib::JointVector RigidBodyDynamics::inverse_dynamics(const calib::JointVector& q,
                                                       const calib::JointVector& qd,
                                                       const calib::JointVector& qdd) {
  to_kdl(q, q_);
  to_kdl(qd, qd_);
  to_kdl(qdd, qdd_);
  if (rne_->CartToJnt(q_, qd_, qdd_, no_wrenches_, torque_) < 0) {
    throw std::runtime_error("rigid-body dynamics: KDL RNE failed");
  }
  return from_kdl(torque_);
}

calib::JointVector RigidBodyDynamics::bias_torque(const calib::JointVector& q,
                                                  const calib::JointVector& qd) {
  return inverse_dynamics(q, qd, calib::JointVector::Zero());
}

calib::JointVector RigidBodyDynamics::gravity_torque(const calib::JointVector& q) {
  return inverse_dynamics(q, calib::JointVector::Zero(), calib::JointVector::Zero());
}

double RigidBodyDynamics::potential_energy_j(const calib::JointVector& q) const {
  const calib::ChainPoses<double> poses = calib::chain_poses<double>(robot_.kinematics, q);
  double energy = 0.0;
  auto add = [&](double mass, const Eigen::Vector3d& com_in_base) {
    energy -= mass * gravity_.dot(com_in_base);
  };
  for (int i = 0; i < kN; ++i) {
    const calib::RigidBodyParameters& link = robot_.joints[i].link;
    add(link.mass_kg, poses.T_R_link[i + 1] * link.com_m);
  }
  const Eigen::Isometry3d T_R_T = poses.T_R_H * robot_.tool.T_H_T;
  add(robot_.tool.body.mass_kg, T_R_T * robot_.tool.body.com_m);
  if (payload_) add(payload_->mass_kg, T_R_T * payload_->com_m);
  return energy;
}

}  // namespace imscal::sim
