#include "ident/identified_structure.hpp"

#include <cmath>
#include <complex>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>
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

// Inverse-variance weighted combination of the cells' estimates, component by component; the
// covariance of two components is Σ w_a w_b cov_ab / (Σ w_a Σ w_b) (independent cells).
template <class Estimate, class Vector, class Matrix>
Estimate combined(const std::vector<Estimate>& cells, Vector Estimate::*value,
                  Matrix Estimate::*covariance) {
  const Eigen::Index n = (cells.front().*value).size();
  Eigen::VectorXd weight_sum = Eigen::VectorXd::Zero(n), weighted = Eigen::VectorXd::Zero(n);
  Eigen::MatrixXd cross = Eigen::MatrixXd::Zero(n, n);
  for (const Estimate& g : cells) {
    const Eigen::VectorXd w = (g.*covariance).diagonal().cwiseInverse();
    weight_sum += w;
    weighted += w.cwiseProduct(g.*value);
    cross += w.asDiagonal() * (g.*covariance) * w.asDiagonal();
  }
  Estimate out;
  out.*value = weighted.cwiseQuotient(weight_sum);
  const Eigen::VectorXd inverse = weight_sum.cwiseInverse();
  out.*covariance = inverse.asDiagonal() * cross * inverse.asDiagonal();
  return out;
}

// The pair's inputs: the plain pair where the table has it, else the gear-mode pair.
std::pair<int, int> transmission_error_pair(std::span<const TableInput> inputs) {
  const bool plain = has_input(inputs, TableInput::kTransmissionErrorSin);
  return {index_of(inputs, plain ? TableInput::kTransmissionErrorSin
                                 : TableInput::kTransmissionErrorModeSin),
          index_of(inputs, plain ? TableInput::kTransmissionErrorCos
                                 : TableInput::kTransmissionErrorModeCos)};
}

// Throws std::invalid_argument unless the model has one further input per entry of `inputs`.
void require_table_inputs(const ArxStructure& s, std::span<const TableInput> inputs,
                          const std::string& caller) {
  if (std::size_t(s.extra_inputs) != inputs.size())
    throw std::invalid_argument(caller + ": the model has " + std::to_string(s.extra_inputs) +
                                " further inputs, the table " + std::to_string(inputs.size()));
}

// A cell's weight in the speed the combined pair is given at: the inverse of its variance.
double pair_weight(const PairResponse& r) {
  return 1.0 / r.covariance.trace();
}

}  // namespace

StaticGains static_gains(const ArxFitResult& fit, std::span<const TableInput> inputs) {
  const ArxStructure& s = fit.model.structure();
  require_table_inputs(s, inputs, "static_gains");
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

PairResponse transmission_error_response(const ArxFitResult& fit,
                                         std::span<const TableInput> inputs, double frequency_rad_s,
                                         FitForm form) {
  const ArxStructure& s = fit.model.structure();
  require_table_inputs(s, inputs, "transmission_error_response");
  const auto [sin_input, cos_input] = transmission_error_pair(inputs);
  if (sin_input < 0 || cos_input < 0)
    throw std::invalid_argument("transmission_error_response: no transmission-error pair");
  using Complex = std::complex<double>;
  const Complex i(0.0, 1.0);
  const Complex u = std::polar(1.0, -frequency_rad_s * fit.model.sample_time_s());  // z^-1
  const auto power = [&](int k) { return std::pow(u, k); };
  // The preview's lead z^P_v and the delay z^-δ, and N = A + z^-δ (1 - z^-1) z^P_v B in the
  // inverse form (N = A otherwise), Q = C_s + i C_c: the error at the link z^P_v z^-δ Q / N.
  const Complex lead = form.inverse ? power(-form.preview_cycles) : Complex(1.0);
  const Complex delay = power(s.dead_time);
  const Complex loop = form.inverse ? delay * (1.0 - u) * lead : Complex(0.0);
  Complex n = 1.0, q = 0.0;
  for (int k = 0; k < s.na; ++k) n += fit.model.a()(k) * power(k + 1);
  for (int j = 0; j < s.nb; ++j) n += loop * fit.model.b()(j) * power(j);
  const int first_sin = s.extra_offset(sin_input), first_cos = s.extra_offset(cos_input);
  for (int l = 0; l < s.nx[std::size_t(sin_input)]; ++l)
    q += fit.model.c()(first_sin + l) * power(l);
  for (int l = 0; l < s.nx[std::size_t(cos_input)]; ++l)
    q += i * fit.model.c()(first_cos + l) * power(l);
  const Complex response = lead * delay * q / n;
  // Its gradient in θ = [α; β; c]: ∂/∂α_i = -r z^-i / N, ∂/∂β_j = -r loop z^-j / N,
  // ∂/∂c_s,l = z^P_v z^-δ z^-l / N and i times that for c_c,l.
  Eigen::VectorXcd gradient = Eigen::VectorXcd::Zero(s.parameter_count());
  for (int k = 0; k < s.na; ++k) gradient(k) = -response * power(k + 1) / n;
  for (int j = 0; j < s.nb; ++j) gradient(s.na + j) = -response * loop * power(j) / n;
  const int c0 = s.na + s.nb;
  for (int l = 0; l < s.nx[std::size_t(sin_input)]; ++l)
    gradient(c0 + first_sin + l) = lead * delay * power(l) / n;
  for (int l = 0; l < s.nx[std::size_t(cos_input)]; ++l)
    gradient(c0 + first_cos + l) = i * lead * delay * power(l) / n;
  Eigen::MatrixXd jacobian(2, s.parameter_count());
  jacobian.row(0) = gradient.real().transpose();
  jacobian.row(1) = gradient.imag().transpose();
  return {Eigen::Vector2d(response.real(), response.imag()),
          jacobian * fit.covariance * jacobian.transpose()};
}

void set_transmission_error(IdentifiedStructure& s, const PairResponse& r) {
  const double re = r.re_im_rad(0), im = r.re_im_rad(1);
  const double amplitude = std::hypot(re, im);
  Eigen::Vector2d d_amplitude = Eigen::Vector2d::Zero(), d_phase = Eigen::Vector2d::Zero();
  if (amplitude > 0.0) {
    d_amplitude = Eigen::Vector2d(re, im) / amplitude;
    d_phase = Eigen::Vector2d(-im, re) / (amplitude * amplitude);
  }
  s.transmission_error_amplitude_rad = propagated(amplitude, d_amplitude, r.covariance);
  s.transmission_error_phase_rad = propagated(std::atan2(im, re), d_phase, r.covariance);
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
  return s;
}

IdentifiedStructure identified_structure(const JointIdentification& joint,
                                         std::span<const TableInput> inputs, FitForm form) {
  const auto [sin_input, cos_input] = transmission_error_pair(inputs);
  const bool pair = sin_input >= 0 && cos_input >= 0;
  const double phase_rate_rad_per_rad = joint.parameters.transmission_error_rad_per_rad;
  std::vector<StaticGains> cells;
  std::vector<PairResponse> responses;
  double speed_sum = 0.0, weight_sum = 0.0;
  for (const CellIdentification& cell : joint.cells) {
    if (cell.status != CellStatus::kIdentified || !cell.fit || inputs.empty()) continue;
    cells.push_back(static_gains(*cell.fit, inputs));
    if (!pair) continue;
    responses.push_back(transmission_error_response(
        *cell.fit, inputs, phase_rate_rad_per_rad * cell.rms_speed_rad_s, form));
    speed_sum += pair_weight(responses.back()) * cell.rms_speed_rad_s;
    weight_sum += pair_weight(responses.back());
  }
  if (cells.empty()) return {};
  IdentifiedStructure s =
      structure_of_gains(combined(cells, &StaticGains::gain, &StaticGains::covariance), inputs);
  s.cells = cells.size();
  if (pair) {
    set_transmission_error(
        s, combined(responses, &PairResponse::re_im_rad, &PairResponse::covariance));
    s.transmission_error_joint_speed_rad_s = speed_sum / weight_sum;
    s.transmission_error_frequency_hz =
        phase_rate_rad_per_rad * s.transmission_error_joint_speed_rad_s / (2.0 * std::numbers::pi);
  }
  return s;
}

}  // namespace imscal::ident
