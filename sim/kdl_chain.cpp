#include "sim/kdl_chain.hpp"

#include <cmath>

namespace imscal::sim {

KDL::Frame to_kdl_frame(const Eigen::Isometry3d& pose) {
  const Eigen::Matrix3d& r = pose.linear();
  const Eigen::Vector3d& p = pose.translation();
  return KDL::Frame(KDL::Rotation(r(0, 0), r(0, 1), r(0, 2), r(1, 0), r(1, 1), r(1, 2), r(2, 0),
                                  r(2, 1), r(2, 2)),
                    KDL::Vector(p.x(), p.y(), p.z()));
}

KDL::RigidBodyInertia to_kdl_inertia(const calib::RigidBodyParameters& body) {
  const Eigen::Matrix3d& i = body.inertia_kg_m2;
  return KDL::RigidBodyInertia(
      body.mass_kg, KDL::Vector(body.com_m.x(), body.com_m.y(), body.com_m.z()),
      KDL::RotationalInertia(i(0, 0), i(1, 1), i(2, 2), i(0, 1), i(0, 2), i(1, 2)));
}

KDL::Chain build_kdl_chain(const calib::RobotDescription& robot, const KdlChainOptions& options) {
  const calib::KinematicModel& model = robot.kinematics;
  KDL::Chain chain;
  chain.addSegment(
      KDL::Segment("base", KDL::Joint("base_fixed", KDL::Joint::Fixed), to_kdl_frame(model.T_R_0)));
  for (int i = 0; i < calib::kJointCount; ++i) {
    const calib::DhParameters& dh = model.dh[i];
    const calib::JointDescription& joint = robot.joints[i];
    const double rotor_inertia =
        options.include_reflected_motor_inertia
            ? joint.drive.gear_ratio * joint.drive.gear_ratio * joint.drive.motor_inertia_kg_m2
            : 0.0;
    // The joint has no KDL offset: the segment's tip frame is given at q = 0 with the DH
    // offset in it, and KDL turns it about the joint axis by q.
    KDL::Joint kdl_joint;
    KDL::Frame tip_at_zero;
    if (model.convention == calib::DhConvention::kStandard) {
      kdl_joint = KDL::Joint(joint.name, KDL::Joint::RotZ, 1.0, 0.0, rotor_inertia);
      tip_at_zero = KDL::Frame::DH(dh.a_m, dh.alpha_rad, dh.d_m, dh.offset_rad);
    } else {
      // Craig: the joint turns about z_i = Rx(alpha_{i-1}) z through (a_{i-1}, 0, 0).
      kdl_joint = KDL::Joint(joint.name, KDL::Vector(dh.a_m, 0.0, 0.0),
                             KDL::Vector(0.0, -std::sin(dh.alpha_rad), std::cos(dh.alpha_rad)),
                             KDL::Joint::RotAxis, 1.0, 0.0, rotor_inertia);
      tip_at_zero = KDL::Frame::DH_Craig1989(dh.a_m, dh.alpha_rad, dh.d_m, dh.offset_rad);
    }
    chain.addSegment(KDL::Segment(joint.name, kdl_joint, tip_at_zero, to_kdl_inertia(joint.link)));
  }
  // Tool body and payload are given in T; KDL wants them in the flange segment's frame H.
  KDL::RigidBodyInertia on_flange = KDL::RigidBodyInertia::Zero();
  const KDL::Frame T_H_T = to_kdl_frame(robot.tool.T_H_T);
  if (options.include_tool_body) on_flange = on_flange + T_H_T * to_kdl_inertia(robot.tool.body);
  if (options.payload) on_flange = on_flange + T_H_T * to_kdl_inertia(*options.payload);
  chain.addSegment(KDL::Segment("flange", KDL::Joint("flange_fixed", KDL::Joint::Fixed),
                                to_kdl_frame(model.T_6_H), on_flange));
  if (options.end_at_tool) {
    chain.addSegment(KDL::Segment("tool", KDL::Joint("tool_fixed", KDL::Joint::Fixed), T_H_T));
  }
  return chain;
}

}  // namespace imscal::sim
