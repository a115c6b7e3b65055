#pragma once
// The tests' own measure of how much of the joints' acceleration and jerk limits a planned
// segment uses (written apart from sim/cartesian_timing.cpp, to check it): over the segment's
// cycles (first, last], the largest |q_ddot_i| / a_max_i and |q_ddot_i[k] - q_ddot_i[k-1]| /
// cycle / j_max_i (the jerk of the first cycle counted from the sample before it).
#include <cmath>
#include <optional>

#include "robot/robot_description.hpp"
#include "sim/desired_path.hpp"

namespace imscal::sim {

struct MeasuredLimitUse {
  double acceleration = 0.0, jerk = 0.0;
  int acceleration_joint = -1, jerk_joint = -1;
};

inline MeasuredLimitUse measured_limit_use(const DesiredJointPath& path, const PathSegment& seg,
                                           const calib::JointVector& max_acceleration,
                                           const std::optional<calib::JointVector>& max_jerk) {
  const auto first = static_cast<std::size_t>(std::lround(seg.begin_s / path.cycle_s));
  const auto last = static_cast<std::size_t>(std::lround(seg.end_s / path.cycle_s));
  MeasuredLimitUse use;
  for (std::size_t k = first + 1; k <= last; ++k) {
    const calib::JointVector& qdd = path.samples[k].qdd_rad_s2;
    const calib::JointVector& before = path.samples[k - 1].qdd_rad_s2;
    for (int i = 0; i < calib::kJointCount; ++i) {
      const double a = std::abs(qdd(i)) / max_acceleration(i);
      if (a > use.acceleration) use.acceleration = a, use.acceleration_joint = i;
      if (!max_jerk) continue;
      const double j = std::abs(qdd(i) - before(i)) / path.cycle_s / (*max_jerk)(i);
      if (j > use.jerk) use.jerk = j, use.jerk_joint = i;
    }
  }
  return use;
}

}  // namespace imscal::sim
