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
// Each effect's shapes are defined with the effect, in eval/gap_effect_<name>.cpp (the list:
// eval/gap_effects.hpp). Notation there: u is the candidate's driving signal; L_tau,i the i-th
// discrete Laguerre filter of time scale tau, an orthonormal basis of stable linear responses (the
// closed joint loop's reaction to u without knowing its poles); HP_tau = 1 - first-order lag; q̇_a,
// tau_a the velocity and rigid-body torque of the drive's actual motion, q_internal. The geometric
// errors of the IMS chain act on all joints with the same parameters: they are fitted to all
// joints' gaps at once (stacked), and their joint is the one where their modelled gap is largest.
#include <Eigen/Core>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "eval/gap_effects.hpp"
#include "eval/gap_signals.hpp"

namespace imscal::eval {

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
  // The shape is a constant on its own joint (a play held on one flank): its size reads as an
  // offset.
  bool constant_on_own_joint = false;
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
// `training`: the rows a transmission error's order is searched on (one order, chosen by its
// response's fit; eval/gap_effect_transmission_error.cpp); null: the orders 1 to 3.
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
