#include "ims/trajectory_comparison.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "ims/so3.hpp"

namespace imscal::ims {

TrajectoryComparison compare_trajectories(const NavTrajectory& estimate,
                                          const NavTrajectory& reference, double time_tolerance_s) {
  TrajectoryComparison result;
  const bool has_sigma = estimate.sigmas.size() == estimate.states.size();
  double position_sq = 0.0, attitude_sq = 0.0;
  Eigen::Matrix<double, 9, 1> normalised_sq = Eigen::Matrix<double, 9, 1>::Zero();
  const auto by_time = [](const NavState& s, double t) { return s.t_s < t; };
  for (std::size_t i = 0; i < estimate.states.size(); ++i) {
    const NavState& est = estimate.states[i];
    auto it = std::lower_bound(reference.states.begin(), reference.states.end(),
                               est.t_s - time_tolerance_s, by_time);
    if (it == reference.states.end() || std::abs(it->t_s - est.t_s) > time_tolerance_s) continue;
    const NavState& ref = *it;
    // Attitude error as the rotation vector of q_ref * q_est^-1, in W (E, N, U).
    const Eigen::Vector3d phi = quat_log(Eigen::Quaterniond(ref.q_W_S * est.q_W_S.conjugate()));
    const Eigen::Vector3d dp = ref.p_W - est.p_W;
    position_sq += dp.squaredNorm();
    attitude_sq += phi.squaredNorm();
    result.position_max_m = std::max(result.position_max_m, dp.norm());
    result.attitude_max_rad = std::max(result.attitude_max_rad, phi.norm());
    if (has_sigma) {
      Eigen::Matrix<double, 9, 1> error;
      error << phi, ref.v_W - est.v_W, dp;
      normalised_sq += error.cwiseQuotient(estimate.sigmas[i]).cwiseAbs2();
    }
    ++result.matched_states;
  }
  if (result.matched_states == 0) {
    throw std::invalid_argument("no state of the estimate has a reference state at its time");
  }
  const double n = static_cast<double>(result.matched_states);
  result.position_rms_m = std::sqrt(position_sq / n);
  result.attitude_rms_rad = std::sqrt(attitude_sq / n);
  if (has_sigma) result.normalised_error_rms = (normalised_sq / n).cwiseSqrt();
  return result;
}

}  // namespace imscal::ims
