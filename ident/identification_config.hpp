#pragma once
// The identification config (YAML, read by `imscal identify --config`): the operating-point
// grid and the options of ident/joint_identification.hpp. Degrees appear only here, in the key
// names; everything is converted to SI on loading. Shipped default with every key explained:
// datasets/identification/ident-default.yaml.
#include <cstddef>
#include <vector>

#include "core/config_node.hpp"
#include "ident/joint_identification.hpp"
#include "ident/operating_point.hpp"

namespace imscal::ident {

struct ExtraDimension {
  OperatingQuantity quantity = OperatingQuantity::kPosition;
  std::vector<double> bounds_si;  // the same for every joint
};

struct IdentificationConfig {
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
  double nominal_payload_kg = 16.0;
  std::vector<double> speed_fraction_bounds{0.0, 0.2, 0.8, 1.0};  // of max speed (paper, Table 2)
  std::vector<double> payload_fraction_bounds{0.0, 0.5, 1.0};     // of nominal payload
  std::vector<ExtraDimension> extra_dimensions;
  JointIdentificationOptions options;

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
