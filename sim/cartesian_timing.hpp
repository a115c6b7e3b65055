#pragma once
// Timing of a Cartesian segment (lin, circ, circle) within the joints' acceleration and jerk
// limits. The joints follow a path q(s) of the arc length s that the geometry and the
// orientation law alone fix, so for any path profile s(t)
//   q_dot = q' s_dot,   q_ddot = q'' s_dot^2 + q' s_ddot      (q' = dq/ds [rad/m], q'' [rad/m^2]):
// a velocity part, quadratic in the path speed (curvature, the arm's centripetal terms), and an
// acceleration part, linear in the path acceleration.
//
// A segment whose programmed timing uses more than 1 + kJointLimitTolerance of a limit is
// re-planned with the same profile kind and the limits (slowed_limits)
//   velocity V / k,   acceleration A / (k^2 m),   jerk J / (k^3 m^2),      k, m >= 1.
// k slows the whole segment uniformly, s(t / k), like the controller's override: every joint's
// acceleration drops exactly by k^2 and its jerk by k^3. m stretches only the acceleration ramps
// in time (same velocity; a ramp's phases last m times longer), which relieves the acceleration
// part (a line whose path acceleration is too high for a joint) but not the velocity part (a
// small circle too fast for a joint even at constant speed).
// The uniform k_u = max(sqrt(r_a), cbrt(r_j)) (r: the programmed timing's largest ratios)
// would do alone. choose_timing takes the fastest timing of the family (shortest segment; ties
// to the higher path speed): for speed factors k = k_u^(i/16), i = 0..16, the least ramp
// stretch m that brings every joint within its limits (bisection to 1e-4 relative; none if the
// velocity part alone exceeds a limit at that speed, or if every fit is slower than the best).
// Lines and large circles keep their programmed speed with longer ramps; a small circle, whose
// ramps are most of it, is slowed. Candidates are judged without IK, from q'(s), q''(s) at the
// programmed timing's samples (JointPathDerivatives, interpolated linearly: samples <= 1 mm apart
// at 0.5 m/s). The planner then samples the chosen timing by IK and checks it exactly; what the
// interpolation missed
// (~1e-6) it removes by a further uniform slow-down.
#include <functional>
#include <optional>
#include <vector>

#include "robot/robot_description.hpp"
#include "sim/desired_path.hpp"
#include "sim/motion_profile.hpp"

namespace imscal::sim {

struct JointLimits {
  calib::JointVector acceleration_rad_s2 = calib::JointVector::Zero();
  std::optional<calib::JointVector> jerk_rad_s3;  // none: the jerk is not limited
};

// Accumulates JointLimitUse over consecutive control cycles.
class JointLimitMeter {
 public:
  // qdd_before: the planned acceleration of the cycle before the first one added (the jerk of
  // the first cycle is measured from it).
  JointLimitMeter(const JointLimits& limits, double cycle_s, const calib::JointVector& qdd_before);
  void add(const calib::JointVector& qdd_rad_s2);
  const JointLimitUse& use() const { return use_; }

 private:
  JointLimits limits_;
  double cycle_s_;
  calib::JointVector previous_;
  JointLimitUse use_;
};

// q'(s) and q''(s) at increasing arc lengths s [m], interpolated linearly in between.
class JointPathDerivatives {
 public:
  // s_m must not decrease; an entry at the same s as the last one is ignored.
  void add(double s_m, const calib::JointVector& dq_ds, const calib::JointVector& d2q_ds2);
  // q_ddot = q''(s) s_dot^2 + q'(s) s_ddot at a state of a path profile [rad/s^2]. cursor: where
  // the last look-up ended (start with 0): a forward walk, O(1) per cycle along a profile.
  calib::JointVector acceleration(const ProfileState& path, std::size_t& cursor) const;

 private:
  std::vector<double> s_;
  std::vector<calib::JointVector> dq_ds_, d2q_ds2_;
};

// The family of slowed timings above: speed_factor k, ramp_factor m.
ProfileLimits slowed_limits(const ProfileLimits& programmed, double speed_factor,
                            double ramp_factor);

// What choose_timing asks about a candidate timing (its path limits).
struct TimingJudge {
  std::function<double(const ProfileLimits&)> duration;  // of the segment [s], whole cycles
  std::function<bool(const ProfileLimits&)> within;      // every joint within its limits
};

struct TimingChoice {
  double speed_factor = 1.0;  // k
  double ramp_factor = 1.0;   // m
  ProfileLimits limits;       // slowed_limits(programmed, k, m)
  double duration_s = 0.0;
  int trials = 0;  // calls of judge.within
};

// The fastest timing of the family that the judge finds within the limits (see above).
// programmed_use: the programmed timing's use (its ratio > 1 + kJointLimitTolerance). Throws
// std::logic_error if even the uniform slow-down is never judged within (cannot happen for a
// judge whose verdict follows the joint accelerations, which that slow-down scales exactly).
TimingChoice choose_timing(const ProfileLimits& programmed, const JointLimitUse& programmed_use,
                           const TimingJudge& judge);

}  // namespace imscal::sim
