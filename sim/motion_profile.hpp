#pragma once
// One-dimensional rest-to-rest motion profiles s(t) over a distance D (any unit: rad for a
// joint, m for a path, or 1 for a normalised move), as a chain of pieces of constant jerk, so
// that position, velocity and acceleration are exact polynomials at any t:
// - trapezoidal velocity: accelerate at a_max, cruise at v_max, decelerate (3 pieces, jerk 0
//   inside each; the acceleration jumps at the piece borders). If D is too short to reach
//   v_max, the cruise vanishes and the peak velocity is sqrt(D a_max) (triangle).
// - jerk-limited ("S-curve"): 7 pieces with jerk +j, 0, -j, 0 (cruise), -j, 0, +j. Degenerate
//   cases: a_max not reached within v_max (v_max j_max < a_max^2: no constant-acceleration
//   piece), v_max not reached within D (reduced peak velocity, no cruise), or both.
// A profile may be stretched in time by a factor k >= 1 (s_k(t) = s(t / k)): velocity, acceleration
// and jerk shrink by k, k^2, k^3, so limits stay respected. Used to synchronise joints and to make
// a duration an integer number of control cycles.
#include <vector>

namespace imscal::sim {

enum class ProfileKind { kTrapezoidal, kJerkLimited };

struct ProfileLimits {
  double velocity = 0.0;      // > 0
  double acceleration = 0.0;  // > 0
  double jerk = 0.0;          // > 0; used by kJerkLimited only
};

struct ProfileState {
  double position = 0.0;
  double velocity = 0.0;
  double acceleration = 0.0;
};

class MotionProfile {
 public:
  // Distance may be negative (the profile then runs backwards) or zero (duration 0).
  // Throws std::invalid_argument for non-positive or non-finite limits.
  static MotionProfile plan(ProfileKind kind, double distance, const ProfileLimits& limits);

  // The same motion slowed down to last `duration` (>= this->duration()).
  MotionProfile stretched_to(double duration) const;

  double duration() const { return duration_; }
  double distance() const { return distance_; }
  // Peak |velocity| and |acceleration| of the profile (after stretching).
  double peak_velocity() const;
  double peak_acceleration() const;
  // State at time t; t < 0 gives the start, t > duration() the end (at rest).
  ProfileState at(double t) const;

 private:
  struct Piece {
    double begin_t = 0.0;  // in unstretched time
    double length_t = 0.0;
    double s0 = 0.0, v0 = 0.0, a0 = 0.0, jerk = 0.0;
  };
  void append(double length_t, double jerk);
  void append_with_acceleration(double length_t, double acceleration);

  std::vector<Piece> pieces_;  // for a positive distance; sign_ applies the direction
  double sign_ = 1.0;
  double distance_ = 0.0;
  double time_scale_ = 1.0;  // k: t_unstretched = t / k
  double duration_ = 0.0;    // stretched
};

}  // namespace imscal::sim
