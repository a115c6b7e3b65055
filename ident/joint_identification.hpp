#pragma once
// The whole identification of one joint (paper, section 3.3), from its desired and measured
// angles:
//  1. backlash l (equation 3) from direction reversals (ident/backlash_identification.hpp), and
//     the joint angle with the backlash part removed, y = q_m + l s(k);
//  2. the last validation_fraction of every segment held out, or, with validation_block_s > 0,
//     of every block of that length (so that every operating point of a long run has held-out
//     rows, not only where the run ends);
//  3. every sample assigned to its operating-point cell (ident/operating_point.hpp), the
//     regression rows of a cell = its samples (regressors reach back into other cells);
//  4. per cell: checks of row count and excitation, order and dead-time sweep on the cell's
//     estimation rows (AIC/BIC/hold-out curves, ident/order_selection.hpp), least-squares fit of
//     the chosen structure on the cell's estimation rows (ident/arx_fit.hpp), stability
//     (ident/model_stability.hpp), validation on the cell's held-out rows
//     (ident/model_validation.hpp);
//  5. cells that failed any step are filled with the model of the nearest identified cell (in
//     band steps; ties: the lower cell number), with the reason — never silently.
//
// Model form. The joint error is ~1e-3 of the joint angle, so a least-squares ARX fit
// of the angle q_m on q_d (ArxModelForm::kAngle, the paper's eq. 2 taken literally) is decided
// by the angle: a model with 99.8 % angle fit can have a static gain of 1 ± 1e-3 and so predict a
// joint error off by ~1 mrad per rad of travel (held-out joint-error fit 59 % down to -44 % on
// the simulated KR 16, and a 2.9 rad "error" at the first cycle of a joint standing at 2.9 rad).
// ArxModelForm::kJointError (the default) fits the same ARX structure to the joint error itself:
//
//   e(k) = q_d(k) - y(k),  w(k) = q_d(k) - q_d(k-1)  (the desired increment)
//   e(k) + α_1 e(k-1) + ... + α_na e(k-na) = β_0 w(k-δ) + ... + β_{nb-1} w(k-δ-nb+1)
//
// (grid, sweep and criteria unchanged, applied to (w, e)), and stores it as the equivalent eq. 2
// model in q_d and q̂ with dead time 0 (angle_form_of_error_model): A(z) = 1 + Σ α_i z^-i,
// B(z) = A(z) - z^-δ (1 - z^-1) Σ β_j z^-j. That model has static gain exactly 1 (no error at
// rest), and its Δq̂(k) = q_d(k) - q̂(k) is the error at the cycle it is applied in, the quantity
// the data measure, with no q_d(k) - q_d(k - d) part left out.
//
// Inverse form (ArxModelForm::kInverse, for the precontrol). Adding the forward model's error
// once, q_c = q_d + Δq̂, leaves the loop's response to the offset itself: with G the loop
// (q_c -> q) the remaining error is (1 - G)^2 q_d, i.e. the error is only cut by |1 - G|, and
// for a joint controller of a few Hz bandwidth that is ~0.5 at the frequencies of a fast path
// (eval/closed_loop.hpp). The inverse form identifies instead the command that made the link follow
// the path it followed: in the identification runs the command was q_d and the (play-free) link
// angle y, so q_d = y + e, and the same error-form ARX is fitted with the link's increments as
// input, P cycles ahead (the controller's interpolator knows the path ahead):
//
//   w(k) = y(k + P) - y(k + P - 1),   e(k) = q_d(k) - y(k)
//
// Fed with the desired angles P cycles ahead, the model gives the offset that makes the link
// follow q_d (q_c = q_d + ê), to the accuracy of the fit, instead of the first-order (1 - G).
// It is stored exactly like the joint-error form (angle_form_of_error_model, d = 0): the
// precontrol computes the same Δq̂(k) = x(k) - q̂(k) = ê(k) from its input x; the table's
// preview_cycles tells the caller to feed x(k) = q_d(k + P). P covers the loop's dead time and
// the non-minimum-phase part of the loop, which a causal inverse cannot follow.
#include <cstddef>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "ident/backlash_identification.hpp"
#include "ident/model_stability.hpp"
#include "ident/model_validation.hpp"
#include "ident/operating_point.hpp"
#include "ident/order_selection.hpp"
#include "ident/parameter_table.hpp"
#include "ident/table_fit.hpp"

namespace imscal::ident {

enum class ArxModelForm {
  kJointError,  // fit the joint error on the desired increments (see above); stored with d = 0
  kAngle,       // fit q_m on q_d (the paper's eq. 2 literally)
  kInverse,     // fit the joint error on the measured increments with preview (see below)
};
const char* to_string(ArxModelForm form);
// "joint-error", "angle", "inverse"; std::invalid_argument otherwise.
ArxModelForm arx_model_form_from_string(const std::string& text);

// Where the gear mode's pairs go among the further inputs (JointIdentificationOptions).
enum class GearModePairs { kNone, kInstead, kBeside };
// "none", "instead", "beside"; std::invalid_argument otherwise.
const char* to_string(GearModePairs pairs);
GearModePairs gear_mode_pairs_from_string(const std::string& text);

struct JointIdentificationOptions {
  ArxModelForm form = ArxModelForm::kJointError;
  int preview_cycles = 0;  // P of the inverse form (>= 0; only with kInverse)
  // Further inputs of the multi-input form (imscal's extension of eq. 2), both taken
  // along the path the model's input follows (q_d, or the link in the inverse form), P cycles
  // ahead like the increments, OrderGrid::extra_taps coefficients each:
  //  * the joint torque of the robot's rigid-body model (identify_joint's model_torque_nm, from
  //    the caller, who has the robot description): the error of a joint controller and the
  //    gear's deflection are driven by the torque the joint has to produce (inertia of the whole
  //    arm in its pose, coupling, gravity, the payload), which the joint's own angle alone cannot
  //    tell; in the inverse form the offset that makes the link follow a path is a fixed linear
  //    filter of that torque and of the motion (tests/ident/test_joint_identification.cpp);
  //  * the direction of motion tanh(q̇ / direction_speed_scale): the drive's Coulomb friction
  //    and the dynamics of crossing the play at a reversal (eq. 3's backlash l is static);
  //  * the side of the gear the model torque presses on, tanh(τ / τ_s) with τ_s =
  //    torque_sign_scale_fraction × the RMS model torque of the joint's data: a backlashed gear
  //    carrying torque sits on one flank, half its play off centre (a constant for a
  //    gravity-loaded joint, which the error form with its static gain of 1 cannot otherwise
  //    hold), and crosses the play where the torque changes sign. Needs the model torque.
  //  * the gear's angle-transmission error, periodic in the motor angle: the pair sin(f q),
  //    cos(f q) with f = transmission_error_rad_per_rad (the harmonic per motor revolution x the
  //    gear ratio). The link sits te(θ) off the motor, which the motor encoder cannot see (the
  //    paper's reason for measuring with the IMS); the pair's coefficients hold its amplitude
  //    and phase (the phase also takes the mean gear deflection), their taps the loop's response
  //    at the error's frequency, which grows with the speed.
  // Taps: input_taps for the model torque and the direction, torque_sign_taps for the sign,
  // transmission_error_taps for each of the pair (identify_joint sets OrderGrid::extra_taps).
  bool model_torque_input = false;
  bool direction_input = false;
  bool torque_sign_input = false;
  bool transmission_error_input = false;
  // A second transmission-error pair sin(f_2 (x + τ / k)), cos(f_2 (x + τ / k)) beside the first
  // (needs transmission_error_input; f_2 = transmission_error_2_rad_per_rad, other than f).
  bool second_transmission_error_input = false;
  double direction_speed_scale_rad_s = 0.01;
  double torque_sign_scale_fraction = 0.01;
  double transmission_error_rad_per_rad = 0.0;    // of this joint; > 0 with the input
  double transmission_error_2_rad_per_rad = 0.0;  // of this joint; > 0 with the second pair
  // The gear's compliance 1 / k [rad/(N m)]: the motor sits τ / k ahead of the link under the
  // model torque τ, so the error's phase is f (q + τ / k) (0: the link angle alone).
  double transmission_error_compliance_rad_per_nm = 0.0;
  // The pairs through the joint's locked-motor gear mode (the gear-mode kinds of
  // ident/exogenous_inputs.hpp): none, instead of the plain pairs (with their taps), or beside
  // them with transmission_error_mode_taps each (the plain pairs keep the loop's response at the
  // error's frequency, the filtered ones the mode's transient; the filtered pair is narrow-band,
  // so many taps of it are nearly collinear). The mode: natural frequency [rad/s] and damping
  // ratio; 0: none (the gear-mode pairs equal the plain ones).
  GearModePairs transmission_error_mode_pairs = GearModePairs::kNone;
  double transmission_error_mode_rad_s = 0.0;
  double transmission_error_mode_damping = 0.0;
  int input_taps = 32;
  int torque_sign_taps = 1;
  int transmission_error_taps = 8;
  int transmission_error_mode_taps = 4;
  OrderGrid grid{1, 32, 1, 32, 0, 4};
  OrderCriterion criterion = OrderCriterion::kBic;
  double validation_fraction = 0.3;  // of every segment (or block), held out (its end)
  double validation_block_s = 0.0;   // > 0: segments cut into blocks of this length [s]
  ValidationOptions validation;
  std::size_t min_rows_per_cell = 1000;  // estimation rows; fewer: the cell is filled
  // Excitation: RMS of the desired speed over the cell's estimation rows [rad/s]; a cell where
  // the joint (nearly) stands still carries no information about its dynamics.
  double min_rms_speed_rad_s = 1e-3;
  double stability_margin = 1e-3;
  bool identify_backlash = true;
  BacklashOptions backlash;
  double min_relative_pivot = 1e-12;  // of the sweep (OrderSelectionOptions)
  ArxFitOptions fit;
};

struct CellIdentification {
  int cell = 0;
  std::string label;
  CellStatus status = CellStatus::kIdentified;
  int filled_from = -1;
  std::string reason;  // why it was not identified
  std::size_t estimation_rows = 0, validation_rows = 0;
  double rms_speed_rad_s = 0.0;
  std::optional<OrderSweepResult> sweep;
  std::optional<ArxFitResult> fit;
  std::optional<ArxValidationReport> validation;
  std::optional<StabilityCheck> stability;
};

struct JointIdentification {
  JointParameters parameters;
  BacklashEstimate backlash;
  std::vector<CellIdentification> cells;  // flat order of the grid
  // The whole table's held-out joint-error fit, its cells blended as the precontrol blends them
  // (ident/table_fit.hpp): what the joint's correction achieves, where a cell's own figure
  // judges its model only on its own held-out runs.
  TableFit table_fit;
};

// The eq. 2 model (input q_d, output q̂, dead time 0) equivalent to an error model of the form
// above (input w, output e, its own dead time δ): na unchanged, nb = max(na + 1, δ + nb_e + 1).
ArxModel angle_form_of_error_model(const ArxModel& error_model);

// The defined neutral model of a joint that could not be identified: one pass-through cell
// (q̂ = q_d, so Δq̂ = 0) over the speed range 0..max_speed, no backlash, the reason in the cell.
// The precontrol then adds exactly zero for that joint.
// extra_inputs: the table's further inputs (the neutral cell gives them zero coefficients).
JointParameters neutral_joint_parameters(const std::string& name, double max_speed_rad_s,
                                         const std::string& reason, int extra_inputs = 0);
// The same as a whole identification result (for reports): those parameters, no backlash, one
// cell with status kNeutral, label "neutral" and the reason.
JointIdentification neutral_joint_identification(const std::string& name, double max_speed_rad_s,
                                                 const std::string& reason, int extra_inputs = 0);

// The further inputs the options switch on (ident/exogenous_inputs.hpp), in the order of the
// table and of the fit: model torque, direction, torque sign, transmission-error sin and cos
// (then the second order's), then the gear-mode pairs (first, second order).
std::vector<TableInput> extra_inputs_of(const JointIdentificationOptions& options);
// The number of them (the transmission error counts twice).
int extra_input_count(const JointIdentificationOptions& options);
// The taps the options give one of them (OrderGrid::extra_taps).
int extra_input_taps(TableInput input, const JointIdentificationOptions& options);
// The most taps any switched-on further input takes (0: none): with the largest dead time, what
// the precontrol must hold per input (kMaxPrecontrolOrder, ident/precontrol.hpp).
int longest_extra_input_taps(const JointIdentificationOptions& options);
// The constants of the inputs for one joint, with the torque-sign scale found from its data.
ExogenousParameters exogenous_parameters(const JointIdentificationOptions& options,
                                         double torque_sign_scale_nm);

// segments: [begin, end) ranges of separate runs. model_torque_nm: the joint's model torque per
// sample (needed with options.model_torque_input), along q_desired in the forward forms and
// along the measured link path in the inverse form. Throws std::invalid_argument for bad sizes,
// std::runtime_error when no cell at all can be identified (with every cell's reason).
JointIdentification identify_joint(const std::string& name, std::span<const double> q_desired_rad,
                                   std::span<const double> q_measured_rad,
                                   std::span<const double> payload_kg,
                                   std::span<const std::pair<std::size_t, std::size_t>> segments,
                                   double cycle_s, const CellGrid& grid,
                                   const JointIdentificationOptions& options = {},
                                   std::span<const double> model_torque_nm = {});

// The held-out joint-error fit of an identified joint's models on ANOTHER record of the same
// joint (e.g. the simulator's truth of a run that was identified from its measurement, or a
// second measurement of the same motion): the record is split into estimation and held-out rows
// as identify_joint splits it, its samples are assigned to the identification's cells, and each
// identified cell's fitted model is run free on the held-out rows with the identification's
// backlash and torque-sign scale, as identify_joint validates it on its own data (the same
// figure as CellFitFigures::joint_error_fit_percent). Row-weighted over the cells; NaN without
// held-out rows. options and grid: those of the identification. Throws std::invalid_argument on
// size mismatches or another grid.
struct HeldOutReplay {
  double joint_error_fit_percent = std::numeric_limits<double>::quiet_NaN();
  std::size_t validation_rows = 0;
};
HeldOutReplay replay_held_out_fit(const JointIdentification& identified,
                                  std::span<const double> q_desired,
                                  std::span<const double> q_measured,
                                  std::span<const double> payload,
                                  std::span<const std::pair<std::size_t, std::size_t>> segments,
                                  double cycle_s, const CellGrid& grid,
                                  const JointIdentificationOptions& options,
                                  std::span<const double> model_torque_nm = {});

}  // namespace imscal::ident
