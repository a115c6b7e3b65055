#include "calib/encoder_motion.hpp"

#include <algorithm>
#include <cmath>

#include "calib/gear_torque_rate.hpp"
#include "robot/forward_kinematics.hpp"
#include "robot/jacobian.hpp"

namespace imscal::calib {
namespace {

// Runs of samples [first, last] in which the desired joint angles do not change.
struct StandstillRun {
  std::size_t first = 0, last = 0;
};

std::vector<StandstillRun> standstill_runs(const RobotLog& log) {
  std::vector<StandstillRun> runs;
  const std::vector<RobotLogSample>& s = log.samples;
  for (std::size_t i = 0; i + 1 < s.size();) {
    if (s[i + 1].q_desired_rad != s[i].q_desired_rad) {
      ++i;
      continue;
    }
    std::size_t last = i + 1;
    while (last + 1 < s.size() && s[last + 1].q_desired_rad == s[i].q_desired_rad) ++last;
    runs.push_back({i, last});
    i = last + 1;
  }
  return runs;
}

// Joint rates at sample k from a line through the readings of the run within +-half samples
// (fewer at the run's ends). A symmetric window: an unequal one biases the slope by the
// curvature of the creep (~1e-3 of it per missing 2 ms sample for a 0.3 s decay).
JointVector fitted_rate(const RobotLog& log, const StandstillRun& run, std::size_t k,
                        std::size_t half) {
  const std::vector<RobotLogSample>& s = log.samples;
  const std::size_t reach = std::min({half, k - run.first, run.last - k});
  double s_t = 0.0, s_tt = 0.0;
  JointVector s_q = JointVector::Zero(), s_tq = JointVector::Zero();
  int n = 0;
  for (std::size_t j = k - reach; j <= k + reach; ++j) {
    const double t = s[j].t_s - s[k].t_s;
    s_t += t, s_tt += t * t, s_q += s[j].q_internal_rad, s_tq += t * s[j].q_internal_rad, ++n;
  }
  const double det = n * s_tt - s_t * s_t;
  if (n < 2 || !(det > 0.0)) {
    // At a run's end: the one-sided difference to its neighbour.
    const std::size_t other = k > run.first ? k - 1 : k + 1;
    if (other < run.first || other > run.last) return JointVector::Zero();
    return (s[k].q_internal_rad - s[other].q_internal_rad) / (s[k].t_s - s[other].t_s);
  }
  return (n * s_tq - s_t * s_q) / det;
}

// The sensor's speed [m/s] from the gears' deflection rates at sample k of a standstill run
// (calib/gear_torque_rate.hpp): the readings' acceleration is the difference of the fitted rates
// +-half samples apart; each joint's rate moves the sensor by its column of the sensor's velocity
// Jacobian (r_R: the sensor's offset from the flange in R), the joints in quadrature (their
// creep tails are not in phase).
double torque_rate_sensor_speed_m_s(const RobotLog& log, const StandstillRun& run, std::size_t k,
                                    std::size_t half, const JointVector& rate,
                                    const RobotDescription& nominal_robot, const Jacobian& J,
                                    const Eigen::Vector3d& r_R) {
  const std::size_t hi = std::min(run.last, k + half);
  const std::size_t lo = std::max(run.first, k - std::min(k, half));
  const double span_s = log.samples[hi].t_s - log.samples[lo].t_s;
  if (!(span_s > 0.0)) return 0.0;
  const JointVector accel =
      (fitted_rate(log, run, hi, half) - fitted_rate(log, run, lo, half)) / span_s;
  const RobotLogSample& sample = log.samples[k];
  const JointVector deflection_rate = gear_deflection_rate_rad_s(
      nominal_robot, sample.q_desired_rad, sample.q_internal_rad, rate, accel);
  double speed_sq = 0.0;
  for (int i = 0; i < kJointCount; ++i) {
    const Eigen::Vector3d column = J.block<3, 1>(0, i) + J.block<3, 1>(3, i).cross(r_R);
    speed_sq += std::pow(deflection_rate[i] * column.norm(), 2);
  }
  return std::sqrt(speed_sq);
}

}  // namespace

EncoderMotion encoder_motion(const RobotLog& log, const KinematicModel& kinematics,
                             const Eigen::Isometry3d& T_W_R, const Eigen::Vector3d& p_H_S,
                             double time_offset_s, const EncoderMotionOptions& options,
                             const RobotDescription* nominal_robot) {
  EncoderMotion out;
  const bool torque_rate = options.gear_torque_rate && nominal_robot != nullptr;
  const Eigen::Matrix3d R_W_R = T_W_R.linear();
  const double cycle = log.cycle_s > 0.0 ? log.cycle_s : 0.002;
  const auto half = static_cast<std::size_t>(std::max(1L, std::lround(options.fit_s / cycle)));
  for (const StandstillRun& run : standstill_runs(log)) {
    const double stop_s = log.samples[run.first].t_s;
    std::size_t still_first = 0;
    bool in_still = false;
    const auto close_still = [&](std::size_t last) {
      const double begin = log.samples[still_first].t_s, end = log.samples[last].t_s;
      if (end - begin >= options.min_still_s)
        out.still.push_back({begin + time_offset_s, end + time_offset_s});
      in_still = false;
    };
    for (std::size_t k = run.first; k <= run.last; ++k) {
      const RobotLogSample& sample = log.samples[k];
      const JointVector rate = fitted_rate(log, run, k, half);
      const Jacobian J = geometric_jacobian(kinematics, sample.q_internal_rad);
      const Eigen::Matrix3d R_R_H =
          forward_kinematics<double>(kinematics, sample.q_internal_rad).linear();
      const Eigen::Vector3d omega_R = J.bottomRows<3>() * rate;
      const Eigen::Vector3d v_W = R_W_R * (J.topRows<3>() * rate + omega_R.cross(R_R_H * p_H_S));
      const bool still =
          v_W.norm() < options.still_velocity_m_s && omega_R.norm() < options.still_rate_rad_s;
      if (still && !in_still) {
        still_first = k;
        in_still = true;
      } else if (!still && in_still) {
        close_still(k - 1);
      }
      if (sample.t_s - stop_s >= options.settle_s) {
        double sigma = std::hypot(options.velocity_sigma_floor_m_s,
                                  options.velocity_sigma_fraction * v_W.norm());
        if (torque_rate)
          sigma = std::hypot(sigma, torque_rate_sensor_speed_m_s(log, run, k, half, rate,
                                                                 *nominal_robot, J, R_R_H * p_H_S));
        out.creep_velocity.push_back({sample.t_s + time_offset_s, v_W, sigma});
      }
    }
    if (in_still) close_still(run.last);
  }
  return out;
}

}  // namespace imscal::calib
