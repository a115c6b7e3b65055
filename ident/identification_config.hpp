#pragma once
// The identification config (YAML, read by `imscal identify --config`): the operating-point
// grid and the options of ident/joint_identification.hpp. Degrees appear only here, in the key
// names; everything is converted to SI on loading. Shipped default with every key explained:
// datasets/identification/ident-default.yaml.
#include <cstddef>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "core/config_node.hpp"
#include "ident/joint_identification.hpp"
#include "ident/operating_point.hpp"

namespace imscal::ident {

struct ExtraDimension {
  OperatingQuantity quantity = OperatingQuantity::kPosition;
  std::vector<double> bounds_si;  // the same for every joint
};

// The durations a config may state in seconds instead of cycles (NaN: given as a count, or not
// at all), by key path: model.preview_s (preview_cycles), model.input_history_s (input_taps),
// model.torque_sign_history_s (torque_sign_taps), model.transmission_error_history_s
// (transmission_error_taps), model.transmission_error_gear_mode_history_s
// (transmission_error_gear_mode_taps), cells.min_estimation_s (min_rows).
struct ConfigDurations {
  static constexpr double kNone = std::numeric_limits<double>::quiet_NaN();
  double preview_s = kNone;
  double input_history_s = kNone;
  double torque_sign_history_s = kNone;
  double transmission_error_history_s = kNone;
  double transmission_error_gear_mode_history_s = kNone;
  double min_estimation_s = kNone;
};

struct IdentificationConfig {
  std::string file;   // the config file (messages of refusals made against a record)
  std::string robot;  // `robot:` the speeds, gear data and rating are of; empty: not named
  // `cycle_s:` the cycle the config's counts (preview_cycles, *_taps, min_rows, the order grid,
  // validation.max_lag) are in; NaN: not stated (counts are then taken in the record's cycle).
  double counts_cycle_s = std::numeric_limits<double>::quiet_NaN();
  ConfigDurations durations;
  std::map<std::string, std::size_t> key_lines;  // line of robot, cycle_s and each duration key
  // The record cycle the durations were last turned into counts for (ident/
  // identification_config_record.hpp); at loading, cycle_s or 2 ms.
  double resolved_cycle_s = 0.002;
  std::vector<double> max_speed_rad_s;  // per joint, in the joint order of the data
  // Per joint (motor revolutions per joint revolution), for the transmission-error inputs; empty
  // when the config gives none.
  std::vector<double> gear_ratio;
  std::vector<double> gear_stiffness_nm_per_rad;  // per joint; empty: the phase from q alone
  double transmission_error_harmonic_per_motor_rev = 1.0;
  // Per joint, when given (a list in the config, or found from the data by an order search):
  // replaces transmission_error_harmonic_per_motor_rev for that joint.
  std::vector<double> transmission_error_harmonic_per_joint;
  // The harmonic per motor revolution of one joint's transmission error.
  double transmission_error_harmonic(std::size_t joint) const;
  // Per joint, a second harmonic (found from the data by the order search, other than the
  // first), with options.second_transmission_error_input; 0 (or a joint beyond the list): the
  // joint has no second order, its model leaves the pair out (zero coefficients in the table).
  std::vector<double> transmission_error_second_harmonic_per_joint;
  // `model.transmission_error_gear_mode:` each joint's transmission-error pairs through its
  // locked-motor gear mode as a filter with state along the path (ident/gear_mode_filter.hpp),
  // the mode found before identifying (eval/transmission_error_gear_mode.hpp): per joint its
  // natural frequency [rad/s] and damping ratio (empty, or 0 for a joint: the plain pair).
  // `model.transmission_error_gear_mode_pairs: instead | beside` (options.
  // transmission_error_mode_pairs): the filtered pairs instead of the plain ones (their taps), or
  // beside them with `transmission_error_gear_mode_taps` each.
  bool transmission_error_gear_mode = false;
  std::vector<double> transmission_error_mode_rad_s;
  std::vector<double> transmission_error_mode_damping;
  double nominal_payload_kg = 16.0;
  std::vector<double> speed_fraction_bounds{0.0, 0.2, 0.8, 1.0};  // of max speed (paper, Table 2)
  std::vector<double> payload_fraction_bounds{0.0, 0.5, 1.0};     // of nominal payload
  std::vector<ExtraDimension> extra_dimensions;
  JointIdentificationOptions options;
  // `model.refine_mass_parameters:` the model torque's link masses and centres of mass refined
  // from the record before the tables are identified (eval/mass_refinement.hpp).
  bool refine_mass_parameters = false;
  // `model.refine_gravity:` the same refinement with the gravity's columns only: the links'
  // first moments from the static gravity torque's derivatives, the masses nominal
  // (eval::MassRefinementOptions::gravity_first_moments). Not with refine_mass_parameters.
  bool refine_gravity = false;

  // Speed × payload (× extra dimensions) of one joint, in SI. Throws std::invalid_argument for
  // a joint without a maximum speed.
  CellGrid joint_grid(std::size_t joint) const;
  // The options of one joint: `options` with the joint's transmission-error phase rate
  // (harmonic x gear ratio) when that input is on. Throws std::invalid_argument for a joint
  // without a gear ratio then.
  JointIdentificationOptions joint_options(std::size_t joint) const;
};

// InputError (file, line, key) on unknown keys, bad values or an inconsistent grid.
IdentificationConfig load_identification_config(const ConfigNode& root);

}  // namespace imscal::ident
