#pragma once
// The further (exogenous) inputs x_e of the ARX models (imscal's multi-input extension of the
// paper's eq. 2), defined once: their kinds and names, the constants they depend on, and the one
// function that computes their values from a sample's joint state. The identification
// (ident/joint_identification.cpp), the real-time precontrol (ident/precontrol.cpp, inside its
// cycle: no allocation, no exception) and the test reference (tests/support/
// reference_precontrol.hpp) all call exogenous_values, so the three cannot disagree.
//
// The kinds (the maths and why: ident/joint_identification.hpp, JointIdentificationOptions):
//  * model_torque: the joint torque τ of the robot's rigid-body model [N m], from the caller;
//  * direction: the direction of motion tanh(ẋ / direction_speed_scale);
//  * torque_sign: the side of the gear the model torque presses on, tanh(τ / torque_sign_scale);
//  * transmission_error_sin / _cos: the gear's angle-transmission error as the pair
//    sin(f (x + τ / k)), cos(f (x + τ / k)), f = harmonic per motor revolution x gear ratio,
//    1 / k the gear's compliance (the motor angle the deflected gear sits at);
//  * transmission_error_2_sin / _cos: the same pair at a second harmonic f_2 (a gear's error
//    repeats at several of its stages' tooth and lobe counts over the motor revolution);
//  * transmission_error_mode_sin / _cos, transmission_error_2_mode_sin / _cos: the same pairs
//    through the joint's locked-motor gear mode (natural frequency ω_n > 0, damping ratio ζ),
//    beside the plain pairs or instead of them. The error is a displacement between motor and
//    link, and at the joint speed ẋ it oscillates at Ω = f ẋ, where the mode
//    H(s) = ω_n² / (s² + 2 ζ ω_n s + ω_n²) turns sin φ into Im(H(jΩ) e^{jφ}) and cos φ into
//    Re(H(jΩ) e^{jφ}): the resonance the plain pair's FIR taps cannot follow (decay time
//    1 / (ζ ω_n) ≈ 0.2 s at 15 Hz, 5 %). Along a path (the identification's segments, the
//    precontrol's model steps) each is the mode as a filter with state (ident/gear_mode_filter.hpp,
//    exogenous_values with an ExogenousFilterState), which follows the error's frequency sweeping
//    through the mode faster than the mode's decay; a single sample (exogenous_value) gets the
//    filter's steady state H(jΩ) e^{jφ}. Without a mode (ω_n = 0) they equal the plain pairs.
//    Tables before version 7 filtered the plain pairs' kinds of joints with a mode; they are read
//    as these kinds (ident/parameter_table_io.hpp).
#include <array>
#include <cmath>
#include <complex>
#include <span>
#include <string>

#include "ident/gear_mode_filter.hpp"

namespace imscal::ident {

struct ParameterTable;
struct JointParameters;

enum class TableInput {
  kModelTorque,
  kDirection,
  kTorqueSign,
  kTransmissionErrorSin,
  kTransmissionErrorCos,
  kTransmissionError2Sin,
  kTransmissionError2Cos,
  kTransmissionErrorModeSin,
  kTransmissionErrorModeCos,
  kTransmissionError2ModeSin,
  kTransmissionError2ModeCos
};

// One input kind: how parameters.json names it, the words errors use for it, the first table
// schema version that has it, and whether its value needs the model torque input beside it.
struct ExogenousInputKind {
  TableInput input;
  const char* name;
  const char* family;  // "the <family> input(s) ..." in messages
  int since_schema_version;
  bool needs_model_torque_input;
};
inline constexpr ExogenousInputKind kExogenousInputKinds[] = {
    {TableInput::kModelTorque, "model_torque", "model-torque", 2, false},
    {TableInput::kDirection, "direction", "direction", 2, false},
    {TableInput::kTorqueSign, "torque_sign", "torque-sign", 2, true},
    {TableInput::kTransmissionErrorSin, "transmission_error_sin", "transmission-error", 3, false},
    {TableInput::kTransmissionErrorCos, "transmission_error_cos", "transmission-error", 3, false},
    {TableInput::kTransmissionError2Sin, "transmission_error_2_sin", "second transmission-error", 4,
     false},
    {TableInput::kTransmissionError2Cos, "transmission_error_2_cos", "second transmission-error", 4,
     false},
    {TableInput::kTransmissionErrorModeSin, "transmission_error_mode_sin",
     "gear-mode transmission-error", 7, false},
    {TableInput::kTransmissionErrorModeCos, "transmission_error_mode_cos",
     "gear-mode transmission-error", 7, false},
    {TableInput::kTransmissionError2ModeSin, "transmission_error_2_mode_sin",
     "second gear-mode transmission-error", 7, false},
    {TableInput::kTransmissionError2ModeCos, "transmission_error_2_mode_cos",
     "second gear-mode transmission-error", 7, false},
};
inline constexpr int kExogenousInputKindCount = int(std::size(kExogenousInputKinds));
const ExogenousInputKind& kind_of(TableInput input);
// "model_torque", "direction", "torque_sign", "transmission_error_sin", "transmission_error_cos",
// "transmission_error_2_sin", "transmission_error_2_cos", "transmission_error_mode_sin", ...
const char* to_string(TableInput input);

// The joint state of one sample the inputs are computed from: the model's input path x (the
// desired angle, or the link's path in the inverse form), its rate, and the model torque along
// it (0 when the caller has none: no input that reads it is then switched on).
struct ExogenousSample {
  double angle_rad = 0.0;
  double speed_rad_s = 0.0;
  double model_torque_nm = 0.0;
};

// The constants the inputs' values depend on, of one joint (0 where the input is not used).
struct ExogenousParameters {
  double direction_speed_scale_rad_s = 0.01;
  double torque_sign_scale_nm = 0.0;
  double transmission_error_rad_per_rad = 0.0;
  // The second harmonic's phase rate (0: the joint has no second order, the pair's inputs are 0).
  double transmission_error_2_rad_per_rad = 0.0;
  double transmission_error_compliance_rad_per_nm = 0.0;
  // The joint's locked-motor gear mode of the gear-mode pairs (0: none, they equal the plain
  // pairs).
  double transmission_error_mode_rad_s = 0.0;
  double transmission_error_mode_damping = 0.0;
};
// A table's constants for one of its joints.
ExogenousParameters exogenous_parameters(const ParameterTable& table, const JointParameters& joint);
bool has_input(std::span<const TableInput> inputs, TableInput input);
// Whether `inputs` has either kind of a pair (its sin or its cos).
bool has_pair(std::span<const TableInput> inputs, TableInput sin_kind, TableInput cos_kind);
// Why the list `inputs` cannot be computed (an input needs another that is missing); empty when
// it can.
std::string exogenous_inputs_problem(std::span<const TableInput> inputs);
// Why a joint's constants cannot feed `inputs`; empty when they can.
std::string exogenous_parameters_problem(std::span<const TableInput> inputs,
                                         const ExogenousParameters& p);

// The joint angle the motor sits at, x + τ / k [rad]: the transmission error's phase per its
// phase rate f.
inline double transmission_error_motor_angle(const ExogenousParameters& p,
                                             const ExogenousSample& s) noexcept {
  const double compliance = p.transmission_error_compliance_rad_per_nm;
  return s.angle_rad + (compliance != 0.0 ? compliance * s.model_torque_nm : 0.0);
}

// The motor-side phase f (x + τ / k) of the transmission error [rad].
inline double transmission_error_phase(const ExogenousParameters& p,
                                       const ExogenousSample& s) noexcept {
  return p.transmission_error_rad_per_rad * transmission_error_motor_angle(p, s);
}

// The gear mode's response H(jΩ) = ω_n² / (ω_n² − Ω² + 2 j ζ ω_n Ω) at the error's frequency
// Ω = phase rate × speed [rad/s] (signed: H(−jΩ) is H(jΩ)'s conjugate); 1 without a mode.
inline std::complex<double> gear_mode_response(const ExogenousParameters& p,
                                               double phase_rate_rad_per_rad,
                                               double speed_rad_s) noexcept {
  const double w = p.transmission_error_mode_rad_s;
  if (!(w > 0.0)) return {1.0, 0.0};
  const double omega = phase_rate_rad_per_rad * speed_rad_s;
  return w * w /
         std::complex<double>(w * w - omega * omega,
                              2.0 * p.transmission_error_mode_damping * w * omega);
}

// The pair (Im, Re) of H(jΩ) e^{jφ}: the response of sin φ and of cos φ through the gear mode
// (the plain pair without a mode, or with filtered false).
inline double transmission_error_pair_value(const ExogenousParameters& p,
                                            double phase_rate_rad_per_rad, const ExogenousSample& s,
                                            bool sine, bool filtered) noexcept {
  const double phase = phase_rate_rad_per_rad * transmission_error_motor_angle(p, s);
  const double sin_phase = std::sin(phase), cos_phase = std::cos(phase);
  if (!filtered || !(p.transmission_error_mode_rad_s > 0.0)) return sine ? sin_phase : cos_phase;
  const std::complex<double> h = gear_mode_response(p, phase_rate_rad_per_rad, s.speed_rad_s);
  return sine ? h.real() * sin_phase + h.imag() * cos_phase
              : h.real() * cos_phase - h.imag() * sin_phase;
}

// The second order's pair; 0 on a joint without a second order (phase rate 0), so that its zero
// coefficients are not needed for the pair to do nothing.
inline double second_transmission_error_pair_value(const ExogenousParameters& p,
                                                   const ExogenousSample& s, bool sine,
                                                   bool filtered) noexcept {
  const double f_2 = p.transmission_error_2_rad_per_rad;
  return f_2 == 0.0 ? 0.0 : transmission_error_pair_value(p, f_2, s, sine, filtered);
}

inline double exogenous_value(TableInput input, const ExogenousParameters& p,
                              const ExogenousSample& s) noexcept {
  const double f_1 = p.transmission_error_rad_per_rad;
  switch (input) {
    case TableInput::kModelTorque:
      return s.model_torque_nm;
    case TableInput::kDirection:
      return std::tanh(s.speed_rad_s / p.direction_speed_scale_rad_s);
    case TableInput::kTorqueSign:
      return std::tanh(s.model_torque_nm / p.torque_sign_scale_nm);
    case TableInput::kTransmissionErrorSin:
      return transmission_error_pair_value(p, f_1, s, true, false);
    case TableInput::kTransmissionErrorCos:
      return transmission_error_pair_value(p, f_1, s, false, false);
    case TableInput::kTransmissionError2Sin:
      return second_transmission_error_pair_value(p, s, true, false);
    case TableInput::kTransmissionError2Cos:
      return second_transmission_error_pair_value(p, s, false, false);
    case TableInput::kTransmissionErrorModeSin:
      return transmission_error_pair_value(p, f_1, s, true, true);
    case TableInput::kTransmissionErrorModeCos:
      return transmission_error_pair_value(p, f_1, s, false, true);
    case TableInput::kTransmissionError2ModeSin:
      return second_transmission_error_pair_value(p, s, true, true);
    case TableInput::kTransmissionError2ModeCos:
      return second_transmission_error_pair_value(p, s, false, true);
  }
  return 0.0;
}

// The values of `inputs` (in their order) of one sample, into values[0 .. inputs.size()).
inline void exogenous_values(std::span<const TableInput> inputs, const ExogenousParameters& p,
                             const ExogenousSample& s, double* values) noexcept {
  for (std::size_t e = 0; e < inputs.size(); ++e) values[e] = exogenous_value(inputs[e], p, s);
}

// The further inputs' state along a path: the gear mode's filter of each transmission-error pair.
struct ExogenousFilterState {
  GearModeStep mode;  // Φ for the joint's mode and the path's step
  GearModeFilterState pair_1, pair_2;
};

// Sets the mode for a path sampled every step_s and restarts both pairs: the next sample settles
// them at its own speed.
inline void restart_exogenous_filter(ExogenousFilterState& state, const ExogenousParameters& p,
                                     double step_s) noexcept {
  state.mode =
      gear_mode_step(p.transmission_error_mode_rad_s, p.transmission_error_mode_damping, step_s);
  state.pair_1.started = false;
  state.pair_2.started = false;
}

// The values of `inputs` of the next sample of a path: with a gear mode, each gear-mode pair
// through the mode's filter (advanced once per call), otherwise as exogenous_values.
inline void exogenous_values(std::span<const TableInput> inputs, const ExogenousParameters& p,
                             const ExogenousSample& s, ExogenousFilterState& state,
                             double* values) noexcept {
  if (!(p.transmission_error_mode_rad_s > 0.0)) return exogenous_values(inputs, p, s, values);
  const double motor_angle_rad = transmission_error_motor_angle(p, s);
  const double f_1 = p.transmission_error_rad_per_rad, f_2 = p.transmission_error_2_rad_per_rad;
  std::complex<double> y_1, y_2;
  if (has_pair(inputs, TableInput::kTransmissionErrorModeSin,
               TableInput::kTransmissionErrorModeCos))
    y_1 = gear_mode_filter_advance(state.mode, state.pair_1, f_1 * motor_angle_rad,
                                   f_1 * s.speed_rad_s);
  if (f_2 != 0.0 && has_pair(inputs, TableInput::kTransmissionError2ModeSin,
                             TableInput::kTransmissionError2ModeCos))
    y_2 = gear_mode_filter_advance(state.mode, state.pair_2, f_2 * motor_angle_rad,
                                   f_2 * s.speed_rad_s);
  for (std::size_t e = 0; e < inputs.size(); ++e) switch (inputs[e]) {
      case TableInput::kTransmissionErrorModeSin:
        values[e] = y_1.imag();
        break;
      case TableInput::kTransmissionErrorModeCos:
        values[e] = y_1.real();
        break;
      case TableInput::kTransmissionError2ModeSin:
        values[e] = y_2.imag();
        break;
      case TableInput::kTransmissionError2ModeCos:
        values[e] = y_2.real();
        break;
      default:
        values[e] = exogenous_value(inputs[e], p, s);
    }
}

}  // namespace imscal::ident
