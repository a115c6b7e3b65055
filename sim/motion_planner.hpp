#pragma once
// Turns a motion program (sim/motion_program.hpp) into the desired joint path that the robot's
// interpolator hands to the joint controllers every control cycle (sim/desired_path.hpp).
//
// - Sampling: at the robot's controller cycle (RobotDescription::controller_cycle_s). Every
//   segment lasts an integer number of cycles: a rest is rounded to the nearest cycle (at least
//   one), a move's profile is stretched (slowed down, s(t / k), k <= 1 + cycle / duration) to the
//   next whole cycle, so limits stay respected and segment borders fall on samples.
// - PTP: a straight line in joint space, q = q0 + (q1 - q0) s(t) with one normalised profile
//   s: 0 -> 1 for all joints, whose limits are the tightest of the joints' own
//   (velocity_scale * v_max_i / |dq_i|, acceleration_scale * a_max_i / |dq_i|, likewise jerk):
//   all joints start and end together, and the slowest joint sets the time.
//   v_max_i from the robot file, a_max_i and j_max_i from the program.
// - LIN / CIRC: the flange origin follows the line/arc with a profile along the arc length
//   (path velocity, acceleration, jerk); orientation constant or slerp (R0 exp(sigma theta k),
//   sigma = s / L). Joints by IK (the solver of the arm's class, robot/ik_solver.hpp) at every
//   sample (configuration and 2 pi branch of the previous sample), joint rates from the Cartesian
//   twist, q_dot = J^-1 [v; w], and accelerations q_ddot = J^-1 ([a; w_dot] - J_dot q_dot), J_dot
//   q_dot in closed form (jacobian_rate_times_joint_rate): exact up to rounding, no finite
//   differences. Joint limits: a LIN/CIRC move whose programmed timing would take a joint beyond
//   its acceleration limit (or, jerk_limited, its jerk limit per cycle; both from the program) by
//   more than kJointLimitTolerance is slowed, as a controller does: same path and orientation
//   law, a slower profile (sim/cartesian_timing.hpp: longer ramps where they suffice, a lower
//   path speed where not). Logged (info) and recorded in PathSegment::timing (programmed and
//   planned limits, speeds and joint use); a move within the limits keeps its timing bit for bit.
// - Refusals: InputError(program file, line of the segment, "segments[i] 'label'", problem with
//   the joint and the value) when a target is unreachable or outside the joint limits, a
//   Cartesian move comes within kSingularityTolerance of a singularity, a joint would exceed its
//   max velocity, or the IK solution jumps (change of configuration).
#include <Eigen/Core>

#include "robot/robot_description.hpp"
#include "sim/desired_path.hpp"
#include "sim/motion_program.hpp"

namespace imscal::sim {

// Singularity margin for Cartesian moves (IkOptions::singularity_tolerance): 10 mm of the wrist
// centre (UR class: wrist point) from the shoulder singularity, |sin| 0.01 (0.57 deg) of the
// elbow and wrist bends. Closer, the joint rates
// of a constant path speed grow like 1 / distance and the IK branch is ill-defined.
inline constexpr double kSingularityTolerance = 0.01;

DesiredJointPath plan_motion(const calib::RobotDescription& robot, const MotionProgram& program);

// J_dot(q, q_dot) * q_dot for the geometric Jacobian of robot/jacobian.hpp (flange origin
// velocity and angular velocity in R): the velocity-product term of the flange acceleration,
// [a; w_dot] = J q_ddot + J_dot q_dot.
Eigen::Matrix<double, 6, 1> jacobian_rate_times_joint_rate(const calib::KinematicModel& model,
                                                           const calib::JointVector& q,
                                                           const calib::JointVector& q_dot);

}  // namespace imscal::sim
