#include "sim/motion_profile.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace imscal::sim {
namespace {

void check_limit(double value, const char* name) {
  if (!(value > 0.0) || !std::isfinite(value)) {
    throw std::invalid_argument(std::string("motion profile: ") + name +
                                " limit must be positive and finite, got " + std::to_string(value));
  }
}

}  // namespace

void MotionProfile::append(double length_t, double jerk) {
  if (!(length_t > 0.0)) return;  // degenerate phase
  Piece piece;
  if (!pieces_.empty()) {
    const Piece& p = pieces_.back();
    const double dt = p.length_t;
    piece.begin_t = p.begin_t + dt;
    piece.s0 = p.s0 + p.v0 * dt + p.a0 * dt * dt / 2.0 + p.jerk * dt * dt * dt / 6.0;
    piece.v0 = p.v0 + p.a0 * dt + p.jerk * dt * dt / 2.0;
    piece.a0 = p.a0 + p.jerk * dt;
  }
  piece.length_t = length_t;
  piece.jerk = jerk;
  pieces_.push_back(piece);
}

void MotionProfile::append_with_acceleration(double length_t, double acceleration) {
  if (!(length_t > 0.0)) return;
  append(length_t, 0.0);
  pieces_.back().a0 = acceleration;  // trapezoid: the acceleration jumps at the border
}

MotionProfile MotionProfile::plan(ProfileKind kind, double distance, const ProfileLimits& limits) {
  check_limit(limits.velocity, "velocity");
  check_limit(limits.acceleration, "acceleration");
  if (kind == ProfileKind::kJerkLimited) check_limit(limits.jerk, "jerk");
  if (!std::isfinite(distance)) throw std::invalid_argument("motion profile: distance not finite");

  MotionProfile out;
  out.distance_ = distance;
  out.sign_ = distance < 0.0 ? -1.0 : 1.0;
  const double d = std::abs(distance);
  if (d == 0.0) return out;
  const double a_max = limits.acceleration;

  if (kind == ProfileKind::kTrapezoidal) {
    // Peak velocity: v_max, or sqrt(D a) when the ramps (v^2 / a in total) would overshoot D.
    const double v = std::min(limits.velocity, std::sqrt(d * a_max));
    const double ramp_t = v / a_max;
    const double cruise_t = std::max(0.0, (d - v * v / a_max) / v);
    out.append_with_acceleration(ramp_t, a_max);
    out.append_with_acceleration(cruise_t, 0.0);
    out.append_with_acceleration(ramp_t, -a_max);
  } else {
    const double j = limits.jerk;
    // Ramp from rest to velocity v: jerk phase tj, constant-acceleration phase tc, jerk phase tj.
    // a_max is reached only if v >= a_max^2 / j. The ramp covers v (2 tj + tc) / 2.
    auto ramp = [&](double v, double& tj, double& tc) {
      if (v * j >= a_max * a_max) {
        tj = a_max / j;
        tc = v / a_max - a_max / j;
      } else {
        tj = std::sqrt(v / j);
        tc = 0.0;
      }
    };
    double v = limits.velocity;
    double tj = 0.0, tc = 0.0;
    ramp(v, tj, tc);
    if (v * (2.0 * tj + tc) > d) {
      // v_max not reached: both ramps cover D exactly. With a_max reached,
      // D = v (a/j + v/a) -> v = a/2 (-a/j + sqrt(a^2/j^2 + 4 D / a));
      // otherwise D = 2 v^1.5 / sqrt(j) -> v = cbrt(D^2 j / 4).
      v = a_max / 2.0 * (-a_max / j + std::sqrt(a_max * a_max / (j * j) + 4.0 * d / a_max));
      if (v * j < a_max * a_max) v = std::cbrt(d * d * j / 4.0);
      ramp(v, tj, tc);
    }
    const double cruise_t = std::max(0.0, (d - v * (2.0 * tj + tc)) / v);
    out.append(tj, j);
    out.append(tc, 0.0);
    out.append(tj, -j);
    out.append(cruise_t, 0.0);
    out.append(tj, -j);
    out.append(tc, 0.0);
    out.append(tj, j);
  }
  const Piece& last = out.pieces_.back();
  out.duration_ = last.begin_t + last.length_t;
  return out;
}

MotionProfile MotionProfile::stretched_to(double duration) const {
  MotionProfile out = *this;
  const double raw = pieces_.empty() ? 0.0 : pieces_.back().begin_t + pieces_.back().length_t;
  if (duration < duration_ * (1.0 - 1e-12)) {
    throw std::invalid_argument("motion profile: cannot stretch to a shorter duration");
  }
  out.duration_ = duration;
  out.time_scale_ = raw > 0.0 ? duration / raw : 1.0;
  return out;
}

double MotionProfile::peak_velocity() const {
  double peak = 0.0;
  for (const Piece& p : pieces_) {
    // Velocity is extreme where the acceleration changes sign: at piece borders for these
    // profiles (a is 0 at the cruise borders and at the ends).
    const double dt = p.length_t;
    peak = std::max({peak, std::abs(p.v0), std::abs(p.v0 + p.a0 * dt + p.jerk * dt * dt / 2.0)});
  }
  return peak / time_scale_;
}

double MotionProfile::peak_acceleration() const {
  double peak = 0.0;
  for (const Piece& p : pieces_) {
    peak = std::max({peak, std::abs(p.a0), std::abs(p.a0 + p.jerk * p.length_t)});
  }
  return peak / (time_scale_ * time_scale_);
}

ProfileState MotionProfile::at(double t) const {
  ProfileState state;
  if (pieces_.empty() || t <= 0.0) return state;
  if (t >= duration_) {
    state.position = distance_;  // exactly the distance, at rest
    return state;
  }
  const double tu = t / time_scale_;
  auto it = std::upper_bound(pieces_.begin(), pieces_.end(), tu,
                             [](double value, const Piece& p) { return value < p.begin_t; });
  const Piece& p = *std::prev(it);  // tu >= first begin_t = 0, so it != begin()
  const double dt = tu - p.begin_t;
  const double k = time_scale_;
  state.position = sign_ * (p.s0 + p.v0 * dt + p.a0 * dt * dt / 2.0 + p.jerk * dt * dt * dt / 6.0);
  state.velocity = sign_ * (p.v0 + p.a0 * dt + p.jerk * dt * dt / 2.0) / k;
  state.acceleration = sign_ * (p.a0 + p.jerk * dt) / (k * k);
  return state;
}

}  // namespace imscal::sim
