#pragma once
// Verification of the dynamic calibration (paper, section 4): the same path run by the
// uncalibrated robot and by the robot with the precontrol in the loop (eval/closed_loop.hpp), n
// cycles each, compared by ISO 9283 path characteristics (eval/iso9283_path.hpp) and by the
// maximum perpendicular path deviation (eval/path_deviation.hpp, the paper's Fig. 6).
//
// Cycles: the simulator is deterministic, so a cycle is one run of the path by a plant whose
// friction is drawn anew (Coulomb and viscous friction of every joint scaled by 1 + σ N(0, 1),
// σ = friction_sigma_fraction; run-to-run friction changes with temperature and lubrication are
// the main cause of path repeatability errors of geared arms). Cycle j uses the same draw with
// and without compensation, so the comparison is paired.
//
// Which part of the path is evaluated: the Cartesian segments (lin, circ/circle) whose label
// contains segment_filter (all of them when empty). The plant is run from lead_in_s before the
// first of them (if the robot is at rest there; the plant starts balanced at rest, so this is
// the same as having arrived and settled) to lead_out_s after the last, to save time.
//
// The attained path is the flange's, as the IMS chain measures it (VerificationOptions::
// measure_with_ims: the plant's run recorded by the scenario's simulated IMS, mechanized,
// smoothed, through the frames and the inverse kinematics), and by forward kinematics of the
// link-side joint angles the plant reached (the truth, VerificationCase::true_figures).
//
// Identification from simulator truth: joint errors q_d - q_link of a scenario's run, one sample
// per controller cycle (a stand-in for the IMS chain's joint_errors.csv), and the parameter
// table identified from them with an identification config (ident/identification_config.hpp).
#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "eval/closed_loop.hpp"
#include "ident/identification_config.hpp"
#include "ident/joint_error_io.hpp"
#include "ident/joint_identification.hpp"
#include "sim/scenario.hpp"

namespace imscal::eval {

// ---- Identification from the simulator's truth --------------------------------------------

// Runs the scenario's program through its plant and returns q_d and q_link (as q_measured and,
// for lack of an encoder model here, q_internal = motor angle / N) every controller cycle, in a
// log of the scenario's nominal robot (its name and joints: what the chain is given).
// max_duration_s cuts the program (lighter runs under sanitizers).
ident::JointErrorLog simulate_truth_joint_errors(
    const sim::Scenario& scenario, double max_duration_s = std::numeric_limits<double>::infinity());

// The same run measured as the paper measures it: the plant's link-side motion recorded by the
// scenario's simulated IMS and taken through the chain (eval/ims_measured_path.hpp), q_measured
// the IMS's joint angles (samples the chain could not measure are left out: the log then has
// gaps), q_internal the encoders. seed: the sensor's draw. The joint_errors.csv `imscal
// calibrate` writes, with the frames known (their calibration: tests/calib's figures).
ident::JointErrorLog simulate_ims_joint_errors(
    const sim::Scenario& scenario, std::uint64_t seed = 1,
    double max_duration_s = std::numeric_limits<double>::infinity());

struct IdentifiedTable {
  ident::ParameterTable table;
  std::vector<ident::JointIdentification> joints;  // reports (chosen orders, fits, backlash)
  // Joints where no cell could be identified: "A5: <reason>"; their table entry is the defined
  // neutral model (ident::neutral_joint_parameters: one pass-through cell, q̂ = q_d, no backlash:
  // exactly zero compensation of that joint) so that the rest can be verified.
  std::vector<std::string> failed_joints;
};

// The rigid-body model of the nominal robot, with the scenario site's normal gravity in R: the
// model torques of multi-input tables (eval/model_torque.hpp). Never the plant's masses.
ModelTorqueSource nominal_model_torque(const sim::NominalRobot& nominal,
                                       const sim::Scenario& scenario);
// The same for the scenario's nominal robot (sim::load_nominal_robot).
ModelTorqueSource scenario_model_torque(const sim::Scenario& scenario);

// identify_joint for every joint of the log (as `imscal identify`). source_file names the data.
// A config whose models take the model torque needs `torque_model` (the torques are attached to
// a copy of the log along the path its form reads) or torques already in the log
// (std::invalid_argument otherwise). With config.transmission_error_gear_mode, the joints' gear
// modes come from `torque_model` (eval/transmission_error_gear_mode.hpp); without a model, none.
IdentifiedTable identify_table(const ident::JointErrorLog& log,
                               const ident::IdentificationConfig& config,
                               const std::string& source_file = "simulator truth",
                               const ModelTorqueSource* torque_model = nullptr);

// The ablation: the config with one part changed at a time, so that the contribution
// of each part is measured on the same paths. Labels say what changed:
//  * "paper form": the paper's model as it stands (eq. 2 in joint-error form, no further inputs,
//    the operating-point grid of Table 2, the backlash term of eq. 3), for any config;
//  * "without model torque": the torque and torque-sign inputs off (configs that have them; the
//    transmission error's phase then from the link angle alone);
//  * "without transmission error": the transmission-error pair off (configs that have it);
//  * "with/without backlash term": eq. 3's backlash identification and term switched;
//  * "with operating-point grid" / "single cell": Table 2's speed x payload cells instead of one
//    cell per joint, or the reverse.
struct AblationConfig {
  std::string label;
  ident::IdentificationConfig config;
};
std::vector<AblationConfig> ablation_configs(const ident::IdentificationConfig& config);

// Parts of an ablation, each on its own: Table 2's grid (speed 0 .. 0.2 .. 0.8 .. 1 of the
// maximum x payload 0 .. 0.5 .. 1 of nominal), one cell per joint, the paper's model form.
ident::IdentificationConfig with_operating_point_grid(ident::IdentificationConfig config);
ident::IdentificationConfig single_cell(ident::IdentificationConfig config);
ident::IdentificationConfig paper_form(ident::IdentificationConfig config);

// The held-out joint-error fit of every joint of an identified table on ANOTHER record of the
// same runs (ident::replay_held_out_fit): e.g. a table identified from the IMS-measured joint
// errors, judged against the simulator's true joint errors, which tells the model's own error
// from the measurement's noise in the held-out target. One figure per joint (NaN: the joint was
// not identified, or no held-out rows). config and torque_model as for identify_table.
std::vector<double> replay_held_out_fits(const IdentifiedTable& identified,
                                         const ident::JointErrorLog& reference,
                                         const ident::IdentificationConfig& config,
                                         const ModelTorqueSource* torque_model = nullptr);

// Held-out simulation fit of a joint: the identified cells' figures weighted by their held-out
// rows (NaN when no cell has held-out data).
struct JointFitSummary {
  double simulation_fit_percent = std::numeric_limits<double>::quiet_NaN();
  double joint_error_fit_percent = std::numeric_limits<double>::quiet_NaN();
  std::size_t validation_rows = 0;
};
JointFitSummary summarize_fit(const ident::JointIdentification& joint);

// ---- Verification --------------------------------------------------------------------------

struct VerificationOptions {
  int cycles = 10;
  std::uint64_t seed = 1;
  double friction_sigma_fraction = 0.05;
  std::string segment_filter;  // label substring of the evaluated Cartesian segments
  // The IMS chain needs its aiding around the evaluated segments, as a lab recording has it: a
  // rest before them (its first rest: 2 s, of which the still part is kept; with 1 s the
  // compensated runs kept 0.5 s and the chain's errors grew to 0.2-0.7 mm on seed-line) and
  // the standstill after them (the readings' creep velocities from 1 s after the stop; with
  // 0.5 s the smoother ran free to the record's end, 1.3 mm off on seed-line's second line).
  double lead_in_s = 2.0;
  double lead_out_s = 3.0;
  // The precontrol's supervisor at its defaults: tolerances from the table's envelope of the
  // identification data (ident/precontrol.hpp; the 100 % ISO 9283 small circle needs A3 offsets
  // of 25 mrad, which a fixed 20 mrad tolerance switched off). Look-ahead 4 cycles = 8 ms = 2τ,
  // the low-frequency delay of the precontrol's critically damped smoother (τ = 4 ms): the offset
  // then lands in the cycle it is computed for. Inversion iterations stay 0 (they need
  // look-ahead 0 and a forward-form table): on the simulated KR 16 one iteration amplifies the
  // unmodelled high-frequency part until the supervisor's rate tolerance switches the
  // compensation off, and even with the TRUE plant the iteration does not converge.
  CompensationOptions compensation = [] {
    CompensationOptions c;
    c.look_ahead_cycles = 4;
    c.warm_up_cycles = 500;  // 1 s at 2 ms: the precontrol settled before the run (closed_loop.hpp)
    return c;
  }();
  // The attained path as the paper measures it: recorded by the scenario's simulated IMS and
  // taken through the chain (eval/ims_measured_path.hpp; sensor draws seeded per cycle from
  // ims_seed, the same for a cycle's uncompensated and compensated runs). false: the plant's
  // true link-side path (a perfect measurement).
  bool measure_with_ims = true;
  std::uint64_t ims_seed = 1;
  // Computes the offsets of a table along the path (default, when empty: run_precontrol). The
  // online bridge's benchmark puts the RSI server behind it (bench/bench_rsi_iso9283.cpp).
  std::function<CompensationRun(const ident::ParameterTable&, const std::string& robot_name,
                                const sim::DesiredJointPath&, const CompensationOptions&)>
      compensation_runner;
  int calculation_points = 200;      // ISO 9283 calculation points per segment
  double iso_time_window_s = 0.25;   // a crossing counts within this time of its point
  double deviation_window_s = 0.25;  // path deviation: desired path within this time
};

// ISO 9283 path characteristics over the evaluated segments (each segment is one ISO path; the
// figures are the worst over the segments) and the path deviation (max over the cycles).
struct PathFigures {
  double AT_p_m = 0.0, RT_p_m = 0.0;
  Eigen::Vector3d AT_abc_rad = Eigen::Vector3d::Zero(), RT_abc_rad = Eigen::Vector3d::Zero();
  // The programs' paths stop at every end (no corner run through), so CO is the overshoot at the
  // end of each straight segment along its direction (ISO's overshoot applied to the stop) and
  // CR is not defined (NaN).
  double CO_m = 0.0;
  double CR_m = std::numeric_limits<double>::quiet_NaN();
  double AV_percent = 0.0;  // the segment with the largest |AV|, signed
  double RV_percent = 0.0, FV_m_s = 0.0;
  double max_path_deviation_m = 0.0;  // max over cycles and evaluated segments
  double rms_path_deviation_m = 0.0;  // RMS over cycles and samples
  // The cycles' own scatter as a floor under max_path_deviation_m: at each instant, half the
  // widest distance between two cycles' deviation vectors (each from its closest desired point),
  // the max over the instants. A command that is the same in every cycle (any precontrol fed the
  // desired path) moves every cycle's point alike, so it cannot bring the max deviation below
  // this, as long as the scatter itself does not change with the command (the offsets change the
  // speeds, on which friction depends, by < 1 %). It is the repeatability's share of the max
  // deviation: the friction drawn per cycle and, as measured, the IMS's per-cycle errors.
  double scatter_floor_m = 0.0;
  // The same cycles split at each instant into their mean (systematic_max_m: the max of the
  // repeatable error, what the model gets wrong) and the distances from it (about_mean_max_m:
  // the max deviation a precontrol exact on average would leave) (eval::split_cycles).
  double systematic_max_m = 0.0;
  double about_mean_max_m = 0.0;
  int missed_crossings = 0;
};

// Series of cycle 0 for the paper's Fig. 5 (paths) and Fig. 6 (deviation along the path), at
// every controller cycle inside the evaluated segments.
struct PlotSeries {
  std::vector<double> t_s;
  std::vector<double> arc_length_m;  // along the desired path, through the evaluated segments
  std::vector<Eigen::Vector3d> desired_m, attained_m;
  std::vector<double> deviation_m;
};

struct VerificationCase {
  std::string label;         // "uncompensated" or the table's label
  PathFigures figures;       // of the attained path as measured (by the IMS chain when enabled)
  PathFigures true_figures;  // of the plant's true link-side path (equal without the IMS chain)
  PlotSeries series;
  std::vector<ident::PrecontrolEvent> events;  // precontrol events (compensated cases)
  std::size_t inactive_cycles = 0;             // cycles with the precontrol not active
};

struct NamedTable {
  std::string label;
  ident::ParameterTable table;
};

struct VerificationResult {
  std::string scenario;
  int cycles = 0;
  double evaluated_from_s = 0.0, evaluated_to_s = 0.0;  // scenario clock
  std::vector<std::string> segments;                    // labels of the evaluated segments
  VerificationCase before;
  std::vector<VerificationCase> after;  // one per table, in the given order
  // Commanded and attained flange poses of every case's cycles, for `imscal evaluate`
  // (poses[case][cycle], case 0 = before; the commanded path is desired_poses).
  std::vector<std::vector<std::vector<Eigen::Matrix<double, 8, 1>>>> attained_poses;
  std::vector<Eigen::Matrix<double, 8, 1>> desired_poses;  // t, x, y, z, qw, qx, qy, qz
};

// The precontrol's options in verify_scenario: options.compensation, with the scenario's nominal
// model torque (scenario_model_torque) unless it holds one.
CompensationOptions verification_compensation(const sim::Scenario& scenario,
                                              const VerificationOptions& options);

// The closed loop: the scenario's plant (sim::load_plant_robot) plans, runs and gives the true
// path; the chain's side (the IMS chain's kinematics, the model torque, the precontrol) uses its
// nominal robot only. Throws InputError for a scenario that cannot be loaded,
// std::invalid_argument when no segment matches the filter or a table is refused.
VerificationResult verify_scenario(const sim::Scenario& scenario,
                                   const std::vector<NamedTable>& tables,
                                   const VerificationOptions& options = {});

// 100 (1 - after / before): the reduction in percent.
double reduction_percent(double before, double after);

}  // namespace imscal::eval
