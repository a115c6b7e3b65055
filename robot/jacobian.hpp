#pragma once
// Geometric Jacobian of the flange: the twist of H in the base R from the joint rates,
//   [v; w] = J(q) * q_dot,
// rows 0..2 the linear velocity [m/s] of the flange origin, rows 3..5 the angular velocity
// [rad/s], both in R coordinates (the same reference point and axes as KDL's
// ChainJntToJacSolver on a chain ending at H).
#include <Eigen/Core>

#include "robot/forward_kinematics.hpp"
#include "robot/robot_description.hpp"

namespace imscal::calib {

using Jacobian = Eigen::Matrix<double, 6, kJointCount>;

Jacobian geometric_jacobian(const KinematicModel& model, const JointVector& q);
// The same from the chain's poses at q, for a caller that has them already.
Jacobian geometric_jacobian(const ChainPoses<double>& poses);

}  // namespace imscal::calib
