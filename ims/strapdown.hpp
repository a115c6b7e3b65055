#pragma once
// Strapdown mechanization in the Earth-fixed frame W (ENU at the site, ims/frames.hpp) from
// gyro and accelerometer INCREMENTS (ImuQuantity::kIncrements).
//
// Model (W rotates with the Earth at omega_ie; g is gravity incl. centrifugal, EarthModel):
//   dq_W_S/dt = q_W_S (x) omega_is^S / 2 - omega_ie^W / 2 (x) q_W_S
//   dv_W/dt   = R_W_S f^S - 2 omega_ie^W x v_W + g_W(p_W)
//   dp_W/dt   = v_W
// A sample stamped t_k holds dtheta = int omega_is^S dt and dv = int f^S dt over (t_{k-1}, t_k].
//
// Algorithm of one step (h = t_k - t_{k-1}), chosen so that a noise-free 60 s run at 1 kHz with
// rates of 3 rad/s keeps position errors below 1 um (the dominant requirement: a tilt error of
// 1e-10 rad alone, mis-projecting gravity, already costs ~0.5 um after 60 s):
//  - Within the interval, omega_is^S(t) and f^S(t) are modelled as quadratics in time fitted
//    to the last three increments (their integrals match exactly). The first steps after
//    construction, reset() or a change of the sample interval use lower orders (constant, then
//    linear), which is exact for motions that start at rest.
//  - Attitude: the body rotation vector of the interval is the Magnus / Bortz expansion of the
//    fitted rate to second order (classical coning correction generalised to the quadratic fit;
//    for a rate linear in time the third-order terms cancel), applied as an exact quaternion.
//    The Earth rotation of W over the interval, exp(-omega_ie h) on the left, is moved into
//    the body frame and joined with the body rotation by Baker-Campbell-Hausdorff (third
//    order, rest below 1e-18 rad) before the one quaternion product: at rest the two cancel
//    and the attitude stays put to rounding instead of drifting by a repeated rounding error.
//  - Velocity: int R_S_{k-1}_S(t) f^S(t) dt (rotation compensation and sculling in one) is
//    evaluated by two-point Gauss-Legendre quadrature of the rotated fitted specific force,
//    which is exact to all orders for a constant rate and leaves ~1e-15 m/s per step at 3 rad/s.
//    The rotation of W during the interval enters at first order in omega_ie h (midpoint), the
//    Coriolis term from the position increment (midpoint velocity), gravity at the
//    mid-interval position.
//  - Position: trapezoid of the velocity with the end correction -(h/12)(dv_k - dv_{k-1})
//    (O(h^5) per step; the error sum telescopes), Coriolis to second order.
// No heap allocation and no trigonometric call while |rotation per step| < 0.01 rad. The
// per-sample code works on 3-vectors padded to 4 doubles (one AVX register) and is arranged for
// short dependency chains; about 45 ns per sample on one core of the development machine
// (bench/bench_strapdown.cpp, which also times the previous implementation in the same run).
//
// References (docs/references.md): [Bortz1971] (rotation vector, coning), [Savage1998] (coning and
// sculling, position from increments), [Groves2013] (Earth-fixed-frame mechanization).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

#include "ims/earth_model.hpp"
#include "ims/imu_data.hpp"
#include "ims/nav_state.hpp"

namespace imscal::ims {

// Switches for the terms of the model; all on for real use. They exist so that tests can show
// that each term matters.
struct StrapdownOptions {
  bool coning_sculling = true;  // off: rate and specific force taken constant in each interval
  bool earth_rate = true;       // off: gyro increments taken as rates relative to W
  bool coriolis = true;         // off: no -2 omega_ie x v term
  bool gravity = true;          // off: no g_W(p) term (accelerometers then read d2p/dt2)
};

class Strapdown {
 public:
  // `initial.t_s` is the start of the first increment's interval.
  Strapdown(const EarthModel& earth, const NavState& initial, StrapdownOptions options = {});

  // Integrates one increment sample over (state().t_s, increment.t_s]; afterwards
  // state().t_s == increment.t_s. Throws std::invalid_argument if the time does not advance
  // or a value is not finite.
  void step(const ImuSample& increment);

  const NavState& state() const { return state_; }
  // Restarts from `state` and forgets the increment history (the interval fit restarts).
  void reset(const NavState& state);

 private:
  // A three-vector padded with a zero to four doubles and aligned to 32 bytes: one AVX register
  // in the per-sample code (ims/strapdown.cpp), loaded and stored whole.
  struct alignas(32) Vec3 {
    double x = 0.0, y = 0.0, z = 0.0, zero = 0.0;
  };
  static constexpr int kEarthRateSyncSteps = 1024;
  void sync_earth_rate();
  void update_increment_maps(double h, double trapezoid_fraction);

  Vec3 earth_rate_W_;  // omega_ie in W [rad/s]; zero when options.earth_rate is off
  Vec3 earth_rate_S_;  // the same in S at state_.t_s [rad/s]
  int steps_since_sync_ = 0;
  Vec3 coriolis_rate_W_;  // omega_ie used in the Coriolis term [rad/s] (or zero)
  Vec3 gravity_origin_W_;
  Vec3 gravity_gradient_W_[3];  // columns of the gravity gradient [1/s^2]
  StrapdownOptions options_;
  // state_ is the output; the per-sample code works on the copies below (same values).
  NavState state_;
  Vec3 q_vec_;  // vector part of state_.q_W_S
  double q_w_ = 1.0;
  Vec3 v_W_, p_W_;
  // The two previous increments, the latest at index newest_, and how many of them are valid
  // (0..2).
  Vec3 gyro_history_[2];
  Vec3 acc_history_[2];
  int newest_ = 0;
  int history_count_ = 0;
  Vec3 previous_dv_0_W_;  // last dv without Coriolis [m/s]
  double previous_dt_s_ = 0.0;
  // Constant 3x3 matrices (columns) that take R_W_S times the sum of the two Gauss-node
  // values of the rotated specific force to the velocity, position and Coriolis-free velocity
  // increments (ims/strapdown.cpp), made for the interval maps_h_s_ and the trapezoid weight
  // maps_trapezoid_fraction_ * h.
  Vec3 velocity_map_[3], position_map_[3], dv_0_map_[3];
  double maps_h_s_ = -1.0, maps_trapezoid_fraction_ = -1.0;
};

// Mechanizes a whole series of increments. Returns samples.size() + 1 states: element 0 is
// `initial` itself, element i + 1 the state at increments.samples[i].t_s. `initial.t_s` must
// lie before the first sample (normally samples[0].t_s - nominal_dt_s: the first increment's
// interval). Throws std::invalid_argument for a series of rates (ImuQuantity::kRates): rates
// cannot be turned into exact increments here, convert them where their sampling is known.
std::vector<NavState> mechanize(const ImuSeries& increments, const EarthModel& earth,
                                const NavState& initial, StrapdownOptions options = {});

}  // namespace imscal::ims
