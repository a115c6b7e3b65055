#pragma once
// The data of a sim-to-real gap diagnosis: per joint and controller cycle, the gap
// between the measured ("real") joint error and the predicted ("sim") one, and the known signals
// from which the candidate effects are built (desired joints and their derivatives, the rigid-
// body torques of the desired motion, gear ratios, time).
//
//   joint error  Δq = q_desired - q_measured   (paper, Fig. 2; ident/joint_error_io.hpp)
//   gap          g  = Δq_real - Δq_sim         [rad]
//
// "sim" is either the identified error model (parameters.json) run on the desired joints, or a
// second joint_errors.csv (e.g. the simulator's prediction without some effect). The desired
// derivatives are central differences of q_desired within each run (one-sided at its ends).
#include <Eigen/Core>
#include <cstddef>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "eval/gap_measurement_prior.hpp"
#include "ident/joint_error_io.hpp"
#include "ident/parameter_table.hpp"
#include "robot/robot_description.hpp"

namespace imscal::eval {

struct GapSignals {
  double cycle_s = 0.002;
  std::vector<std::string> joint_names;
  std::vector<double> time_s, payload_kg;
  std::vector<std::pair<std::size_t, std::size_t>> runs;  // [begin, end) without time gaps
  // [joint][sample]
  std::vector<std::vector<double>> q_desired_rad, qd_desired_rad_s, qdd_desired_rad_s2;
  std::vector<std::vector<double>> q_internal_rad;  // motor encoder / N of the real run
  // Its derivatives (as those of q_desired) and the rigid-body torque of that motion: the drive's
  // actual motion, which lags q_desired by the tracking error (~1 / kp_position, 80 ms on the
  // main axes). Friction acts on the motor's own velocity and the gear torque changes sign when
  // the actual motion's torque does, so these time reversals and torque zero crossings where
  // q_desired would place them ~0.1 s off. Empty: not known (the candidates then use q_desired).
  std::vector<std::vector<double>> qd_internal_rad_s, torque_internal_nm;
  std::vector<std::vector<double>> gap_rad;             // real - sim joint error
  std::vector<std::vector<double>> gravity_torque_nm;   // its gravity part G(q_d)
  std::vector<std::vector<double>> torque_nm;           // inverse dynamics on q_d, logged payload
  std::vector<std::vector<double>> unit_payload_nm_kg;  // torque change per kg of extra payload
  // The same along the drive's actual motion (q_internal): the payload loads the arm as it moves,
  // ~80 ms behind q_d on the main axes. Empty: not known (the candidates then use the above).
  std::vector<std::vector<double>> unit_payload_internal_nm_kg;
  // The arm's mass matrix along q_d with the logged payload, M_ij(q_d) [kg m²] at
  // [i * joint_count() + j][sample]: how much torque an acceleration of joint j asks of joint i.
  // The coupled dynamics spread one joint's effect over the others through it (see
  // eval/gap_coupling.hpp). Empty: not known (no robot model, e.g. in synthetic tests).
  std::vector<std::vector<double>> mass_matrix_kg_m2;
  std::vector<double> gear_ratio;       // motor angle = N * joint angle
  std::vector<double> max_speed_rad_s;  // the robot's joint speed limits
  // The nominal model's drive parameters (the robot description; empty: not known, taken as
  // none): how far a candidate may lower them before the combined model turns unphysical
  // (eval/gap_candidates.hpp, physical bounds).
  std::vector<double> nominal_compliance_rad_per_nm;  // 1 / gear stiffness, 0: rigid
  std::vector<double> nominal_half_play_rad;          // half the backlash's full width
  std::vector<double> nominal_coulomb_nm;             // Coulomb friction torque
  // The operating-point grids of the identified model (empty without a table), per joint, and
  // whether each of its cells was identified from data (false: filled from a neighbour).
  std::vector<std::vector<ident::CellDimension>> table_dimensions;
  std::vector<std::vector<bool>> table_cell_identified;
  // The joint-space signatures of geometric errors of the IMS chain (empty without a robot
  // model, e.g. in synthetic tests), per joint: samples x parameters, the gap [rad] one unit of
  // each parameter causes. See ImsChainColumns.
  struct ImsChainColumns {
    Eigen::MatrixXd dh;         // 18: a_i [m], alpha_i [rad], d_i [m] of links i = 1..6
    Eigen::MatrixXd mounting;   // 6: sensor mounting error twist in the flange (t_x..z [m], r_x..z)
    Eigen::MatrixXd gyro_bias;  // 3: rate bias about the flange axes x, y, z [rad/s]
    Eigen::MatrixXd gyro_scale;   // 3: scale factor error of the flange-axis rates [1]
    Eigen::MatrixXd accel_scale;  // 1: isotropic accelerometer scale error [1]
    Eigen::MatrixXd world_rate;   // 3: rate error fixed in the base axes x, y, z [rad/s]
    Eigen::MatrixXd start_pose;   // 6: error of the first sample's joint angles dq0 [rad]
  };
  std::vector<ImsChainColumns> ims_chain_columns;
  // The IMS chain's own error budget (eval/gap_measurement_prior.hpp); not known by default.
  MeasurementPrior measurement;

  std::size_t sample_count() const { return time_s.size(); }
  std::size_t joint_count() const { return joint_names.size(); }
};

// The joint errors the identified model predicts on the log's desired joints: per joint every
// cell's ARX model runs free on q_d (paper, eq. 2), the cells are blended by the operating point
// as the precontrol does (ident/cell_blending.hpp), and the backlash term l * sign(q̇_d(k - lag))
// (eq. 3) is added. Runs restart at every time gap. Result [joint][sample], rad.
// Throws std::invalid_argument when the table's joints do not match the log's.
std::vector<std::vector<double>> predict_table_joint_errors(const ident::ParameterTable& table,
                                                            const ident::JointErrorLog& log);

// The chain's geometric error signatures (GapSignals::ImsChainColumns) along q_desired, to first
// order: the IMS chain gives the flange pose T_meas = T_true exp(xi) (xi a body twist of the
// flange: translation in flange axes [m], rotation [rad]); the inverse kinematics with the nominal
// model returns q_m = q + Jb^-1 xi (Jb the body Jacobian, damped near singularities), so the
// joint error q_d - q_m gains -Jb^-1 xi. Per parameter, xi is:
//   dh           T(q; p)^-1 T(q; p + dp): the real arm's DH numbers differ from the nominal ones
//   mounting     (Ad(H_T_H0) - I) xi_D: a mounting error D of the sensor, seen relative to the
//                first sample's pose H0 where the chain is initialised (it cancels there)
//   gyro_bias    (0, R^T u), u = integral of R_R_H e_i dt: the attitude drifts in the base frame
//   gyro_scale   (0, R^T u), u = integral of R_R_H e_i (e_i . w_H) dt: rate scaled per axis
//   accel_scale  (R^T (p - p0), 0): the travelled displacement scaled
//   world_rate   (0, R^T e_i (t - t0)): an attitude drift about a base axis (the Earth rate
//                resolved through a wrong base rotation; eval/gap_measurement_prior.hpp)
//   start_pose   Ad(T^-1 T0) Jb(q0) e_i: the first sample's joint angles, from which the chain
//                starts, off by dq0 (a constant base-frame pose error of every later sample)
// The sensor is taken to sit at the flange (the diagnosis does not know T_S_H); the smoother's
// rest updates, which bound these errors in the real chain, are not modelled (open-loop
// signatures: they give the shape, the fit the size).
std::vector<GapSignals::ImsChainColumns> ims_chain_columns(
    const calib::KinematicModel& kinematics, const std::vector<std::vector<double>>& q_rad,
    const std::vector<std::vector<double>>& qd_rad_s, const std::vector<double>& time_s);

// Builds the signals: gap = (q_d - q_m)_real - sim_joint_error_rad. The robot gives the torques
// (KDL inverse dynamics with a point payload of the logged mass at the tool frame origin) and
// the gear ratios; its joint names must match the log's (std::invalid_argument otherwise).
GapSignals make_gap_signals(const ident::JointErrorLog& real,
                            const std::vector<std::vector<double>>& sim_joint_error_rad,
                            const calib::RobotDescription& robot,
                            const ident::ParameterTable* table_or_null = nullptr);

// The joint errors q_d - q_m of a log, [joint][sample].
std::vector<std::vector<double>> measured_joint_errors(const ident::JointErrorLog& log);

}  // namespace imscal::eval
