#include "robot/jacobian.hpp"

#include "robot/forward_kinematics.hpp"

namespace imscal::calib {

Jacobian geometric_jacobian(const KinematicModel& model, const JointVector& q) {
  const ChainPoses<double> poses = chain_poses<double>(model, q);
  const Eigen::Vector3d p_flange = poses.T_R_H.translation();
  Jacobian jacobian;
  for (int i = 0; i < kJointCount; ++i) {
    // A revolute joint about unit axis z through o moves the point p at z x (p - o).
    const Eigen::Vector3d axis = poses.T_R_axis[i].linear().col(2);
    const Eigen::Vector3d origin = poses.T_R_axis[i].translation();
    jacobian.block<3, 1>(0, i) = axis.cross(p_flange - origin);
    jacobian.block<3, 1>(3, i) = axis;
  }
  return jacobian;
}

}  // namespace imscal::calib
