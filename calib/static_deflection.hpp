#pragma once
// Link-side joint angles of a robot at rest from its internal (motor-side) readings.
//
// At standstill every gear carries the gravity torque of the bodies beyond it, tau_g(q) (the
// torque the drive must supply to hold the arm, as KDL's ChainDynParam::JntToGravity gives it),
// so the gear winds up by tau_g / k and takes up its play on the side of the torque:
//   q_link = q_internal - tau_g(q_link) / k - (b / 2) sign(tau_g)
// (k stiffness, b full backlash width, both joint side). tau_g depends on q_link, so the
// equation is solved as a fixed point (d tau_g / dq / k < 1e-2 on arms of the KR 16 class: a few
// iterations). tau_g comes from the robot description's link masses and centres of mass, the
// mounted tool's body and a payload (mass + COM in the tool frame T) in the gravity field of the
// site expressed in the base R; no KDL (calib/ does not depend on it).
//
// Where |tau_g| is below the Coulomb friction (e.g. A1 of a floor-mounted arm, always 0), the
// link may rest anywhere in the play: the backlash term is left out and the prior 1-sigma of
// the joint is that of a uniform distribution over the play, b / sqrt(12). Loaded joints get
// a model-uncertainty fraction of their deflection, and every joint a floor, in quadrature.
// Not modelled: the gear's transmission error (a periodic error of the motor-side reading, a
// few arcsec on good gears) - raise the floor to cover it.
#include <Eigen/Core>
#include <array>

#include "core/units.hpp"
#include "robot/robot_description.hpp"

namespace imscal::calib {

struct StaticDeflectionOptions {
  // Gravity in the robot base R [m/s^2]: down along -z_R for a floor-mounted arm; the site's
  // value is R_R_W g_W (ims::EarthModel::gravity_W at the base).
  Eigen::Vector3d gravity_R_m_s2{0.0, 0.0, -kStandardGravity_m_s2};
  // 1-sigma of the deflection model as a fraction of the modelled deflection (stiffness, masses
  // and backlash known to a few per cent) [1].
  double model_uncertainty_fraction = 0.05;
  // 1-sigma floor of every joint (reading resolution, unmodelled gear errors) [rad].
  double sigma_floor_rad = 5e-6;
  // A joint is "loaded" (backlash side known) when |tau_g| exceeds its Coulomb friction times
  // this factor and at least min_loaded_torque_nm.
  double coulomb_factor = 1.0;
  double min_loaded_torque_nm = 1e-3;
  int max_iterations = 20;
  double tolerance_rad = 1e-13;  // stop when no angle changes by more
};

struct StaticDeflection {
  JointVector q_link_rad = JointVector::Zero();
  JointVector q_link_sigma_rad = JointVector::Zero();   // prior 1-sigma of the remaining error
  JointVector gravity_torque_nm = JointVector::Zero();  // tau_g(q_link) [N m]
  JointVector deflection_rad = JointVector::Zero();     // q_internal - q_link
  // Its two parts (deflection_rad = windup_rad + play_rad): the gear wind-up tau_g / k and the
  // play taken up on loaded joints (b / 2) sign(tau_g). The bundle may scale each per joint
  // (calib/frame_calibration.hpp, estimate_deflection_scale): the robot file's stiffness and
  // play checked by the data.
  JointVector windup_rad = JointVector::Zero();
  JointVector play_rad = JointVector::Zero();
  std::array<bool, kJointCount> loaded{};  // backlash side known (|tau_g| above friction)
  int iterations = 0;
};

// tau_g(q): the holding torques of the links, the tool body and the payload (nullptr: none;
// given in the tool frame T, like ToolDescription::body) [N m].
JointVector gravity_torques(const RobotDescription& robot, const RigidBodyParameters* payload,
                            const JointVector& q_rad, const Eigen::Vector3d& gravity_R_m_s2);

StaticDeflection correct_static_deflection(const RobotDescription& robot,
                                           const RigidBodyParameters* payload,
                                           const JointVector& q_internal_rad,
                                           const StaticDeflectionOptions& options = {});

}  // namespace imscal::calib
