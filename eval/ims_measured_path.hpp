#pragma once
// The attained joint angles as the IMS chain measures them (paper, section 4: "the actual paths
// measured with the inertial measurement system"): a plant run's link-side flange motion
// recorded by the scenario's simulated IMS (sim::record_ims: sensor errors drawn from its spec,
// noise), corrected by the unit's own calibration (scale factors and misalignments, as a lab
// does with its IMS's calibration sheet), then mechanized, zero-velocity smoothed and turned into
// joint angles by inverse kinematics (calib::joint_space_errors) with the frames, biases and
// clock offset of the measurement setup. The frames are the simulation's own here: how well a
// campaign finds them is the frame calibration's figure (tests/calib).
#include <cstdint>
#include <vector>

#include "ims/zupt_smoother.hpp"
#include "robot/robot_description.hpp"
#include "sim/desired_path.hpp"
#include "sim/plant_simulator.hpp"
#include "sim/scenario.hpp"

namespace imscal::eval {

struct ImsJointMeasurement {
  // One entry per plant sample: the measured link-side angles, valid[k] false where the chain
  // gave none (outside the IMS record, inverse kinematics near the wrist singularity).
  std::vector<calib::JointVector> q_rad;
  std::vector<bool> valid;
  ims::ZuptSummary smoother;
};

// desired: the interpolator's desired angles (the robot log's q_desired, without a precontrol's
// offsets: the chain finds the program's standstills there); plant: its run, one
// sample per controller cycle, starting at rest (its first lead_in_s are the smoother's first
// rest). seed: the sensor errors' and noise's draw. Throws InputError (from the chain) when the
// record cannot be used.
// plant_robot: the simulated world's (the IMS rides on its flange); nominal: the chain's (the
// controller's log names it, the inverse kinematics use its geometry).
ImsJointMeasurement measure_joints_with_ims(const sim::Scenario& scenario,
                                            const calib::RobotDescription& plant_robot,
                                            const sim::NominalRobot& nominal,
                                            const sim::DesiredJointPath& desired,
                                            const sim::PlantLog& plant, double lead_in_s,
                                            std::uint64_t seed);

}  // namespace imscal::eval
