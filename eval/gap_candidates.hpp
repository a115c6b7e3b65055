#pragma once
// The library of candidate effects of the gap diagnosis ("which"): each candidate is a
// small parametric model of one joint's gap g (eval/gap_signals.hpp), linear in its parameters,
// built from known signals only. Its nonlinear shape (a time constant, a resonance frequency, a
// harmonic) is chosen from a small grid by the 2-fold validation inside the training rows
// (eval/gap_validation.hpp); the linear parameters are then the least-squares solution on the
// training rows with 1-sigma from the residual variance, inflated by the residual's integrated
// autocorrelation (the residuals are coloured, so the plain LS sigma would be far too small).
// An effect that moves a link also reaches the other joints through the coupled dynamics: its
// fit is extended to the joints the validation chooses (eval/gap_coupling.hpp).
//
// Candidates (u: the candidate's driving signal; L_tau,i: the i-th discrete Laguerre filter of
// time scale tau, an orthonormal basis of stable linear responses: the closed joint loop's
// reaction to u without knowing its poles; HP_tau = 1 - first-order lag; q̇_a, tau_a the
// velocity and rigid-body torque of the drive's actual motion, q_internal):
//   backlash        the flank the link rests on: a relay with memory r of the sign of
//                   z = tau_a / RMS + c tanh(q̇_a / 5 mrad/s) (c = 0 .. 3: the friction at the link
//                   can outweigh a light axis' inertia torque; hold thresholds 2 / 10 %), or of q̇_a
//                   alone, as [r] or [r, L_10/30/100ms,0..3 r]; the smooth tanh(tau_a / 1, 5 or
//                   20 % of its RMS) as [u] or [u, L_10/30/100ms,0..3 u] (when >= 5 % of the
//                   samples lie on the torque's minority side); tanh(q̇_a / 5 mrad/s) (paper,
//                   eq. 3) as [u] or [u, LP_30ms u]. A relay that never switches is the one-flank
//                   shape kOneFlankShape: a constant, half the play
//   coulomb         u = tanh(q̇_a / v_s), v_s 5, 10, 20 mrad/s: the friction acts on the motor's
//                   own velocity and the PI loop works it off after every reversal:
//                   [L_100ms,0..5 u], [L_100ms,0..3 u], [L_30ms,0..5 u] or [HP_30/100/300ms u]
//   compliance      u = tau_d (inverse dynamics on q_d): deflection tau/k; [u], [G, u - G] (gravity
//                   and motion parts apart), [u, L_30ms,0..1 u] or [u, L_30ms,0..5 u]
//   transmission    s, c = sin/cos(h N q_internal), h = 1..3 per motor revolution and the two
//                   orders of 1..8 whose raw ripple best fits the training rows: raw, through
//                   L_3ms (x3, x4), L_10ms or L_30ms (x4), or with the ripple torque tau_d s,
//                   tau_d c (the gear's virtual work on the motor) through L_100ms x3 beside
//                   L_10ms x3 or L_3ms + L_30ms x3 of s, c: below the loop's bandwidth the link
//                   follows the error, above the link's mode it does not
//   resonance       q̈_d through ω²/(s² + 2ζωs + ω²), f 2..40 Hz in 10 % steps x ζ {0.02, 0.04,
//                   0.07, 0.12, 0.3}; [y, ẏ/ω] (gain and phase)
//   time_offset     [q̇_d]: the parameter is the offset dt [s] between the streams
//   clock_offset    all joints at once, one parameter: [q̇_d,j] on every joint j, the offset dt [s]
//                   of the measuring clock against the robot's (a parameter of the nominal model:
//                   q_m(t) = q(t - dt), linearised -dt q̇ of the joint error's measured side)
//   payload         all joints at once (one mass acts on every joint it loads): per joint
//                   u_j = d tau_j / d m_payload, [u_j], [L_30ms,0..3 u_j], [L_100ms,0..5 u_j] or
//                   [L_30ms,0..3 u_j, L_100ms,0..5 u_j] with its own parameters per joint (Δm / k_j
//                   through joint j's loop)
//   zero_offset     [1]
//   thermal_drift   [1, t', t'^2], t' = (t - t_mid) / duration
//   operating_point [o, o sign(q̇_d)], o = how far |q̇_d| lies beyond the identified speed range
//                   of the table, relative to it (only with a table that has a speed dimension)
// The geometric errors of the IMS chain (columns of GapSignals::ims_chain_columns, only with a
// robot model; the joint-space map -Jb^-1 of a flange pose error, eval/gap_signals.hpp) act on
// all joints with the same parameters: they are fitted to all joints' gaps at once (stacked), and
// their joint is the one where their modelled gap is largest:
//   kinematic_parameters  DH a, alpha, d of one link i = 1..6 (3 parameters, link chosen as the
//                         shape; the joint zero offsets are zero_offset)
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
  kClockOffset,
};
inline constexpr int kEffectKindCount = 15;
const char* to_string(EffectKind kind);
EffectKind effect_kind_from_index(int index);

// One shape of a candidate: its regressor columns over all samples, per joint (an empty matrix:
// the candidate does not act on that joint; all others have one column per parameter).
struct CandidateShape {
  std::string label;                         // e.g. "sign(qd), lag 30 ms"
  std::vector<Eigen::MatrixXd> columns;      // [joint]: samples x parameters, or empty
  std::vector<std::string> parameter_names;  // with units, e.g. "l_rad"
  // The effect's static signal on its own joint, whose coefficient in the modelled gap is the
  // effect's level, and the level's physical lower bound (eval/gap_bounds.hpp): tau_d for a
  // compliance (>= -1 / nominal stiffness), the flank for a play (>= -nominal half play), the sign
  // of the velocity for friction (>= 0 when the nominal model has none). Empty: unbounded.
  Eigen::VectorXd level_signal;
  double level_lower = 0.0;
};

// A physical bound of a fit (eval/gap_bounds.hpp): the level of the parameters
// [first, first + count), on joint `joint`, is at least `lower`.
struct LevelBound {
  std::size_t joint = 0;
  Eigen::Index first = 0, count = 0;  // count 0: no bound
  Eigen::VectorXd signal;             // the static signal u over all samples
  double lower = 0.0;                 // in the level's units (u's coefficient)
};

// The shapes of a candidate on a joint (empty when the candidate does not apply, e.g. the
// operating point without a table). The columns are computed from the whole record (filters run
// across training and held-out rows alike: they are known signals).
// `training`: the rows a transmission error's further orders are searched on (below); null: the
// orders 1 to 3 only.
std::vector<CandidateShape> candidate_shapes(EffectKind kind, const GapSignals& signals,
                                             std::size_t joint,
                                             const std::vector<bool>* training = nullptr);

// The orders h per motor revolution of a transmission error on `joint`, 1 to 8 in steps of 0.5,
// best first by the residual RMS of the raw ripple [sin, cos](h N q_internal) fitted to `gap` on
// the rows `use` (an order search: a gear's error has orders other than the first few). Only
// orders whose ripple completes at least 10 periods over the joint's range of motion: fewer are a
// slow drift to the data (an order 0.5 on a slow A2 displaced its zero offset).
std::vector<double> transmission_orders_by_fit(const GapSignals& signals, std::size_t joint,
                                               const std::vector<double>& gap,
                                               const std::vector<bool>& use);

// The backlash shape of a joint whose gear torque never changes sign on the data: the link rests
// on one flank and the play is a constant offset of half its width, indistinguishable there from
// a zero offset of the joint (eval/gap_ambiguity.hpp).
inline constexpr const char* kOneFlankShape =
    "held on one flank (the gear torque never changes sign)";

// Effects that move a link (and so reach the other joints through the coupled dynamics,
// eval/gap_coupling.hpp), unlike offsets, drifts, time offsets, table extrapolation and errors of
// the IMS chain, which act on the measurement or the model only.
bool acts_through_dynamics(EffectKind kind);

struct CandidateFit {
  EffectKind kind = EffectKind::kZeroOffset;
  // The joint whose signals drive the candidate, or (candidates acting on several joints) the
  // joint where its modelled gap has the most energy.
  std::size_t joint = 0;
  bool spans_joints = false;  // its own columns act on more than one joint
  std::string shape;
  // The joints its coupling reaches (eval/gap_coupling.hpp; their parameters follow the shape's in
  // `parameters`), and that reach in words. Empty: it stays on its own joint(s).
  std::vector<std::size_t> coupled_joints;
  std::string coupling;
  std::size_t coupling_parameter_count = 0;  // the last ones of `parameters`
  std::vector<std::string> parameter_names;
  Eigen::VectorXd parameters, sigma;            // 1-sigma (autocorrelation-inflated)
  std::vector<Eigen::MatrixXd> columns;         // [joint], of the chosen shape (for combinations)
  std::vector<std::vector<double>> prediction;  // [joint] model of the gap [rad]; empty: none
  double training_rms_rad = 0.0;                // residual RMS on the training rows
  // The size of the effect in words, e.g. "l = 0.000437 ± 0.000002 rad (1.50 arcmin)".
  std::string size_text;
  // Its physical bound (count 0: none), the level fitted, and whether the bound is active (the
  // unconstrained fit was unphysical; its level is `unconstrained_level`).
  LevelBound bound;
  double level = 0.0, unconstrained_level = 0.0;
  bool at_bound = false;
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

// The same fit over several joints at once: the rows of every joint that has columns are stacked
// (one parameter vector for all of them), `use` flags the samples (the same on every joint).
LinearFit fit_joint_columns(const std::vector<Eigen::MatrixXd>& columns,
                            const std::vector<std::vector<double>>& gap,
                            const std::vector<bool>& use);

// columns * parameters per joint (empty where the joint has no columns).
std::vector<std::vector<double>> predict_joint_columns(const std::vector<Eigen::MatrixXd>& columns,
                                                       const Eigen::VectorXd& parameters);

// The columns of two candidates side by side per joint (zeros where one of them has none).
std::vector<Eigen::MatrixXd> join_columns(const std::vector<Eigen::MatrixXd>& a,
                                          const std::vector<Eigen::MatrixXd>& b,
                                          std::size_t samples);

// Best shape by the 2-fold validation within the training rows (the only shape when there is
// one), fitted on all training rows; nullopt when the candidate does not apply.
std::optional<CandidateFit> fit_candidate(EffectKind kind, const GapSignals& signals,
                                          std::size_t joint, const std::vector<bool>& training);

}  // namespace imscal::eval
