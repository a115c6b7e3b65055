#pragma once
// A robot read from a URDF (parsed with urdfdom) and turned into the project's robot model.
//
// The serial chain from a base link to a tip link (by default the URDF's root and `tool0`) must
// hold exactly six revolute (or continuous) joints; fixed joints are folded into their
// neighbours. The chain is converted to standard DH exactly (Spong 2006, sec. 3.2.3: z_{i-1}
// along joint i's axis with the URDF's sign, x_i along the common normal of z_{i-1} and z_i, d = 0
// where two axes are parallel): the URDF's joint value is the DH joint angle q, the URDF's base
// link is the base R and the tip link is the flange H, so T_R_H(q) equals the URDF's
// T(base <- tip)(q) up to rounding. Link inertials (with those of links fixed to them on the
// chain) are expressed in the DH frame of their link; links off the chain are ignored.
//
// What a URDF lacks comes from an optional side file next to it: `<stem>.imscal.yaml` for
// `<stem>.urdf` (format in datasets/FORMAT.md, "URDF robots"): name, payload, reach, controller
// cycle, the chain's end links, the mounted tool and per joint the drive and controller. Without
// it the robot carries kinematics, limits and inertials only; drives and controllers stay at
// their zero defaults (enough for kinematics, calibration and rigid-body dynamics, not for the
// simulator's plant).
#include <Eigen/Geometry>
#include <array>
#include <filesystem>
#include <string>

#include "robot/robot_description.hpp"

namespace imscal::calib {

// The chain as the URDF states it: T(base <- tip)(q) = F_1 R_1(q_1) F_2 R_2(q_2) ... R_6(q_6) F_7
// with F_i the fixed joint origins (fixed joints merged) and R_i a rotation about axis_i.
struct UrdfChain {
  std::string robot_name;
  std::string base_link;
  std::string tip_link;
  std::array<std::string, kJointCount> joint_names;
  std::array<Eigen::Isometry3d, kJointCount + 1> fixed;  // F_1 .. F_7
  std::array<Eigen::Vector3d, kJointCount> axis;         // unit, in the joint frame
};

// Reads the chain base_link -> tip_link (empty base_link: the root link). InputError names the
// file, the line of the offending element where it can be found, and the joint or link.
UrdfChain read_urdf_chain(const std::filesystem::path& urdf, const std::string& base_link,
                          const std::string& tip_link);

// T(base <- tip)(q) straight from the URDF's joint origins and axes (the reference the DH
// conversion is checked against).
Eigen::Isometry3d urdf_chain_pose(const UrdfChain& chain, const JointVector& q);

// The robot of a URDF with its side file `<stem>.imscal.yaml` when present.
RobotDescription load_urdf_robot(const std::filesystem::path& urdf);

// The side file's name for a URDF: `ur10.urdf` -> `ur10.imscal.yaml`.
std::filesystem::path urdf_side_file(const std::filesystem::path& urdf);

}  // namespace imscal::calib
