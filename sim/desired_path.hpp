#pragma once
// The desired joint motion that the robot's interpolator hands to the joint controllers every
// control cycle: the output of path planning (sim/motion_planner.hpp) and the input of the plant
// (sim/plant_simulator.hpp). Also the q_desired column of robot.csv.
#include <string>
#include <vector>

#include "calib/robot_description.hpp"

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

// A piece of the program, for reports and for splitting the data (rest poses, moves).
struct PathSegment {
  SegmentKind kind = SegmentKind::kRest;
  std::string label;  // from the program, e.g. "A2 fast +", or generated ("rest 3")
  double begin_s = 0.0;
  double end_s = 0.0;
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
