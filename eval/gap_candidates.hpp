#pragma once
// The library of candidate effects of the gap diagnosis ("which", issue 7): each candidate is a
// small parametric model of one joint's gap g (eval/gap_signals.hpp), linear in its parameters,
// built from known signals only. Its nonlinear shape (a time constant, a resonance frequency, a
// harmonic) is chosen from a small grid by a 2-fold validation inside the training rows (see
// fit_candidate); the linear parameters are
// then the least-squares solution on the training rows with 1-sigma from the residual variance,
// inflated by the residual's integrated autocorrelation (the residuals are coloured, so the plain
// LS sigma would be far too small).
//
// Candidates (u: the candidate's driving signal; LP_tau: first-order lag, HP_tau = 1 - LP_tau):
//   backlash        u = tanh(q̇_d / 5 mrad/s) or tanh(tau_d / 5 % of its RMS): the gear play shows
//                   where the motion (or the gear torque) changes sign; [u], [u, LP_30ms u] or
//                   (torque sign) [u, Laguerre_10ms,0..3 u] (eval/gap_candidates.cpp laguerre)
//                   (torque sign only when >= 5 % of the samples lie on its minority side)
//   coulomb         u = tanh(q̇_d / 5 mrad/s) through the joint controller: the PI loop removes the
//                   steady part, so only transients after every reversal remain:
//                   [HP_30ms u, HP_100ms u, HP_300ms u] (chosen from the simulator's data: a static
//                   sign explains < 10 % of a withheld motor-side friction, the high-passes ~50 %),
//                   [HP_100ms u], Laguerre bases [L_30ms,0..5 u] or [L_100ms,0..1 u]
//   compliance      u = tau_d (inverse dynamics on q_d): deflection tau/k; [u], [G, u - G] (gravity
//                   and motion parts apart) or [u, LP_10ms u, LP_30ms u]
//   transmission    sin/cos(h N q_internal), h = 1..3 per motor revolution (the motor angle comes
//                   from the internal encoder: q_d is off by the tracking error times N)
//   resonance       q̈_d through ω²/(s² + 2ζωs + ω²), f 2..40 Hz x ζ {0.02, 0.05, 0.1, 0.3};
//                   [y, ẏ/ω] (gain and phase)
//   time_offset     [q̇_d]: the parameter is the offset dt [s] between the streams
//   payload         [d tau / d m_payload]: the parameter is Δm / k [rad/kg]
//   zero_offset     [1]
//   thermal_drift   [1, t', t'^2], t' = (t - t_mid) / duration
//   operating_point [o, o sign(q̇_d)], o = how far |q̇_d| lies beyond the identified speed range
//                   of the table, relative to it (only with a table that has a speed dimension)
// The geometric errors of the IMS chain (columns of GapSignals::ims_chain_columns, only with a
// robot model; the joint-space map -Jb^-1 of a flange pose error, eval/gap_signals.hpp):
//   kinematic_parameters  DH a, alpha, d of one link i = 1..6 (3 parameters, link chosen as the
//   shape;
//                         the joint zero offsets are zero_offset)
//   sensor_mounting       the mounting twist of the sensor on the flange: rotation (3),
//                         translation (3) or both (6)
//   ims_scale_factor      gyro scale per flange axis (3), isotropic gyro scale (1), isotropic
//                         accelerometer scale (1)
//   ims_bias              gyro rate bias about the flange axes (3): an attitude drift
#include <Eigen/Core>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "eval/gap_signals.hpp"

namespace imscal::eval {

enum class EffectKind {
  kBacklash,
  kCoulombFriction,
  kGearCompliance,
  kTransmissionError,
  kResonance,
  kTimeOffset,
  kPayloadMismatch,
  kZeroOffset,
  kThermalDrift,
  kOperatingPoint,
  kKinematicParameters,
  kSensorMounting,
  kImsScaleFactor,
  kImsBias,
};
inline constexpr int kEffectKindCount = 14;
const char* to_string(EffectKind kind);
EffectKind effect_kind_from_index(int index);

// One shape of a candidate: its regressor columns over all samples.
struct CandidateShape {
  std::string label;                         // e.g. "sign(qd), lag 30 ms"
  Eigen::MatrixXd columns;                   // samples x parameters
  std::vector<std::string> parameter_names;  // with units, e.g. "l_rad"
};

// The shapes of a candidate on a joint (empty when the candidate does not apply, e.g. the
// operating point without a table). The columns are computed from the whole record (filters run
// across training and held-out rows alike: they are known signals).
std::vector<CandidateShape> candidate_shapes(EffectKind kind, const GapSignals& signals,
                                             std::size_t joint);

struct CandidateFit {
  EffectKind kind = EffectKind::kZeroOffset;
  std::size_t joint = 0;
  std::string shape;
  std::vector<std::string> parameter_names;
  Eigen::VectorXd parameters, sigma;  // 1-sigma (autocorrelation-inflated)
  Eigen::MatrixXd columns;            // of the chosen shape (kept for combinations)
  std::vector<double> prediction;     // the candidate's model of the gap, every sample [rad]
  double training_rms_rad = 0.0;      // residual RMS on the training rows
  // The size of the effect in words, e.g. "l = 0.000437 ± 0.000002 rad (1.50 arcmin)".
  std::string size_text;
};

// LS fit of columns to y on the rows flagged `use`; returns the parameters, their sigma
// (inflated as described above) and the residual RMS on those rows.
struct LinearFit {
  Eigen::VectorXd parameters, sigma;
  Eigen::MatrixXd covariance;  // of the parameters, inflated as sigma (sigma² on its diagonal)
  double rms = 0.0;
  double inflation = 1.0;  // sqrt of the integrated autocorrelation time used for sigma
};
LinearFit fit_columns(const Eigen::MatrixXd& columns, const std::vector<double>& y,
                      const std::vector<bool>& use);

// Best shape by the 2-fold validation within the training rows (the only shape when there is
// one), fitted on all training rows; nullopt when the candidate does not apply.
std::optional<CandidateFit> fit_candidate(EffectKind kind, const GapSignals& signals,
                                          std::size_t joint, const std::vector<bool>& training);

}  // namespace imscal::eval
