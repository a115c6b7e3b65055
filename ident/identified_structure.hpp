#pragma once
// The drive structure an identified joint model implies, with 1σ: what the ARX models of
// ident/joint_identification.hpp hold about the joint beside their dynamics.
//
// At rest (all increments zero) the error form e(k) + Σ α_i e(k-i) = Σ β_j w(k-δ-j) + Σ_e Σ_l
// c_e,l x_e(k-δ-l) reduces to e = Σ_e g_e x_e with the static gains g_e = C_e(1) / A(1),
// A(1) = 1 + Σ α_i, C_e(1) = Σ_l c_e,l. Read per further input (ident/exogenous_inputs.hpp):
//  * model torque τ: g is the joint error per N m the joint carries, the drive's static
//    compliance [rad/(N m)] (the gear's 1 / k where the position loop holds the motor without a
//    standing error, plus the loop's own static compliance where it has one); its inverse the
//    stiffness [N m/rad], defined where the compliance is more than 3σ above zero (otherwise the
//    data show a rigid drive: stiffness NaN);
//  * direction tanh(q̇ / s) (±1 while moving): g is the offset the direction of motion adds as
//    the speed tends to zero [rad], half the step at a reversal. It is not the Coulomb friction
//    through the gear's compliance: on the simulated KR 16 (A4: 10 N m through 3e4 N m/rad,
//    69″) it is 9″, the rest taken by the increments' terms and the position loop;
//  * transmission error sin(φ), cos(φ): the pair of gains (g_s, g_c) is the error
//    A sin(φ + ψ) with amplitude A = √(g_s² + g_c²) [rad] and phase ψ = atan2(g_c, g_s) [rad].
// 1σ by first-order propagation (delta method) of the least-squares covariance σ_e² (ΦᵀΦ)⁻¹ of
// θ = [α; β; c] (ident/arx_fit.hpp), which takes the equation errors as white: the chosen ARX
// order whitens them (the validation's residual correlation test says where it did not).
// Several identified cells combine by inverse-variance weighting (their rows are disjoint).
//
// References (docs/references.md): [Ljung1999] (static gain; covariance of least squares and
// Gauss's approximation formula for functions of the estimates, ch. 9).
#include <cstddef>
#include <limits>
#include <span>

#include "ident/arx_fit.hpp"
#include "ident/exogenous_inputs.hpp"

namespace imscal::ident {

struct JointIdentification;

struct StructureEstimate {
  double value = std::numeric_limits<double>::quiet_NaN();
  double sigma = std::numeric_limits<double>::quiet_NaN();  // 1σ; NaN: not identified
  bool identified() const { return value == value; }
};

struct IdentifiedStructure {
  std::size_t cells = 0;  // identified cells combined
  StructureEstimate compliance_rad_per_nm;
  StructureEstimate stiffness_nm_per_rad;
  StructureEstimate direction_offset_rad;
  StructureEstimate transmission_error_amplitude_rad;
  StructureEstimate transmission_error_phase_rad;
  // The values the identification was given (NaN where it had none): the config's gear
  // compliance 1 / k and the transmission error's harmonic per motor revolution.
  double nominal_compliance_rad_per_nm = std::numeric_limits<double>::quiet_NaN();
  double transmission_error_harmonic_per_motor_rev = std::numeric_limits<double>::quiet_NaN();
};

// The static gains of one fitted cell model, one per further input in `inputs` order, and their
// covariance (delta method). Throws std::invalid_argument when the fit's structure does not
// have inputs.size() further inputs.
struct StaticGains {
  Eigen::VectorXd gain;
  Eigen::MatrixXd covariance;
};
StaticGains static_gains(const ArxFitResult& fit, std::span<const TableInput> inputs);

// The structure of one cell's gains (NaN where the input is absent).
IdentifiedStructure structure_of_gains(const StaticGains& gains,
                                       std::span<const TableInput> inputs);

// The structure of a joint: its identified cells' gains combined (cells == 0 and NaN values when
// none was identified or the model has none of these inputs).
IdentifiedStructure identified_structure(const JointIdentification& joint,
                                         std::span<const TableInput> inputs);

}  // namespace imscal::ident
