#pragma once
// Errors of an estimated trajectory against a reference (truth) trajectory, matched by time
// stamp: position and attitude error statistics and, where the estimate carries 1-sigma, the
// normalised errors that show whether the reported uncertainty is honest.
#include <Eigen/Core>

#include "ims/nav_trajectory_io.hpp"

namespace imscal::ims {

struct TrajectoryComparison {
  std::size_t matched_states = 0;
  double position_rms_m = 0.0;  // 3-D RMS over the matched states
  double position_max_m = 0.0;
  double attitude_rms_rad = 0.0;  // RMS of the rotation angle between estimate and reference
  double attitude_max_rad = 0.0;
  // RMS over the matched states of error / sigma per component (attitude E, N, U, velocity,
  // position); NaN where the estimate has no sigmas. Near 1 when the 1-sigma is honest.
  Eigen::Matrix<double, 9, 1> normalised_error_rms = Eigen::Matrix<double, 9, 1>::Constant(NAN);
};

// States are matched when their time stamps agree within `time_tolerance_s`; reference states
// must be sorted by time. Throws std::invalid_argument when nothing matches.
TrajectoryComparison compare_trajectories(const NavTrajectory& estimate,
                                          const NavTrajectory& reference,
                                          double time_tolerance_s = 1e-6);

}  // namespace imscal::ims
