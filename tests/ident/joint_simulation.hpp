#pragma once
// A simulated robot joint for the ident tests: a known ARX joint (static gain 1) followed by a
// backlash (play) element of known half width l, driven by a smooth desired motion. The truth
// that identification results are checked against.
#include <cmath>
#include <cstddef>
#include <numbers>
#include <random>
#include <vector>

namespace imscal::test_support {

struct SimulatedJoint {
  // y(k) = -a1 y(k-1) - a2 y(k-2) + b0 u(k-d) (+ noise); poles r e^{±iφ}, gain 1.
  double pole_modulus = 0.92;
  double pole_angle_rad = 0.08;
  int dead_time = 2;
  double backlash_l_rad = 0.0;  // half the play: output = input ∓ l while moving ±
  double measurement_noise_rad = 0.0;
  // Desired motion: offset + Σ amplitude_i sin(2π f_i t + phase_i).
  double offset_rad = 0.3;
  std::vector<double> amplitude_rad{0.4, 0.15};
  std::vector<double> frequency_hz{0.35, 0.9};
  std::vector<double> phase_rad{0.0, 1.0};

  double a1() const { return -2.0 * pole_modulus * std::cos(pole_angle_rad); }
  double a2() const { return pole_modulus * pole_modulus; }
  double b0() const { return 1.0 + a1() + a2(); }  // static gain 1
};

struct JointRecord {
  std::vector<double> t_s, q_desired, q_linear, q_measured;
};

// Play operator: the output follows the input only when it is pushed, leaving a gap of l.
inline double play(double input, double previous_output, double l) {
  if (input - previous_output > l) return input - l;
  if (previous_output - input > l) return input + l;
  return previous_output;
}

inline JointRecord simulate_joint(const SimulatedJoint& j, std::size_t samples, double dt,
                                  unsigned seed, double t0 = 0.0) {
  JointRecord r;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  r.t_s.resize(samples);
  r.q_desired.resize(samples);
  r.q_linear.resize(samples);
  r.q_measured.resize(samples);
  for (std::size_t k = 0; k < samples; ++k) {
    const double t = t0 + double(k) * dt;
    r.t_s[k] = t;
    double q = j.offset_rad;
    for (std::size_t i = 0; i < j.amplitude_rad.size(); ++i)
      q += j.amplitude_rad[i] *
           std::sin(2.0 * std::numbers::pi * j.frequency_hz[i] * t + j.phase_rad[i]);
    r.q_desired[k] = q;
  }
  // Start at rest at the first desired angle (no start-up transient).
  const double q0 = r.q_desired[0];
  double y1 = q0, y2 = q0, out = q0;
  for (std::size_t k = 0; k < samples; ++k) {
    const long idx = long(k) - j.dead_time;
    const double u = idx >= 0 ? r.q_desired[std::size_t(idx)] : q0;
    const double y = -j.a1() * y1 - j.a2() * y2 + j.b0() * u;
    r.q_linear[k] = y;
    out = play(y, out, j.backlash_l_rad);
    r.q_measured[k] = out + j.measurement_noise_rad * normal(rng);
    y2 = y1;
    y1 = y;
  }
  return r;
}

}  // namespace imscal::test_support
