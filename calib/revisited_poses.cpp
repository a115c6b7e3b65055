#include "calib/revisited_poses.hpp"

#include <algorithm>
#include <optional>

#include "calib/joint_space_errors.hpp"
#include "robot/forward_kinematics.hpp"

namespace imscal::calib {
namespace {

// A commanded standstill long enough to have settled: its pose, payload and the settled means.
struct SettledStandstill {
  std::size_t first = 0, last = 0;  // log samples of the whole standstill
  double end_robot_s = 0.0;
  JointVector q_desired_rad = JointVector::Zero();
  double payload_kg = 0.0;
  Eigen::Vector3d difference_W = Eigen::Vector3d::Zero();  // p_IMS - p_FK(q_internal)
};

}  // namespace

std::vector<StandstillWindow> settled_standstill_windows(const RobotLog& log,
                                                         const RevisitedPoseOptions& options) {
  const auto& s = log.samples;
  std::vector<StandstillWindow> windows;
  for (std::size_t i = 0; i < s.size();) {
    std::size_t last = i;
    while (last + 1 < s.size() && s[last + 1].q_desired_rad == s[i].q_desired_rad &&
           s[last + 1].payload_kg == s[i].payload_kg)
      ++last;
    if (s[last].t_s - s[i].t_s >= options.settle_s) {
      std::size_t first_averaged = last;
      while (first_averaged > i && s[last].t_s - s[first_averaged - 1].t_s <= options.average_s)
        --first_averaged;
      windows.push_back({i, first_averaged, last});
    }
    i = last + 1;
  }
  return windows;
}

std::vector<PositionErrorSample> position_errors_at_revisited_poses(
    const std::vector<ims::SmoothedState>& trajectory, const RobotLog& log,
    const KinematicModel& kinematics, const Eigen::Isometry3d& T_W_R, const Eigen::Vector3d& p_H_S,
    double time_offset_s, const RevisitedPoseOptions& options) {
  const auto& s = log.samples;
  // The mean of p_IMS - p_FK over samples [first, last]; nullopt outside the trajectory.
  const auto mean_difference = [&](std::size_t first,
                                   std::size_t last) -> std::optional<Eigen::Vector3d> {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (std::size_t k = first; k <= last; ++k) {
      Eigen::Isometry3d T_W_S;
      if (!interpolate_sensor_pose(trajectory, s[k].t_s + time_offset_s, T_W_S))
        return std::nullopt;
      const Eigen::Vector3d p_fk =
          T_W_R * (forward_kinematics<double>(kinematics, s[k].q_internal_rad) * p_H_S);
      sum += T_W_S.translation() - p_fk;
    }
    return sum / double(last - first + 1);
  };
  std::vector<SettledStandstill> standstills;
  for (const StandstillWindow& w : settled_standstill_windows(log, options))
    if (const auto d = mean_difference(w.first_averaged, w.last))
      standstills.push_back(
          {w.first, w.last, s[w.last].t_s, s[w.first].q_desired_rad, s[w.first].payload_kg, *d});
  // One sample per standstill, at its end; errors from the solve below.
  std::vector<PositionErrorSample> out;
  for (const SettledStandstill& st : standstills)
    out.push_back({st.end_robot_s + time_offset_s, Eigen::Vector3d::Zero(), false});
  if (out.empty()) return out;
  const auto same_pose = [&](const JointVector& a, const JointVector& b) {
    return (a - b).cwiseAbs().maxCoeff() <= options.same_pose_tolerance_rad;
  };
  // The normal equations of the least squares in the header, the same for the three axes:
  // H e = g_axis, e_0 fixed at 0 (H's first row and column dropped: unknowns e_1 .. e_{n-1}).
  const std::size_t n = standstills.size();
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(Eigen::Index(n), Eigen::Index(n));
  Eigen::MatrixXd g = Eigen::MatrixXd::Zero(Eigen::Index(n), 3);
  // w (e_k - e_j - m)^2 for the difference m [m] with weight w [1/m^2].
  const auto add_difference = [&](std::size_t j, std::size_t k, double w,
                                  const Eigen::Vector3d& m) {
    const auto J = Eigen::Index(j), K = Eigen::Index(k);
    H(J, J) += w;
    H(K, K) += w;
    H(J, K) -= w;
    H(K, J) -= w;
    g.row(K) += w * m.transpose();
    g.row(J) -= w * m.transpose();
  };
  const double w_visit = 1.0 / (2.0 * options.repeatability_m * options.repeatability_m);
  for (std::size_t k = 1; k < n; ++k) {
    const SettledStandstill& st = standstills[k];
    const double dt = std::max(st.end_robot_s - standstills[k - 1].end_robot_s, 1e-3);
    add_difference(k - 1, k, 1.0 / (options.position_walk_m2_per_s * dt), Eigen::Vector3d::Zero());
    // A payload change at rest: the standstill before it ends where this one begins.
    if (standstills[k - 1].last + 1 == st.first &&
        same_pose(st.q_desired_rad, standstills[k - 1].q_desired_rad)) {
      add_difference(k - 1, k, w_visit, Eigen::Vector3d::Zero());
      out[k].revisit = true;
      continue;
    }
    // The latest earlier visit of the same pose with the same payload.
    for (std::size_t j = k; j-- > 0;) {
      if (standstills[j].payload_kg == st.payload_kg &&
          same_pose(standstills[j].q_desired_rad, st.q_desired_rad)) {
        add_difference(j, k, w_visit, st.difference_W - standstills[j].difference_W);
        out[k].revisit = true;
        break;
      }
    }
  }
  if (n > 1) {
    const auto m = Eigen::Index(n - 1);
    const Eigen::MatrixXd e = H.bottomRightCorner(m, m).ldlt().solve(g.bottomRows(m));
    for (std::size_t k = 1; k < n; ++k) out[k].error_W = e.row(Eigen::Index(k - 1)).transpose();
  }
  return out;
}

void remove_position_errors(std::span<ims::SmoothedState> trajectory,
                            const std::vector<PositionErrorSample>& errors) {
  if (errors.empty()) return;
  std::size_t next = 0;  // first error sample after the state's time
  for (ims::SmoothedState& state : trajectory) {
    const double t = state.state.t_s;
    while (next < errors.size() && errors[next].t_s <= t) ++next;
    Eigen::Vector3d e;
    if (next == 0) {
      e = errors.front().error_W;
    } else if (next == errors.size()) {
      e = errors.back().error_W;
    } else {
      const PositionErrorSample& a = errors[next - 1];
      const PositionErrorSample& b = errors[next];
      const double f = (t - a.t_s) / (b.t_s - a.t_s);
      e = (1.0 - f) * a.error_W + f * b.error_W;
    }
    state.state.p_W -= e;
  }
}

}  // namespace imscal::calib
