#pragma once
// Each joint's locked-motor gear mode, which the transmission-error inputs pass through
// (ident/exogenous_inputs.hpp): ω_n = √(k / M), ζ = c / (2 √(k M)).
//  * M: the link-side inertia M_jj(q) of the NOMINAL robot's rigid-body model (with the log's
//    payload as a point mass at T, eval/model_torque.hpp), the median over the log's samples
//    where the joint moves. One value per joint: the table carries no pose, so the mode's shift
//    with the arm's reach (up to ~1.7× in ω_n on A1) is not followed.
//  * k: the stiffness the data show (ident/identified_structure.hpp, the static gain of the
//    model-torque input, from an identification of the log without the mode), where it is more
//    than 4σ from zero and within 0.5–2× the nominal robot's; otherwise the nominal robot's.
//  * ζ: a prior, the nominal robot's damping ratio c / (2 √(k M)) with its own c and k at that M
//    (5 % on the shipped KR 16): the data of a 2 ms log at the error's amplitudes (arcseconds)
//    do not resolve it.
// Only the nominal robot and the log are read; the plant never is.
//
// References (docs/references.md): [Spong2006] (the flexible-joint model and its locked-motor
// mode).
#include <string>
#include <vector>

#include "eval/model_torque.hpp"
#include "ident/identification_config.hpp"
#include "ident/joint_error_io.hpp"

namespace imscal::eval {

struct JointGearMode {
  double inertia_kg_m2 = 0.0;  // median M_jj over the moving samples
  double stiffness_nm_per_rad = 0.0;
  bool stiffness_from_data = false;
  double data_stiffness_nm_per_rad = 0.0;  // NaN: not identified
  double data_stiffness_sigma_nm_per_rad = 0.0;
  double damping_ratio = 0.0;
  double natural_frequency_rad_s = 0.0;
};

// Median M_jj [kg m²] of each joint over the samples (every 10th) where it moves faster than
// min_speed_rad_s; over all samples where it never does.
std::vector<double> median_link_inertia_kg_m2(const ident::JointErrorLog& log,
                                              const ModelTorqueSource& model,
                                              double min_speed_rad_s = 0.05);

// The mode of one joint from its inertia, the data's stiffness estimate (NaN: none) with 1σ,
// and the nominal drive.
JointGearMode gear_mode_of(double inertia_kg_m2, double data_stiffness_nm_per_rad,
                           double data_stiffness_sigma_nm_per_rad,
                           const calib::DriveParameters& nominal_drive);

// With config.transmission_error_gear_mode: identifies the log once without the modes (its model
// torques attached) for the stiffness, and fills config's per-joint modes. Returns the modes
// (empty when the option is off).
std::vector<JointGearMode> set_transmission_error_gear_modes(ident::IdentificationConfig& config,
                                                             const ident::JointErrorLog& log,
                                                             const ModelTorqueSource& model);

// One joint's mode in words, for the log.
std::string describe_gear_mode(const JointGearMode& mode);

}  // namespace imscal::eval
