#pragma once
// Forward kinematics of the DH chain, templated on the scalar so that Ceres can differentiate it
// (T = double or ceres::Jet): T_R_H(q) = T_R_0 * A_1(q_1) * ... * A_6(q_6) * T_6_H.
// Joint angles q in [rad]; lengths in [m]. The DH numbers may be of type T as well
// (dh_link_transform), so that a calibration can differentiate with respect to them.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cmath>

#include "robot/robot_description.hpp"

namespace imscal::calib {

template <typename T>
using Isometry3 = Eigen::Transform<T, 3, Eigen::Isometry>;

// The cosine and sine of an angle, for callers that reuse them across several transforms.
template <typename T>
struct CosSin {
  T c, s;
};
template <typename T>
CosSin<T> cos_sin(const T& angle_rad) {
  using std::cos;
  using std::sin;
  return {cos(angle_rad), sin(angle_rad)};
}

// Rigid transform with rotation about z by theta and translation (0, 0, d), and likewise about x.
template <typename T>
Isometry3<T> rot_z_trans_z(const CosSin<T>& theta, const T& d) {
  Isometry3<T> out = Isometry3<T>::Identity();
  out.linear() << theta.c, -theta.s, T(0), theta.s, theta.c, T(0), T(0), T(0), T(1);
  out.translation() << T(0), T(0), d;
  return out;
}
template <typename T>
Isometry3<T> trans_x_rot_x(const T& a, const CosSin<T>& alpha) {
  Isometry3<T> out = Isometry3<T>::Identity();
  out.linear() << T(1), T(0), T(0), T(0), alpha.c, -alpha.s, T(0), alpha.s, alpha.c;
  out.translation() << a, T(0), T(0);
  return out;
}

// A_i: link frame i in link frame i-1 (see DhConvention for the two conventions), with the
// cosine and sine of the twist alpha and of theta = q_i + offset_i given.
template <typename T>
Isometry3<T> dh_link_transform(DhConvention convention, const T& a, const CosSin<T>& alpha,
                               const T& d, const CosSin<T>& theta) {
  if (convention == DhConvention::kStandard) {
    return rot_z_trans_z(theta, d) * trans_x_rot_x(a, alpha);
  }
  return trans_x_rot_x(a, alpha) * rot_z_trans_z(theta, d);
}

// A_i from the angles alpha and theta = q_i + offset_i.
template <typename T>
Isometry3<T> dh_link_transform(DhConvention convention, const T& a, const T& alpha, const T& d,
                               const T& theta) {
  return dh_link_transform(convention, a, cos_sin(alpha), d, cos_sin(theta));
}

template <typename T>
Isometry3<T> dh_link_transform(DhConvention convention, const DhParameters& p, const T& q) {
  return dh_link_transform(convention, T(p.a_m), T(p.alpha_rad), T(p.d_m), q + T(p.offset_rad));
}

template <typename T>
Isometry3<T> cast_pose(const Eigen::Isometry3d& pose) {
  Isometry3<T> out = Isometry3<T>::Identity();
  out.linear() = pose.linear().cast<T>();
  out.translation() = pose.translation().cast<T>();
  return out;
}

// The chain at q, with the frames every joint turns in.
template <typename T>
struct ChainPoses {
  // T_R_i for i = 0..6 (DH link frames; index 0 is the base frame 0).
  std::array<Isometry3<T>, kJointCount + 1> T_R_link;
  // Joint i (0-based) turns about the z axis of T_R_axis[i], whose origin lies on the axis.
  std::array<Isometry3<T>, kJointCount> T_R_axis;
  Isometry3<T> T_R_H;  // flange
};

template <typename T>
ChainPoses<T> chain_poses(const KinematicModel& model, const Eigen::Matrix<T, 6, 1>& q) {
  ChainPoses<T> out;
  out.T_R_link[0] = cast_pose<T>(model.T_R_0);
  for (int i = 0; i < kJointCount; ++i) {
    const DhParameters& p = model.dh[i];
    if (model.convention == DhConvention::kStandard) {
      out.T_R_axis[i] = out.T_R_link[i];
    } else {
      // Modified DH: the joint turns about z_i, i.e. after Rx(alpha_{i-1}) Tx(a_{i-1}).
      out.T_R_axis[i] = out.T_R_link[i] * trans_x_rot_x(T(p.a_m), cos_sin(T(p.alpha_rad)));
    }
    out.T_R_link[i + 1] = out.T_R_link[i] * dh_link_transform(model.convention, p, q(i));
  }
  out.T_R_H = out.T_R_link[kJointCount] * cast_pose<T>(model.T_6_H);
  return out;
}

// T_R_H(q): the flange in the robot base.
template <typename T>
Isometry3<T> forward_kinematics(const KinematicModel& model, const Eigen::Matrix<T, 6, 1>& q) {
  Isometry3<T> pose = cast_pose<T>(model.T_R_0);
  for (int i = 0; i < kJointCount; ++i) {
    pose = pose * dh_link_transform(model.convention, model.dh[i], q(i));
  }
  return pose * cast_pose<T>(model.T_6_H);
}

// Pointer form for Ceres cost functors: q points at 6 joint angles [rad].
template <typename T>
Isometry3<T> forward_kinematics(const KinematicModel& model, const T* q) {
  return forward_kinematics<T>(model, Eigen::Map<const Eigen::Matrix<T, 6, 1>>(q).eval());
}

}  // namespace imscal::calib
