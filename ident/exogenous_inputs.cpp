#include "ident/exogenous_inputs.hpp"

#include <algorithm>

#include "ident/parameter_table.hpp"

namespace imscal::ident {

// kind_of indexes the descriptors by the enum's value.
static_assert([] {
  for (int i = 0; i < kExogenousInputKindCount; ++i)
    if (int(kExogenousInputKinds[i].input) != i) return false;
  return true;
}());

const ExogenousInputKind& kind_of(TableInput input) {
  return kExogenousInputKinds[std::size_t(input)];
}

const char* to_string(TableInput input) {
  return kind_of(input).name;
}

ExogenousParameters exogenous_parameters(const ParameterTable& table,
                                         const JointParameters& joint) {
  ExogenousParameters p;
  p.direction_speed_scale_rad_s = table.direction_speed_scale_rad_s;
  p.torque_sign_scale_nm = joint.torque_sign_scale_nm;
  p.transmission_error_rad_per_rad = joint.transmission_error_rad_per_rad;
  p.transmission_error_2_rad_per_rad = joint.transmission_error_2_rad_per_rad;
  p.transmission_error_compliance_rad_per_nm = joint.transmission_error_compliance_rad_per_nm;
  p.transmission_error_mode_rad_s = joint.transmission_error_mode_rad_s;
  p.transmission_error_mode_damping = joint.transmission_error_mode_damping;
  return p;
}

bool has_input(std::span<const TableInput> inputs, TableInput input) {
  return std::find(inputs.begin(), inputs.end(), input) != inputs.end();
}

bool has_pair(std::span<const TableInput> inputs, TableInput sin_kind, TableInput cos_kind) {
  return has_input(inputs, sin_kind) || has_input(inputs, cos_kind);
}

std::string exogenous_inputs_problem(std::span<const TableInput> inputs) {
  for (const TableInput input : inputs)
    if (kind_of(input).needs_model_torque_input && !has_input(inputs, TableInput::kModelTorque))
      return std::string("the ") + kind_of(input).family + " input needs the model torque input";
  return {};
}

std::string exogenous_parameters_problem(std::span<const TableInput> inputs,
                                         const ExogenousParameters& p) {
  if (has_input(inputs, TableInput::kTorqueSign) && !(p.torque_sign_scale_nm > 0.0))
    return "the torque-sign input needs a scale > 0";
  const double compliance = p.transmission_error_compliance_rad_per_nm;
  if (!(compliance >= 0.0 && std::isfinite(compliance)))
    return "the transmission error's compliance must be finite and >= 0";
  if (compliance > 0.0 && !has_input(inputs, TableInput::kModelTorque))
    return "the transmission error's compliance needs the model torque input";
  using enum TableInput;
  const bool plain = has_pair(inputs, kTransmissionErrorSin, kTransmissionErrorCos);
  const bool filtered = has_pair(inputs, kTransmissionErrorModeSin, kTransmissionErrorModeCos);
  const bool transmission_error = plain || filtered;
  const double f = p.transmission_error_rad_per_rad;
  if (transmission_error && !(f > 0.0 && std::isfinite(f)))
    return "the transmission-error inputs need a phase rate > 0";
  const bool second = has_pair(inputs, kTransmissionError2Sin, kTransmissionError2Cos) ||
                      has_pair(inputs, kTransmissionError2ModeSin, kTransmissionError2ModeCos);
  const double f2 = p.transmission_error_2_rad_per_rad;
  if (second && !(f2 >= 0.0 && std::isfinite(f2) && f2 != f))
    return "the second transmission-error inputs need a phase rate >= 0 other than the first's "
           "(0: no second order on the joint)";
  if (has_pair(inputs, kTransmissionError2Sin, kTransmissionError2Cos) && !plain)
    return "the second transmission-error inputs need the first transmission-error inputs";
  if (has_pair(inputs, kTransmissionError2ModeSin, kTransmissionError2ModeCos) && !filtered)
    return "the second gear-mode transmission-error inputs need the first gear-mode inputs";
  const double mode = p.transmission_error_mode_rad_s, damping = p.transmission_error_mode_damping;
  if (!(mode >= 0.0 && std::isfinite(mode) && damping >= 0.0 && std::isfinite(damping)))
    return "the transmission error's gear mode needs a finite frequency and damping >= 0";
  if (mode > 0.0 && !(damping > 0.0))
    return "the transmission error's gear mode needs a damping ratio > 0";
  if (mode > 0.0 && !filtered)
    return "the transmission error's gear mode needs the gear-mode transmission-error inputs";
  return {};
}

}  // namespace imscal::ident
