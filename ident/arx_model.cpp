#include "ident/arx_model.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

#include "ident/lagged_products.hpp"

namespace imscal::ident {

ArxModel::ArxModel(ArxStructure structure, Eigen::VectorXd a, Eigen::VectorXd b,
                   double sample_time_s)
    : ArxModel(structure, std::move(a), std::move(b), Eigen::VectorXd(), sample_time_s) {}

ArxModel::ArxModel(ArxStructure structure, Eigen::VectorXd a, Eigen::VectorXd b, Eigen::VectorXd c,
                   double sample_time_s)
    : structure_(structure),
      a_(std::move(a)),
      b_(std::move(b)),
      c_(std::move(c)),
      sample_time_s_(sample_time_s) {
  structure_.validate();
  if (a_.size() != structure_.na || b_.size() != structure_.nb ||
      c_.size() != structure_.extra_coefficient_count())
    throw std::invalid_argument("ArxModel: coefficient counts (" + std::to_string(a_.size()) +
                                ", " + std::to_string(b_.size()) + ", " +
                                std::to_string(c_.size()) + ") do not match " +
                                to_string(structure_));
  if (!(sample_time_s_ > 0.0)) throw std::invalid_argument("ArxModel: sample time must be > 0");
}

Eigen::VectorXd ArxModel::parameters() const {
  Eigen::VectorXd theta(a_.size() + b_.size() + c_.size());
  theta << a_, b_, c_;
  return theta;
}

namespace {

// Adds the input part of rows first .. n-1, Σ_j b_j u(k-d-j) + Σ_e Σ_j c_e,j x_e(k-d-j), to
// part[first..n), as FIR filters over the rows (ident/lagged_products.hpp) instead of a scalar
// sum per row, each row's terms in the order b, then c (the free run then only recurses over
// the na autoregressive terms).
void add_input_part(const ArxStructure& s, const Eigen::VectorXd& b, const Eigen::VectorXd& c,
                    const IoSegment& segment, std::size_t first, std::span<double> part) {
  const std::size_t n = segment.input.size();
  if (first >= n) return;
  const std::size_t rows = n - first;
  const std::size_t start = first - static_cast<std::size_t>(s.dead_time);
  // subtract_fir subtracts: the negated coefficients add (exactly: negation does not round).
  const Eigen::VectorXd minus_b = -b, minus_c = -c;
  subtract_fir(segment.input.data() + start, minus_b.data(), s.nb, rows, part.data() + first);
  for (int e = 0; e < s.extra_inputs; ++e)
    subtract_fir(segment.extra[static_cast<std::size_t>(e)].data() + start,
                 minus_c.data() + s.extra_offset(e), s.nx[std::size_t(e)], rows,
                 part.data() + first);
}

void check_extras(const ArxStructure& s, const IoSegment& segment, const char* where) {
  if (segment.extra_count != s.extra_inputs)
    throw std::invalid_argument(std::string(where) + ": the model has " +
                                std::to_string(s.extra_inputs) + " further inputs, the data " +
                                std::to_string(segment.extra_count));
  for (int e = 0; e < s.extra_inputs; ++e)
    if (segment.extra[static_cast<std::size_t>(e)].size() != segment.input.size())
      throw std::invalid_argument(std::string(where) + ": a further input's length differs");
}

}  // namespace

void ArxModel::predict_one_step(const IoSegment& segment, std::span<double> predicted) const {
  const std::size_t n = segment.output.size();
  if (segment.input.size() != n || predicted.size() != n)
    throw std::invalid_argument("ArxModel::predict_one_step: sizes differ");
  check_extras(structure_, segment, "ArxModel::predict_one_step");
  const std::size_t first = static_cast<std::size_t>(structure_.max_lag());
  const auto& y = segment.output;
  for (std::size_t k = 0; k < std::min(first, n); ++k) predicted[k] = y[k];
  if (first >= n) return;
  // Every row sums -a_1 y(k-1) - ... then + b_0 u(k-d) + ..., then the further inputs: the order
  // in which data are simulated (tests/support/arx_systems.hpp), so a noise-free model predicts
  // its own data exactly.
  std::fill(predicted.begin() + std::ptrdiff_t(first), predicted.end(), 0.0);
  if (structure_.na > 0)
    subtract_fir(y.data() + first - 1, a_.data(), structure_.na, n - first,
                 predicted.data() + first);
  add_input_part(structure_, b_, c_, segment, first, predicted);
}

void ArxModel::simulate(std::span<const double> input, std::span<const double> initial_output,
                        std::span<double> simulated) const {
  if (structure_.extra_inputs > 0)
    throw std::invalid_argument("ArxModel::simulate: the model has further inputs");
  simulate(IoSegment{input, initial_output}, simulated);
}

void ArxModel::simulate(const IoSegment& segment, std::span<double> simulated) const {
  const std::size_t n = segment.input.size();
  const std::size_t first = static_cast<std::size_t>(structure_.max_lag());
  if (simulated.size() != n) throw std::invalid_argument("ArxModel::simulate: sizes differ");
  if (segment.output.size() < std::min(first, n))
    throw std::invalid_argument("ArxModel::simulate: need max_lag initial outputs");
  check_extras(structure_, segment, "ArxModel::simulate");
  for (std::size_t k = 0; k < std::min(first, n); ++k) simulated[k] = segment.output[k];
  if (first < n) std::fill(simulated.begin() + std::ptrdiff_t(first), simulated.end(), 0.0);
  add_input_part(structure_, b_, c_, segment, first, simulated);
  for (std::size_t k = first; k < n; ++k) {
    double sum = simulated[k];
    for (int i = 0; i < structure_.na; ++i) sum -= a_[i] * simulated[k - 1 - i];
    simulated[k] = sum;
  }
}

void ArxModel::predict_joint_error(std::span<const double> input,
                                   std::span<const double> initial_output,
                                   std::span<double> joint_error) const {
  simulate(input, initial_output, joint_error);
  const std::size_t first = static_cast<std::size_t>(structure_.max_lag());
  const std::size_t d = static_cast<std::size_t>(structure_.dead_time);
  for (std::size_t k = 0; k < joint_error.size(); ++k)
    joint_error[k] = k < first ? 0.0 : input[k - d] - joint_error[k];
}

Eigen::VectorXcd ArxModel::poles() const {
  const int na = structure_.na;
  if (na == 0) return Eigen::VectorXcd(0);
  // Companion matrix of z^na + a_1 z^(na-1) + ... + a_na: first row -a, ones on the
  // sub-diagonal; its characteristic polynomial is A(z).
  Eigen::MatrixXd companion = Eigen::MatrixXd::Zero(na, na);
  companion.row(0) = -a_.transpose();
  for (int i = 1; i < na; ++i) companion(i, i - 1) = 1.0;
  Eigen::EigenSolver<Eigen::MatrixXd> solver(companion, /*computeEigenvectors=*/false);
  if (solver.info() != Eigen::Success)
    throw std::runtime_error("ArxModel::poles: eigenvalue iteration did not converge");
  return solver.eigenvalues();
}

double ArxModel::spectral_radius() const {
  const Eigen::VectorXcd p = poles();
  return p.size() == 0 ? 0.0 : p.cwiseAbs().maxCoeff();
}

double ArxModel::static_gain() const {
  const double a_at_one = 1.0 + a_.sum();
  if (a_at_one == 0.0) return std::numeric_limits<double>::infinity();
  return b_.sum() / a_at_one;
}

double ArxModel::extra_static_gain(int e) const {
  if (e < 0 || e >= structure_.extra_inputs)
    throw std::invalid_argument("ArxModel::extra_static_gain: no further input " +
                                std::to_string(e));
  const double a_at_one = 1.0 + a_.sum();
  if (a_at_one == 0.0) return std::numeric_limits<double>::infinity();
  return c_.segment(structure_.extra_offset(e), structure_.nx[std::size_t(e)]).sum() / a_at_one;
}

}  // namespace imscal::ident
