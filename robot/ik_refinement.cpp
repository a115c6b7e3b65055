#include "robot/ik_refinement.hpp"

#include <fmt/format.h>

#include <Eigen/LU>
#include <cmath>

#include "robot/forward_kinematics.hpp"
#include "robot/jacobian.hpp"

namespace imscal::calib {
namespace {

// Orientation error as a rotation vector in R: R_error = R_target * R^T.
Eigen::Vector3d rotation_error(const Eigen::Matrix3d& R_target, const Eigen::Matrix3d& R) {
  const Eigen::AngleAxisd error(R_target * R.transpose());
  return error.angle() * error.axis();
}

}  // namespace

void refine_ik(const KinematicModel& model, const Eigen::Isometry3d& T_R_H,
               const IkOptions& options, IkResult& result) {
  auto errors = [&](const JointVector& q, Eigen::Matrix<double, 6, 1>& e) {
    const Eigen::Isometry3d pose = forward_kinematics<double>(model, q);
    e.head<3>() = T_R_H.translation() - pose.translation();
    e.tail<3>() = rotation_error(T_R_H.linear(), pose.linear());
  };
  Eigen::Matrix<double, 6, 1> e;
  errors(result.q, e);
  int iteration = 0;
  while (iteration < options.max_newton_iterations &&
         (e.head<3>().norm() > options.position_tolerance_m ||
          e.tail<3>().norm() > options.orientation_tolerance_rad)) {
    const Jacobian jacobian = geometric_jacobian(model, result.q);
    JointVector step = jacobian.partialPivLu().solve(e);
    // Limit the step so that a poor start cannot jump to another solution branch.
    constexpr double kMaxStep = 0.3;  // rad
    if (!step.allFinite()) break;
    if (step.norm() > kMaxStep) step *= kMaxStep / step.norm();
    ++iteration;
    // Backtracking: halve the step until the error shrinks; if even a tiny step does not
    // help, rounding level (or a singular start) is reached.
    bool improved = false;
    for (int halving = 0; halving < 20 && !improved; ++halving, step *= 0.5) {
      const JointVector candidate = result.q + step;
      Eigen::Matrix<double, 6, 1> candidate_error;
      errors(candidate, candidate_error);
      if (candidate_error.norm() < e.norm()) {
        result.q = candidate;
        e = candidate_error;
        improved = true;
      }
    }
    if (!improved) break;
  }
  result.newton_iterations = iteration;
  result.position_error_m = e.head<3>().norm();
  result.orientation_error_rad = e.tail<3>().norm();
}

bool fit_joint_limits(const KinematicModel& model, const IkOptions& options, JointVector& q) {
  bool all_inside = true;
  for (int i = 0; i < kJointCount; ++i) {
    const double reference = options.q_near ? (*options.q_near)(i) : 0.0;
    double best = q(i);
    bool found = false;
    for (int turns = -3; turns <= 3; ++turns) {
      const double candidate = q(i) + 2.0 * M_PI * turns;
      if (candidate < model.lower_limit_rad(i) || candidate > model.upper_limit_rad(i)) {
        continue;
      }
      if (!found || std::abs(candidate - reference) < std::abs(best - reference)) {
        best = candidate;
        found = true;
      }
    }
    if (found) {
      q(i) = best;
    } else {
      all_inside = false;
    }
  }
  return all_inside;
}

std::string describe_joints_outside_limits(const KinematicModel& model, const JointVector& q) {
  std::string outside;
  for (int i = 0; i < kJointCount; ++i) {
    if (q(i) < model.lower_limit_rad(i) || q(i) > model.upper_limit_rad(i)) {
      outside += fmt::format(" q{}={:.6f} rad not in [{:.6f}, {:.6f}]", i + 1, q(i),
                             model.lower_limit_rad(i), model.upper_limit_rad(i));
    }
  }
  return outside;
}

}  // namespace imscal::calib
