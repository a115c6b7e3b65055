#pragma once
// A motion of the sensor frame S relative to W, known at any instant: the truth from which IMS
// signals are synthesised. Implementations: analytic (tests, demo datasets) and sampled poses
// interpolated by splines (simulator output).
#include <Eigen/Core>
#include <Eigen/Geometry>

namespace imscal::ims {

struct KinematicState {
  Eigen::Quaterniond q_W_S = Eigen::Quaterniond::Identity();
  Eigen::Vector3d p_W = Eigen::Vector3d::Zero();         // [m]
  Eigen::Vector3d v_W = Eigen::Vector3d::Zero();         // dp_W/dt [m/s], relative to the Earth
  Eigen::Vector3d a_W = Eigen::Vector3d::Zero();         // d2p_W/dt2 [m/s^2]
  Eigen::Vector3d omega_WS_S = Eigen::Vector3d::Zero();  // rate of S relative to W, in S [rad/s]
};

class Trajectory {
 public:
  virtual ~Trajectory() = default;
  virtual double begin_s() const = 0;
  virtual double end_s() const = 0;
  // State at t_s in [begin_s, end_s]; smooth enough to integrate by Gauss-Legendre quadrature.
  virtual KinematicState at(double t_s) const = 0;
};

}  // namespace imscal::ims
