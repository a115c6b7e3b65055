#include "calib/encoder_motion.hpp"

#include <algorithm>
#include <cmath>

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
  const auto& s = log.samples;
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
  const auto& s = log.samples;
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

}  // namespace

EncoderMotion encoder_motion(const RobotLog& log, const KinematicModel& kinematics,
                             const Eigen::Isometry3d& T_W_R, const Eigen::Vector3d& p_H_S,
                             double time_offset_s, const EncoderMotionOptions& options) {
  EncoderMotion out;
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
        const double sigma = std::hypot(options.velocity_sigma_floor_m_s,
                                        options.velocity_sigma_fraction * v_W.norm());
        out.creep_velocity.push_back({sample.t_s + time_offset_s, v_W, sigma});
      }
    }
    if (in_still) close_still(run.last);
  }
  return out;
}

}  // namespace imscal::calib
