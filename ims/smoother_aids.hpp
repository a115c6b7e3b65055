#pragma once
// What an outside source knows about the sensor's motion, for the zero-velocity smoother
// (ims/zupt_smoother.hpp). On a robot that source is its joint encoders at commanded standstill
// (calib/encoder_motion.hpp): they see whether the arm is still or still creeping after a move,
// which the IMS alone cannot tell apart from rest below ~1e-3 rad/s (the quantisation of 1 ms
// gyro increments hides slower turns in a 20 ms test window).
//
//  - still: intervals (IMS clock) in which the sensor is still. When given, the smoother applies
//    its zero-velocity and zero-rate updates only to the IMS-detected rests inside them: a
//    creeping arm that the IMS takes for resting would otherwise be "pinned" at a velocity of up
//    to ~1e-3 m/s with a sigma of 1e-5 m/s, which bends the trajectory by millimetres.
//  - velocity: the sensor's velocity in W at given times with its 1-sigma (a series; the
//    smoother interpolates it linearly at its update instants, where two neighbours lie at most
//    max_velocity_gap_s apart), applied as a measurement of the velocity state.
#include <Eigen/Core>
#include <optional>
#include <vector>

namespace imscal::ims {

struct TimeInterval {
  double begin_s = 0.0;
  double end_s = 0.0;
};

struct VelocitySample {
  double t_s = 0.0;                               // IMS clock
  Eigen::Vector3d v_W = Eigen::Vector3d::Zero();  // [m/s]
  double sigma_m_s = 0.0;                         // 1-sigma per axis [m/s]
};

struct SmootherAids {
  std::optional<std::vector<TimeInterval>> still;  // sorted, disjoint; nullopt: no restriction
  std::vector<VelocitySample> velocity;            // sorted by time
  double max_velocity_gap_s = 0.011;
};

}  // namespace imscal::ims
