#pragma once
// Navigation state of the sensor frame S in the Earth-fixed frame W (ims/frames.hpp).
#include <Eigen/Core>
#include <Eigen/Geometry>

namespace imscal::ims {

struct NavState {
  double t_s = 0.0;
  Eigen::Quaterniond q_W_S = Eigen::Quaterniond::Identity();  // attitude: p_W = q_W_S * p_S
  Eigen::Vector3d v_W = Eigen::Vector3d::Zero();  // velocity relative to the Earth [m/s]
  Eigen::Vector3d p_W = Eigen::Vector3d::Zero();  // position of the S origin [m]
};

}  // namespace imscal::ims
