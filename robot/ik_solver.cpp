#include "robot/ik_solver.hpp"

#include <fmt/format.h>

#include <stdexcept>

#include "robot/ik_refinement.hpp"
#include "robot/inverse_kinematics.hpp"
#include "robot/ur_inverse_kinematics.hpp"

namespace imscal::calib {

std::string to_string(const ArmConfiguration& c) {
  return fmt::format("{}/{}/{}", c.shoulder_front ? "front" : "back", c.elbow_up ? "up" : "down",
                     c.wrist_flip ? "flip" : "noflip");
}

const char* to_string(IkStatus status) {
  switch (status) {
    case IkStatus::kOk:
      return "ok";
    case IkStatus::kUnreachable:
      return "unreachable";
    case IkStatus::kShoulderSingular:
      return "shoulder singular";
    case IkStatus::kElbowSingular:
      return "elbow singular";
    case IkStatus::kWristSingular:
      return "wrist singular";
    case IkStatus::kOutsideJointLimits:
      return "outside joint limits";
    case IkStatus::kNotConverged:
      return "not converged";
  }
  return "?";
}

std::vector<ArmConfiguration> IkSolver::all_configurations() {
  std::vector<ArmConfiguration> out;
  for (bool front : {true, false}) {
    for (bool up : {true, false}) {
      for (bool flip : {false, true}) out.push_back({front, up, flip});
    }
  }
  return out;
}

std::vector<IkResult> IkSolver::solve_all(const Eigen::Isometry3d& T_R_H,
                                          const IkOptions& options) const {
  std::vector<IkResult> out;
  for (const ArmConfiguration& c : all_configurations()) out.push_back(solve(T_R_H, c, options));
  return out;
}

void IkSolver::finish_refined(bool ideal, const ArmConfiguration& configuration,
                              const IkOptions& options, IkResult& result) const {
  auto fail = [&](IkStatus status, std::string reason) {
    result.status = status;
    result.reason = std::move(reason);
  };
  if (result.position_error_m > options.position_tolerance_m ||
      result.orientation_error_rad > options.orientation_tolerance_rad) {
    return fail(IkStatus::kNotConverged,
                fmt::format("Newton refinement stopped at {:.3g} m, {:.3g} rad after {} steps",
                            result.position_error_m, result.orientation_error_rad,
                            result.newton_iterations));
  }
  if (!ideal) {
    const SingularityMeasures measures = singularity_measures(result.q);
    const double tolerance = options.singularity_tolerance;
    if (measures.shoulder_m < tolerance) {
      return fail(IkStatus::kShoulderSingular, "refined solution at the shoulder singularity");
    }
    if (measures.elbow < tolerance) {
      return fail(IkStatus::kElbowSingular, "refined solution at the elbow singularity");
    }
    if (measures.wrist < tolerance) {
      return fail(IkStatus::kWristSingular, "refined solution at the wrist singularity");
    }
    const ArmConfiguration reached = configuration_of(result.q);
    if (!(reached == configuration)) {
      return fail(IkStatus::kNotConverged,
                  "Newton refinement went over to the " + to_string(reached) + " configuration");
    }
  }
  if (!fit_joint_limits(model_, options, result.q) && options.enforce_joint_limits) {
    return fail(IkStatus::kOutsideJointLimits,
                "outside joint limits:" + describe_joints_outside_limits(model_, result.q));
  }
  result.status = IkStatus::kOk;
  result.reason.clear();
}

IkResult IkSolver::solve_nearest(const Eigen::Isometry3d& T_R_H, const JointVector& q_reference,
                                 IkOptions options) const {
  if (!options.q_near) options.q_near = q_reference;
  ArmConfiguration configuration = configuration_of(q_reference);
  IkResult own = solve(T_R_H, configuration, options);
  configuration.wrist_flip = !configuration.wrist_flip;
  IkResult flipped = solve(T_R_H, configuration, options);
  if (!flipped.ok()) return own;
  if (!own.ok()) return flipped;
  const double own_distance = (own.q - q_reference).cwiseAbs().maxCoeff();
  const double flipped_distance = (flipped.q - q_reference).cwiseAbs().maxCoeff();
  return flipped_distance < own_distance ? flipped : own;
}

std::unique_ptr<IkSolver> make_inverse_kinematics(const KinematicModel& model) {
  std::string spherical_problem;
  try {
    return std::make_unique<InverseKinematics>(model);
  } catch (const std::invalid_argument& e) {
    spherical_problem = e.what();
  }
  try {
    return std::make_unique<UrInverseKinematics>(model);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(fmt::format(
        "no inverse kinematics for this arm: it is neither of the spherical-wrist class ({}) nor "
        "of the UR class ({})",
        spherical_problem, e.what()));
  }
}

}  // namespace imscal::calib
