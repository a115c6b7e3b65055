#pragma once
// A joint's friction levels from its motor encoder's following error, with 1σ.
//
// Model: the torque balance of the drive's motor, in joint-side units. The controller (a position
// loop around a PI velocity loop with velocity feed-forward, robot/robot_description.hpp) acts
// on the following error e(k) = q_desired(k − δ) − q_internal(k) of the command it received δ
// cycles late, and its torque, a linear operator L of e (proportional, derivative and integral
// terms), is what the motor must produce: the nominal model's rigid-body torque τ along the
// desired path (the gear passes the link's torque to the motor), the friction
// F_c tanh(q̇_m / s) + F_v q̇_m on the motor speed q̇_m (Coulomb and viscous, motor and output
// side together) and the reflected motor inertia J q̈ (J = N² J_m):
//   τ(k) = Σ_{i<n} γ_i e(k−i) + γ_I Σ_{m<=k} e(m) Δt + c − F_c tanh(q̇_m(k) / s) − F_v q̇_m(k)
//          − J q̈_d(k),
// linear in (γ, γ_I, c, F_c, F_v, J): ordinary least squares with τ as the target (every column
// and τ low-passed by the same moving average, which keeps the balance), so τ fixes
// the torque scale and the controller's gains need not be known. δ is the caller's (one per
// controller: eval/friction_identification.hpp picks it over all joints). The encoder sees no
// transmission error and no gear deflection; the gear's own dynamics (the link's ringing against
// the motor) and the nominal model's mass errors stay in the residual.
// 1σ: σ_r² (XᵀX)⁻¹ scaled by the residual's correlation factor 1 + 2 Σ ρ_k (the rows are that
// many times fewer independent ones; ρ summed up to its first sign change). It is the
// statistical 1σ only: the balance's model error (its fit is reported) biases the levels by more
// on a gear-dominated joint (decision 0061).
//
// References (docs/references.md): [Ljung1999] (least squares and the covariance of its
// estimates).
#include <Eigen/Core>
#include <cstddef>
#include <limits>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace imscal::ident {

struct FrictionLevelOptions {
  int decimation = 1;  // every decimation-th sample a row (the lags stay at the record's rate)
  int error_lags = 4;  // n: e(k)..e(k−n+1) at the record's rate
  // The command's dead time δ searched over 0..max cycles (the controller acts on
  // q_desired(k − δ)): the one whose balances fit best over all joints (one controller).
  int max_dead_time_cycles = 4;
  // The model torque's RMS must reach this multiple of the nominal Coulomb level (measured: A6
  // 0.05 on the test's moves and on the identification program; A3 0.22 and A4 0.9 on the test's
  // moves, estimated within 6 %): τ is the only
  // scale of the balance, and where it is small (a wrist's last joint) the balance fits with
  // every coefficient near zero.
  double min_torque_to_coulomb = 0.15;
  double cycle_s = 0.002;  // the record's sample time [s] (the integral's step)
  // Every column and the target through the same moving average of this many samples (50 ms at
  // 2 ms; a linear filter keeps the balance exact): it removes what the balance does not model
  // and the encoder sees, the transmission error's torque ripple through the gear (tens of Hz)
  // and the gear's 15 Hz mode. Measured on two population plants (Coulomb, estimate / truth):
  // A1 0.42 / 0.32 without, 0.72 / 0.68 with 25, 0.82 / 0.78 with 50 samples; A3 0.78 / 0.80,
  // 0.89 / 0.87, 0.96 / 0.90; the wrist unchanged; 50 misses the test's tolerances.
  int smoothing_samples = 25;
  double direction_speed_scale_rad_s = 0.01;  // s of tanh(q̇ / s)
};

// A level with its 1σ (NaN: not estimated) and the robot file's value (the prior).
struct FrictionLevel {
  double value = std::numeric_limits<double>::quiet_NaN();
  double sigma = std::numeric_limits<double>::quiet_NaN();
  double nominal = std::numeric_limits<double>::quiet_NaN();
};

struct JointFrictionLevels {
  bool estimated = false;
  std::string not_estimated;  // why, when not estimated
  FrictionLevel coulomb_nm, viscous_nm_s_per_rad, reflected_inertia_kg_m2;
  std::size_t rows = 0;             // regression rows used
  int dead_time_cycles = 0;         // δ used
  double torque_rms_nm = 0.0;       // the model torque's RMS about its mean over the rows
  double correlation_factor = 1.0;  // the covariance's scale for correlated residuals
  double torque_fit_percent = std::numeric_limits<double>::quiet_NaN();  // of τ by the balance
};

// One joint's signals, per sample, over [begin, end) segments (lags never cross a segment).
struct JointFrictionSignals {
  std::span<const double> desired_rad;          // q_desired
  std::span<const double> internal_rad;         // q_internal: the motor encoder, joint side
  std::span<const double> model_torque_nm;      // nominal model along the desired path
  std::span<const double> speed_rad_s;          // q̇ of the desired path
  std::span<const double> acceleration_rad_s2;  // q̈ of the desired path
  std::span<const std::pair<std::size_t, std::size_t>> segments;
};

// The nominal (prior) values the estimate starts from and is reported beside.
struct FrictionPrior {
  double coulomb_nm = 0.0, viscous_nm_s_per_rad = 0.0, reflected_inertia_kg_m2 = 0.0;
};

// The levels at dead time δ = dead_time_cycles. Throws std::invalid_argument for signals of
// different lengths or δ < 0; a joint with too few rows, a singular normal matrix (it did not
// move) or too small a model torque comes back not estimated, with the reason.
JointFrictionLevels estimate_friction_levels(const JointFrictionSignals& signals,
                                             const FrictionPrior& prior,
                                             const FrictionLevelOptions& options,
                                             int dead_time_cycles);

// The balance's regression at dead time δ, for estimators that add columns to it: per row the
// drive's columns [e(k−i), i < n | Σ e Δt | 1 | −tanh(q̇_m/s) | −q̇_m | −q̈_d], then one column per
// extra per-sample signal (taken at k − δ like τ), all through the same moving average; the
// target τ(k − δ) filtered alike. Throws std::invalid_argument for signals of different lengths
// or δ < 0.
struct FrictionBalanceRegression {
  Eigen::MatrixXd columns;
  Eigen::VectorXd target;
  int drive_columns = 0;             // the leading columns that are the drive's
  std::vector<std::size_t> samples;  // each row's sample index k
};
FrictionBalanceRegression friction_balance_regression(
    const JointFrictionSignals& signals, const FrictionLevelOptions& options, int dead_time_cycles,
    std::span<const std::span<const double>> extra);

}  // namespace imscal::ident
