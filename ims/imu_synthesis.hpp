#pragma once
// Ideal (error-free) IMS signals from a known motion of S relative to the rotating Earth-fixed
// frame W (ims/frames.hpp):
//   gyro:           omega_is_S = omega_WS_S + R_S_W * omega_ie_W                      [rad/s]
//   accelerometer:  f_S = R_S_W * (a_W + 2 omega_ie_W x v_W - g_W(p_W))              [m/s^2]
// with g_W the gravity of EarthModel (gravitation + centrifugal), so the centripetal term of
// the Earth rate is already inside g. Increments are the exact integrals of these over each
// sample interval (ims/imu_data.hpp: stamped at the interval's end).
#include <Eigen/Core>
#include <vector>

#include "ims/earth_model.hpp"
#include "ims/imu_data.hpp"
#include "ims/trajectory.hpp"

namespace imscal::ims {

struct InertialSignals {
  Eigen::Vector3d omega_is_S = Eigen::Vector3d::Zero();  // inertial angular rate in S [rad/s]
  Eigen::Vector3d f_S = Eigen::Vector3d::Zero();         // specific force in S [m/s^2]
};

// The instantaneous ideal sensor outputs for one kinematic state.
InertialSignals ideal_signals(const KinematicState& state, const EarthModel& earth);

// Implemented (besides Trajectory) by motions that are smooth only piecewise: the times at which
// some derivative of the IMS signals jumps (ends of smooth steps, spline knots). The synthesiser
// splits its quadrature there, so that every piece it integrates is smooth.
class PiecewiseSmooth {
 public:
  virtual ~PiecewiseSmooth() = default;
  virtual const std::vector<double>& joints_s() const = 0;  // sorted ascending
};

// Gauss-Legendre points per sample interval (per piece of it, see PiecewiseSmooth) used below. 8
// points integrate polynomials of degree 15 exactly; the error on a smooth integrand is ~ h^17
// f^(16) / 1e13 (h = interval), i.e. for a motion whose fastest time scale is T the relative error
// is ~ (h / T)^16: below 1e-16 for h/T < 0.1 (1 kHz and 100 Hz with T ~ 0.1..1 s). At the ends of
// the degree-9 smooth steps of AnalyticTrajectory the specific force is only C^2 (its third
// derivative jumps), where the rule loses ~ jump * h^4 / 1e5 (1e-13 m/s measured at 256 Hz on
// the round-trip motion): hence the split at the joints a PiecewiseSmooth trajectory reports,
// after which each piece is integrated to rounding (tests/ims/test_imu_synthesis.cpp).
inline constexpr int kGaussLegendrePoints = 8;

// Increments over (t_{k-1}, t_k], t_k = begin_s + k / rate_hz, k = 1 .. floor((end-begin)*rate),
// quantity kIncrements, nominal_dt_s = 1 / rate_hz, site = earth.site().
// Throws std::invalid_argument if rate_hz is not positive or the trajectory is shorter than
// one interval.
ImuSeries synthesize_ideal_increments(const Trajectory& trajectory, const EarthModel& earth,
                                      double rate_hz);

// Instantaneous rate and specific force at t_k = begin_s + k / rate_hz, k = 0 .. N (N as above;
// note the sample at begin_s), quantity kRates.
ImuSeries synthesize_ideal_rates(const Trajectory& trajectory, const EarthModel& earth,
                                 double rate_hz);

}  // namespace imscal::ims
