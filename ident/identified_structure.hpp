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
//  * transmission error sin(φ), cos(φ): the pair is fitted where the joint moves, so its
//    static gains are not what the data hold (their many taps leave C_e(1) free: 2-4x the
//    plant's error on the population's plants, decision 0085). At the joint speed v the error's
//    phase φ = f x turns at Ω = f v [rad/s] (f the phase rate per joint radian), and the pair's
//    responses H_e = z^-δ C_e(z^-1) / A(z^-1) at z = e^{iΩT} (T the cycle) turn the inputs
//    sin(Ωt), cos(Ωt) into Im(P e^{iΩt}), P = H_s + i H_c. In the joint-error form that is the
//    error the pair adds at the link. In the inverse form it is the command offset that cancels
//    it, with the pair's inputs P_v cycles ahead: the link follows the command through the loop
//    G, which the same model holds (u = y + e, e = H_w (1 - z^-1) z^P_v y + ..., so 1 / G =
//    1 + H_w (1 - z^-1) z^P_v with H_w = z^-δ B / A), and the error at the link is
//    G z^P_v P = z^P_v z^-δ Q / N, Q = C_s + i C_c, N = A + z^-δ (1 - z^-1) z^P_v B.
//    Amplitude |·| [rad] and phase arg(·) [rad] of the error a sin(φ + ψ); as Ω -> 0 they are
//    the static gains' √(g_s² + g_c²) and atan2(g_c, g_s). Each cell is taken at its own rms
//    speed; the report gives the speed and frequency the cells' weights average to. The 1σ is
//    the fit's alone: where the response changes across a cell's speeds (the slow joints of the
//    population's plants, 1.5-2.4x the plant's error at their rms speed) it does not cover that.
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
  // The transmission error a sin(φ + ψ) at the link, at the error's frequency in the data: its
  // amplitude a, phase ψ, and the joint speed and error frequency (Ω / 2π) the cells give them
  // at (each cell's rms speed, averaged with the weights that combine the cells).
  StructureEstimate transmission_error_amplitude_rad;
  StructureEstimate transmission_error_phase_rad;
  double transmission_error_joint_speed_rad_s = std::numeric_limits<double>::quiet_NaN();
  double transmission_error_frequency_hz = std::numeric_limits<double>::quiet_NaN();
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

// How a fit's error relates to the link (ident/joint_identification.hpp, ArxModelForm): the
// inverse form's error is a command offset and its inputs lead by preview_cycles; the others'
// error is the link's.
struct FitForm {
  bool inverse = false;
  int preview_cycles = 0;
};

// The transmission-error pair of one fitted cell model at the error's frequency Ω [rad/s]: the
// error at the link as [Re, Im] of its complex amplitude (above), with covariance (delta method,
// analytic gradient in θ). The pair is the plain one where `inputs` has it, else the gear-mode
// one (the mode's gain is in its inputs: this is the error before the mode). Throws
// std::invalid_argument when the fit's structure does not have inputs.size() further inputs or
// `inputs` has no pair.
struct PairResponse {
  Eigen::Vector2d re_im_rad;
  Eigen::Matrix2d covariance;
};
PairResponse transmission_error_response(const ArxFitResult& fit,
                                         std::span<const TableInput> inputs, double frequency_rad_s,
                                         FitForm form = {});

// The structure of one cell's gains (NaN where the input is absent; the transmission error is
// left NaN: it needs the frequency, set_transmission_error).
IdentifiedStructure structure_of_gains(const StaticGains& gains,
                                       std::span<const TableInput> inputs);
// The amplitude and phase of a pair's response, with 1σ.
void set_transmission_error(IdentifiedStructure& s, const PairResponse& response);

// The structure of a joint: its identified cells' gains combined, and their transmission-error
// responses at each cell's rms speed times the joint's phase rate (cells == 0 and NaN values when
// none was identified or the model has none of these inputs).
IdentifiedStructure identified_structure(const JointIdentification& joint,
                                         std::span<const TableInput> inputs, FitForm form = {});

}  // namespace imscal::ident
