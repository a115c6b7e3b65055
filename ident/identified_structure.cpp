#include "ident/identified_structure.hpp"

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "ident/joint_identification.hpp"

namespace imscal::ident {
namespace {

int index_of(std::span<const TableInput> inputs, TableInput input) {
  for (std::size_t e = 0; e < inputs.size(); ++e)
    if (inputs[e] == input) return int(e);
  return -1;
}

StructureEstimate gain_estimate(const StaticGains& g, int e) {
  if (e < 0) return {};
  return {g.gain(e), std::sqrt(g.covariance(e, e))};
}

// f(x) with 1σ from the gradient of f at x and the gains' covariance.
StructureEstimate propagated(double value, const Eigen::VectorXd& gradient,
                             const Eigen::MatrixXd& covariance) {
  return {value, std::sqrt(gradient.dot(covariance * gradient))};
}

// A compliance within kSignificantSigmas σ of zero (or below it) is a rigid drive as far as the
// data tell: its inverse is then not defined.
constexpr double kSignificantSigmas = 3.0;

bool compliance_is_significant(const StaticGains& g, int torque) {
  return torque >= 0 &&
         g.gain(torque) > kSignificantSigmas * std::sqrt(g.covariance(torque, torque));
}

void set_transmission_error(IdentifiedStructure& s, const StaticGains& g, int sin_input,
                            int cos_input) {
  if (sin_input < 0 || cos_input < 0) return;
  const double gs = g.gain(sin_input), gc = g.gain(cos_input);
  const double amplitude = std::hypot(gs, gc);
  Eigen::VectorXd d_amplitude = Eigen::VectorXd::Zero(g.gain.size());
  Eigen::VectorXd d_phase = Eigen::VectorXd::Zero(g.gain.size());
  if (amplitude > 0.0) {
    d_amplitude(sin_input) = gs / amplitude;
    d_amplitude(cos_input) = gc / amplitude;
    d_phase(sin_input) = -gc / (amplitude * amplitude);
    d_phase(cos_input) = gs / (amplitude * amplitude);
  }
  s.transmission_error_amplitude_rad = propagated(amplitude, d_amplitude, g.covariance);
  s.transmission_error_phase_rad = propagated(std::atan2(gc, gs), d_phase, g.covariance);
}

// Inverse-variance weighted combination of the cells' gains, input by input; the covariance of
// two inputs is Σ w_a w_b cov_ab / (Σ w_a Σ w_b) (independent cells).
StaticGains combined(const std::vector<StaticGains>& cells) {
  const Eigen::Index n = cells.front().gain.size();
  Eigen::VectorXd weight_sum = Eigen::VectorXd::Zero(n), weighted = Eigen::VectorXd::Zero(n);
  Eigen::MatrixXd cross = Eigen::MatrixXd::Zero(n, n);
  for (const StaticGains& g : cells) {
    const Eigen::VectorXd w = g.covariance.diagonal().cwiseInverse();
    weight_sum += w;
    weighted += w.cwiseProduct(g.gain);
    cross += w.asDiagonal() * g.covariance * w.asDiagonal();
  }
  StaticGains out;
  out.gain = weighted.cwiseQuotient(weight_sum);
  const Eigen::VectorXd inverse = weight_sum.cwiseInverse();
  out.covariance = inverse.asDiagonal() * cross * inverse.asDiagonal();
  return out;
}

}  // namespace

StaticGains static_gains(const ArxFitResult& fit, std::span<const TableInput> inputs) {
  const ArxStructure& s = fit.model.structure();
  if (std::size_t(s.extra_inputs) != inputs.size())
    throw std::invalid_argument("static_gains: the model has " + std::to_string(s.extra_inputs) +
                                " further inputs, the table " + std::to_string(inputs.size()));
  const Eigen::VectorXd& a = fit.model.a();
  const double a_at_one = 1.0 + a.sum();
  const Eigen::Index n = Eigen::Index(inputs.size());
  StaticGains out{Eigen::VectorXd(n), Eigen::MatrixXd()};
  // Jacobian of g_e = C_e(1) / A(1) in θ = [α; β; c]: ∂/∂α_i = -g_e / A(1), ∂/∂c_e,l = 1 / A(1).
  Eigen::MatrixXd jacobian = Eigen::MatrixXd::Zero(n, s.parameter_count());
  for (int e = 0; e < s.extra_inputs; ++e) {
    const int first = s.extra_offset(e), taps = s.nx[std::size_t(e)];
    out.gain(e) = fit.model.c().segment(first, taps).sum() / a_at_one;
    jacobian.row(e).head(s.na).setConstant(-out.gain(e) / a_at_one);
    jacobian.row(e).segment(s.na + s.nb + first, taps).setConstant(1.0 / a_at_one);
  }
  out.covariance = jacobian * fit.covariance * jacobian.transpose();
  return out;
}

IdentifiedStructure structure_of_gains(const StaticGains& g, std::span<const TableInput> inputs) {
  IdentifiedStructure s;
  s.cells = 1;
  const int torque = index_of(inputs, TableInput::kModelTorque);
  const int direction = index_of(inputs, TableInput::kDirection);
  s.compliance_rad_per_nm = gain_estimate(g, torque);
  if (compliance_is_significant(g, torque)) {
    const double c = g.gain(torque);
    s.stiffness_nm_per_rad = {1.0 / c, s.compliance_rad_per_nm.sigma / (c * c)};
  }
  s.direction_offset_rad = gain_estimate(g, direction);
  // The plain pair's gains; with the gear-mode pair instead of it, that pair's (the mode's gain
  // is 1 at rest).
  const bool plain = has_input(inputs, TableInput::kTransmissionErrorSin);
  set_transmission_error(s, g,
                         index_of(inputs, plain ? TableInput::kTransmissionErrorSin
                                                : TableInput::kTransmissionErrorModeSin),
                         index_of(inputs, plain ? TableInput::kTransmissionErrorCos
                                                : TableInput::kTransmissionErrorModeCos));
  return s;
}

IdentifiedStructure identified_structure(const JointIdentification& joint,
                                         std::span<const TableInput> inputs) {
  std::vector<StaticGains> cells;
  for (const CellIdentification& cell : joint.cells)
    if (cell.status == CellStatus::kIdentified && cell.fit && !inputs.empty())
      cells.push_back(static_gains(*cell.fit, inputs));
  if (cells.empty()) return {};
  IdentifiedStructure s = structure_of_gains(combined(cells), inputs);
  s.cells = cells.size();
  return s;
}

}  // namespace imscal::ident
