#pragma once
// The steps every closed-form inverse-kinematics solver shares after its closed form: Newton
// refinement on the full model (absorbs calibrated departures from the ideal structure), the
// choice of the 2*pi-equivalents within the joint limits, and the words of a limit failure.
#include <Eigen/Geometry>
#include <string>

#include "robot/ik_solver.hpp"
#include "robot/robot_description.hpp"

namespace imscal::calib {

// Newton steps q += J^-1 e (step <= 0.3 rad, backtracking) from result.q until the flange pose
// error is below the options' tolerances; fills q, the errors and the step count.
void refine_ik(const KinematicModel& model, const Eigen::Isometry3d& T_R_H,
               const IkOptions& options, IkResult& result);

// Each angle's 2*pi-equivalent within the limits nearest to options.q_near (else 0); false if
// some angle has none (that angle is left as it was).
bool fit_joint_limits(const KinematicModel& model, const IkOptions& options, JointVector& q);

// " q2=... rad not in [..., ...]" for every joint outside its limits.
std::string describe_joints_outside_limits(const KinematicModel& model, const JointVector& q);

}  // namespace imscal::calib
