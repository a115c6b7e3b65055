#pragma once
// The desired joint motion that the robot's interpolator hands to the joint controllers every
// control cycle: the output of path planning (sim/motion_planner.hpp) and the input of the plant
// (sim/plant_simulator.hpp). Also the q_desired column of robot.csv.
#include <optional>
#include <string>
#include <vector>

#include "robot/robot_description.hpp"
#include "sim/motion_profile.hpp"

namespace imscal::sim {

// One interpolation cycle. Derivatives are those of the planned profile (not finite differences),
// so the controller's velocity feed-forward sees the planned joint velocity.
struct DesiredJointSample {
  double t_s = 0.0;
  calib::JointVector q_rad = calib::JointVector::Zero();
  calib::JointVector qd_rad_s = calib::JointVector::Zero();
  calib::JointVector qdd_rad_s2 = calib::JointVector::Zero();
  int payload_index = 0;  // into DesiredJointPath::payloads: the load carried in this cycle
};

enum class SegmentKind { kRest, kPtp, kLinear, kCircular };

// How much of the joints' acceleration and jerk limits (the program's joint_acceleration_deg_s2,
// joint_jerk_deg_s3) a segment's cycles use: the largest |q_ddot_i| / a_max_i and |jerk_i| /
// j_max_i, jerk_i = (q_ddot_i[k] - q_ddot_i[k-1]) / cycle (per control cycle, from the cycle
// before the segment on), with the joint (0 = A1) where each is largest, -1 if none moves.
// The jerk is counted only for jerk_limited moves of a program with joint jerks (a trapezoid's
// acceleration steps have no finite jerk, as for PTP).
struct JointLimitUse {
  double acceleration_ratio = 0.0;
  int acceleration_joint = -1;
  double jerk_ratio = 0.0;
  int jerk_joint = -1;

  double ratio() const { return acceleration_ratio > jerk_ratio ? acceleration_ratio : jerk_ratio; }
  bool jerk_binds() const { return jerk_ratio > acceleration_ratio; }
  int joint() const { return jerk_binds() ? jerk_joint : acceleration_joint; }
};

// The timing of a Cartesian segment (lin, circ, circle): its path profile's limits as programmed
// and as planned. The planner slows a segment whose programmed timing would take a joint beyond
// its acceleration or jerk limit; the geometric path and the orientation law stay the same, only
// s(t) changes (sim/cartesian_timing.hpp says how).
struct CartesianTiming {
  ProfileLimits programmed;  // path velocity [m/s], acceleration [m/s^2], jerk [m/s^3]
  ProfileLimits planned;     // == programmed unless slowed
  double programmed_peak_velocity_m_s = 0.0;  // reached by the programmed profile (short moves
  double planned_peak_velocity_m_s = 0.0;     // may not reach their velocity limit)
  double programmed_duration_s = 0.0;         // whole cycles; the planned one: end_s - begin_s
  JointLimitUse programmed_use;               // of the programmed timing
  JointLimitUse planned_use;  // of the planned one: every ratio <= 1 + kJointLimitTolerance
  bool slowed = false;
};

// A ratio up to 1 + 1e-6 counts as within the limit: a path programmed exactly at a joint's
// limit (up to rounding and the sampling of the peak) is not slowed.
inline constexpr double kJointLimitTolerance = 1e-6;

// A piece of the program, for reports and for splitting the data (rest poses, moves).
struct PathSegment {
  SegmentKind kind = SegmentKind::kRest;
  std::string label;  // from the program, e.g. "A2 fast +", or generated ("rest 3")
  double begin_s = 0.0;
  double end_s = 0.0;
  std::optional<CartesianTiming> timing = std::nullopt;  // lin and circ segments only
};

// A load on the flange: mass properties given in the tool frame T (calib::ToolDescription), on
// top of the mounted tool (the IMS) itself. Changed only while the robot is at rest.
struct Payload {
  std::string name;
  calib::RigidBodyParameters body;
};

struct DesiredJointPath {
  double cycle_s = 0.002;                   // samples[k].t_s = k * cycle_s, k = 0..N-1
  std::vector<DesiredJointSample> samples;  // starts and ends at rest
  std::vector<PathSegment> segments;        // contiguous, cover [0, samples.back().t_s]
  std::vector<Payload> payloads;            // at least one (mass 0 = no payload)
};

}  // namespace imscal::sim
