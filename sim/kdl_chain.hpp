#pragma once
// A KDL::Chain built from our robot description, with the link inertias, for the simulator's
// rigid-body dynamics (KDL's recursive Newton-Euler, ChainDynParam) and as a test oracle for our
// kinematics. robot/ and calib/ do not depend on KDL; only sim/ does.
//
// Segments, base to tip: "base" (fixed, T_R_0), "<joint name>" x 6 (revolute; tip = DH link
// frame i, carrying link i's inertia), "flange" (fixed, T_6_H, carrying the tool body and the
// payload, transformed into H), and, with end_at_tool, "tool" (fixed, massless, T_H_T).
// So the chain's end frame is the flange H (or the tool frame T) and its root is R: KDL's forward
// kinematics gives T_R_H, its Jacobian the twist of H in R (see robot/jacobian.hpp).
// Joint positions are our q [rad] (offsets are in the segment frames, not in KDL joints).
#include <kdl/chain.hpp>
#include <optional>

#include "robot/robot_description.hpp"

namespace imscal::sim {

struct KdlChainOptions {
  bool end_at_tool = false;       // add the massless "tool" segment so that the end frame is T
  bool include_tool_body = true;  // the mounted tool's (e.g. the IMS's) mass on the flange
  std::optional<calib::RigidBodyParameters> payload;  // extra load, given in the tool frame T
  // Adds the reflected motor inertia N^2 * J_m as KDL joint inertia: only for rigid-joint
  // models. An elastic-joint simulation keeps the motor as its own body (leave this false).
  bool include_reflected_motor_inertia = false;
};

KDL::Chain build_kdl_chain(const calib::RobotDescription& robot,
                           const KdlChainOptions& options = {});

// KDL rigid-body inertia of a body given about its centre of mass in its own frame.
KDL::RigidBodyInertia to_kdl_inertia(const calib::RigidBodyParameters& body);
KDL::Frame to_kdl_frame(const Eigen::Isometry3d& pose);

}  // namespace imscal::sim
