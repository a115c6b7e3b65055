#include "sim/cartesian_timing.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace imscal::sim {
namespace {

using calib::JointVector;
using calib::kJointCount;

// Bisection ends when the bracket [lo, hi] of a factor is this narrow (relative): the chosen
// timing is at most 1e-4 slower than the fastest one the search could find.
constexpr double kFactorResolution = 1e-4;

// Speed factors tried: k_uniform^(i / kSpeedFactorSteps), i = 0 .. kSpeedFactorSteps - 1, and
// k_uniform itself (steps of 5.6 % for k_uniform = 2.4).
constexpr int kSpeedFactorSteps = 16;

// Smallest x in [lo, hi] with ok(x), given !ok(lo) and ok(hi), to kFactorResolution.
template <typename Ok>
double smallest_ok(double lo, double hi, const Ok& ok) {
  while (hi > lo * (1.0 + kFactorResolution)) {
    const double mid = std::sqrt(lo * hi);  // factors: bisect their logarithm
    (ok(mid) ? hi : lo) = mid;
  }
  return hi;
}

// Largest x in [lo, hi] with ok(x), given ok(lo) and !ok(hi), to kFactorResolution.
template <typename Ok>
double largest_ok(double lo, double hi, const Ok& ok) {
  while (hi > lo * (1.0 + kFactorResolution)) {
    const double mid = std::sqrt(lo * hi);
    (ok(mid) ? lo : hi) = mid;
  }
  return lo;
}

}  // namespace

JointLimitMeter::JointLimitMeter(const JointLimits& limits, double cycle_s,
                                 const JointVector& qdd_before)
    : limits_(limits), cycle_s_(cycle_s), previous_(qdd_before) {}

void JointLimitMeter::add(const JointVector& qdd) {
  for (int i = 0; i < kJointCount; ++i) {
    const double a = std::abs(qdd(i)) / limits_.acceleration_rad_s2(i);
    if (a > use_.acceleration_ratio) {
      use_.acceleration_ratio = a;
      use_.acceleration_joint = i;
    }
    if (limits_.jerk_rad_s3) {
      const double j = std::abs(qdd(i) - previous_(i)) / cycle_s_ / (*limits_.jerk_rad_s3)(i);
      if (j > use_.jerk_ratio) {
        use_.jerk_ratio = j;
        use_.jerk_joint = i;
      }
    }
  }
  previous_ = qdd;
}

void JointPathDerivatives::add(double s_m, const JointVector& dq_ds, const JointVector& d2q_ds2) {
  if (!s_.empty() && s_m <= s_.back()) {
    if (s_m < s_.back()) throw std::invalid_argument("JointPathDerivatives: s decreases");
    return;
  }
  s_.push_back(s_m);
  dq_ds_.push_back(dq_ds);
  d2q_ds2_.push_back(d2q_ds2);
}

JointVector JointPathDerivatives::acceleration(const ProfileState& path,
                                               std::size_t& cursor) const {
  if (s_.empty()) throw std::logic_error("JointPathDerivatives: empty");
  if (s_.size() == 1) {
    return d2q_ds2_[0] * (path.velocity * path.velocity) + dq_ds_[0] * path.acceleration;
  }
  // Interval [s_[i], s_[i + 1]] holding the state's s (clamped to the table's ends); the cursor
  // only moves forward while s grows, back if s falls below it.
  std::size_t i = std::min(cursor, s_.size() - 2);
  while (i + 2 < s_.size() && s_[i + 1] < path.position) ++i;
  while (i > 0 && s_[i] > path.position) --i;
  cursor = i;
  const double w = std::clamp((path.position - s_[i]) / (s_[i + 1] - s_[i]), 0.0, 1.0);
  const JointVector dq = (1.0 - w) * dq_ds_[i] + w * dq_ds_[i + 1];
  const JointVector d2q = (1.0 - w) * d2q_ds2_[i] + w * d2q_ds2_[i + 1];
  return d2q * (path.velocity * path.velocity) + dq * path.acceleration;
}

ProfileLimits slowed_limits(const ProfileLimits& programmed, double speed_factor,
                            double ramp_factor) {
  const double k = speed_factor, m = ramp_factor;
  return {programmed.velocity / k, programmed.acceleration / (k * k * m),
          programmed.jerk / (k * k * k * m * m)};
}

TimingChoice choose_timing(const ProfileLimits& programmed, const JointLimitUse& programmed_use,
                           const TimingJudge& judge) {
  TimingChoice best;
  auto within = [&](double k, double m) {
    ++best.trials;
    return judge.within(slowed_limits(programmed, k, m));
  };
  auto duration = [&](double k, double m) {
    return judge.duration(slowed_limits(programmed, k, m));
  };
  // Uniform slow-down: exact for the continuous motion; on the cycles (other sample points, the
  // stretch to whole cycles) it may fall short by a little, so widen it until judged within.
  double k_uniform = std::max(
      {1.0, std::sqrt(programmed_use.acceleration_ratio), std::cbrt(programmed_use.jerk_ratio)});
  for (int widen = 0; !within(k_uniform, 1.0); ++widen) {
    if (widen == 100) {
      throw std::logic_error("choose_timing: the uniform slow-down does not reach the limits");
    }
    k_uniform *= 1.001;
  }
  best.speed_factor = k_uniform;
  best.duration_s = duration(k_uniform, 1.0);
  for (int i = 0; i < kSpeedFactorSteps; ++i) {
    const double k = std::pow(k_uniform, static_cast<double>(i) / kSpeedFactorSteps);
    // Ramps stretched beyond m_slowest would make the segment no faster than the best so far.
    if (duration(k, 1.0) > best.duration_s) continue;
    double m_slowest = 2.0;
    while (duration(k, m_slowest) <= best.duration_s && m_slowest < 1e6) m_slowest *= 2.0;
    m_slowest = largest_ok(m_slowest / 2.0, m_slowest,
                           [&](double m) { return duration(k, m) <= best.duration_s; });
    // Even those ramps exceed a limit: the velocity part is too much at this speed (or any
    // timing that fits at this speed is slower than the best so far).
    if (!within(k, m_slowest)) continue;
    const double m =
        within(k, 1.0) ? 1.0 : smallest_ok(1.0, m_slowest, [&](double x) { return within(k, x); });
    const double t = duration(k, m);
    // Ties (durations are whole cycles) go to the higher path speed: k rises with i.
    if (t < best.duration_s || (t == best.duration_s && k < best.speed_factor)) {
      best.speed_factor = k;
      best.ramp_factor = m;
      best.duration_s = t;
    }
  }
  best.limits = slowed_limits(programmed, best.speed_factor, best.ramp_factor);
  return best;
}

}  // namespace imscal::sim
