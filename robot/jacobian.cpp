#include "robot/jacobian.hpp"

namespace imscal::calib {

Jacobian geometric_jacobian(const KinematicModel& model, const JointVector& q) {
  return geometric_jacobian(chain_poses<double>(model, q));
}

Jacobian geometric_jacobian(const ChainPoses<double>& poses) {
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
