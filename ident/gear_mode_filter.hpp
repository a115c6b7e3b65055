#pragma once
// The locked-motor gear mode as a filter with state: the transmission error's complex pair
// u = e^{jφ} (φ the error's motor-side phase) through ÿ + 2 ζ ω_n ẏ + ω_n² y = ω_n² u, run sample
// by sample along the path. Unlike the steady-state response H(jΩ) e^{jφ} it follows sweeps of the
// error's frequency Ω through the mode faster than the mode's decay 1 / (ζ ω_n): the link builds
// the resonance up only as long as Ω stays near ω_n.
//
// Discretization: over the step [t_{k-1}, t_k] the input is taken as u_k e^{jΩ_k (t − t_k)}, a
// complex exponential at the step's own frequency Ω_k = (φ_k − φ_{k-1}) / h ending at the sample's
// value, and the state X = (y, ẏ) advances exactly for it:
//   X_k = Φ X_{k-1} + u_k (jΩ_k I − A)^{-1} (I − e^{-jΩ_k h} Φ) B,  Φ = e^{A h},
//   A = [0 1; −ω_n² −2ζω_n], B = (0, ω_n²).
// At a constant Ω the steady state X = (jΩ I − A)^{-1} B u is a fixed point, so the filter
// reproduces H(jΩ) = ω_n² / (ω_n² − Ω² + 2jζω_nΩ) exactly once the transient has decayed; the
// transient's error is that of holding Ω constant over one step.
// Real time: no allocation, no exception.
//
// References (docs/references.md): [Spong2006] (the locked-motor mode), [Franklin1998] (the
// exact discretization of a linear system, Φ = e^{Ah}).
#include <cmath>
#include <complex>

namespace imscal::ident {

// The filter's state for one pair: the output y (Re: the cos input, Im: the sin input), its rate
// [1/s] and the last sample's phase [rad].
struct GearModeFilterState {
  std::complex<double> y{1.0, 0.0};
  std::complex<double> y_rate{0.0, 0.0};
  double phase_rad = 0.0;
  bool started = false;
};

// The mode's constants for one step length: Φ and the parameters the input term needs.
struct GearModeStep {
  double step_s = 0.0;
  double natural_frequency_rad_s = 0.0;
  double damping_ratio = 0.0;
  double phi[2][2] = {{1.0, 0.0}, {0.0, 1.0}};  // e^{A h}
};

// Φ = e^{A h} of the damped oscillator (under-, critically or over-damped: the damped frequency
// ω_d = ω_n √(1 − ζ²) taken complex).
inline GearModeStep gear_mode_step(double natural_frequency_rad_s, double damping_ratio,
                                   double step_s) noexcept {
  GearModeStep s;
  s.step_s = step_s;
  s.natural_frequency_rad_s = natural_frequency_rad_s;
  s.damping_ratio = damping_ratio;
  const double w = natural_frequency_rad_s, sigma = damping_ratio * w;
  const std::complex<double> wd =
      w * std::sqrt(std::complex<double>(1.0 - damping_ratio * damping_ratio));
  const double decay = std::exp(-sigma * step_s);
  const double c = std::cos(wd * step_s).real();
  // sin(ω_d h) / ω_d, h in the limit ω_d → 0
  const double sinc = std::abs(wd) > 1e-9 * w ? (std::sin(wd * step_s) / wd).real() : step_s;
  s.phi[0][0] = decay * (c + sigma * sinc);
  s.phi[0][1] = decay * sinc;
  s.phi[1][0] = -decay * w * w * sinc;
  s.phi[1][1] = decay * (c - sigma * sinc);
  return s;
}

// The pair's steady state at phase φ and frequency Ω: y = H(jΩ) e^{jφ}, ẏ = jΩ y.
inline void gear_mode_filter_settle(const GearModeStep& m, GearModeFilterState& state,
                                    double phase_rad, double frequency_rad_s) noexcept {
  const double w = m.natural_frequency_rad_s;
  const std::complex<double> h = w * w /
                                 std::complex<double>(w * w - frequency_rad_s * frequency_rad_s,
                                                      2.0 * m.damping_ratio * w * frequency_rad_s);
  state.y = h * std::polar(1.0, phase_rad);
  state.y_rate = std::complex<double>(0.0, frequency_rad_s) * state.y;
  state.phase_rad = phase_rad;
  state.started = true;
}

// Advances the state to the sample at phase φ_k; returns y_k. The first sample after a restart
// settles the filter at the frequency `start_frequency_rad_s` instead.
inline std::complex<double> gear_mode_filter_advance(const GearModeStep& m,
                                                     GearModeFilterState& state, double phase_rad,
                                                     double start_frequency_rad_s) noexcept {
  if (!state.started) {
    gear_mode_filter_settle(m, state, phase_rad, start_frequency_rad_s);
    return state.y;
  }
  const double h = m.step_s, w = m.natural_frequency_rad_s, zeta = m.damping_ratio;
  const double omega = (phase_rad - state.phase_rad) / h;
  const std::complex<double> j_omega(0.0, omega);
  const std::complex<double> u = std::polar(1.0, phase_rad);
  // v = (I − e^{-jΩh} Φ) B, B = (0, ω_n²)
  const std::complex<double> back = std::polar(1.0, -omega * h);
  const std::complex<double> v0 = -back * m.phi[0][1] * (w * w);
  const std::complex<double> v1 = (1.0 - back * m.phi[1][1]) * (w * w);
  // (jΩ I − A)^{-1} = [jΩ + 2ζω_n, 1; −ω_n², jΩ] / (ω_n² − Ω² + 2jζω_nΩ)
  const std::complex<double> det(w * w - omega * omega, 2.0 * zeta * w * omega);
  const std::complex<double> g0 = ((j_omega + 2.0 * zeta * w) * v0 + v1) / det;
  const std::complex<double> g1 = (-w * w * v0 + j_omega * v1) / det;
  const std::complex<double> y = m.phi[0][0] * state.y + m.phi[0][1] * state.y_rate + u * g0;
  const std::complex<double> y_rate = m.phi[1][0] * state.y + m.phi[1][1] * state.y_rate + u * g1;
  state.y = y;
  state.y_rate = y_rate;
  state.phase_rad = phase_rad;
  return y;
}

}  // namespace imscal::ident
