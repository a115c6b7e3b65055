#include "ident/friction_levels.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <stdexcept>
#include <vector>

namespace imscal::ident {
namespace {

constexpr int kLevels = 3;  // F_c, F_v, J

// The least-squares problem at one dead time: regression rows (sample indices), the following
// error and the three friction regressors x_m per sample.
struct FrictionProblem {
  const JointFrictionSignals* signals = nullptr;
  std::vector<double> error;  // q_desired(k − δ) − q_internal(k), 0 where k − δ leaves the segment
  std::vector<std::size_t> rows;
  std::vector<double> direction;  // tanh(q̇ / s)
  int na = 0;                     // lags of e
  std::size_t step = 1;           // decimation of the rows
  std::size_t delay = 0;          // δ [cycles]

  int parameter_count() const { return na + 2 + kLevels; }
  double x(int m, std::size_t k) const {
    if (m == 0) return direction[k];
    return m == 1 ? signals->speed_rad_s[k] : signals->acceleration_rad_s2[k - delay];
  }
};

FrictionProblem make_problem(const JointFrictionSignals& s, const FrictionLevelOptions& options,
                             int dead_time) {
  const std::size_t n = s.desired_rad.size();
  if (s.internal_rad.size() != n || s.model_torque_nm.size() != n || s.speed_rad_s.size() != n ||
      s.acceleration_rad_s2.size() != n)
    throw std::invalid_argument("friction levels: signals of different lengths");
  if (options.decimation < 1 || options.error_lags < 1)
    throw std::invalid_argument("friction levels: decimation, lags and taps must be positive");
  FrictionProblem p;
  p.signals = &s;
  p.na = options.error_lags;
  p.step = std::size_t(options.decimation);
  p.direction.resize(n);
  for (std::size_t k = 0; k < n; ++k)
    p.direction[k] = std::tanh(s.speed_rad_s[k] / options.direction_speed_scale_rad_s);
  const auto delay = std::size_t(dead_time);
  p.delay = delay;
  p.error.assign(n, 0.0);
  for (const auto& [begin, end] : s.segments) {
    for (std::size_t k = begin + delay; k < std::min(end, n); ++k)
      p.error[k] = s.desired_rad[k - delay] - s.internal_rad[k];
    const std::size_t first = begin + delay + std::size_t(p.na - 1 + options.smoothing_samples);
    for (std::size_t k = first; k < std::min(end, n); k += p.step) p.rows.push_back(k);
  }
  return p;
}

// The linear regression of the drive's torque balance: rows k, columns
//   [e(k−i), i = 0..n−1 | Σ_{m<=k} e(m) Δt | 1 | −tanh(q̇/s) | −q̇ | −q̈ | extra(k − δ)],
// target the model torque τ(k).
void regression(const FrictionProblem& pb, const FrictionLevelOptions& options,
                std::span<const std::span<const double>> extra, Eigen::MatrixXd& columns,
                Eigen::VectorXd& target) {
  const std::size_t n = pb.error.size();
  const int lags = pb.na, sum = lags, one = lags + 1, level = lags + 2;
  // Per-sample signals: e, ∫e, tanh, q̇, q̈ (at k − δ), τ (at k − δ), the extra ones (at k − δ);
  // then each filtered by the same moving average within its segment (a linear filter keeps the
  // balance exact).
  std::vector<std::vector<double>> signal(6 + extra.size(), std::vector<double>(n, 0.0));
  for (const auto& x : extra)
    if (x.size() != n) throw std::invalid_argument("friction balance: extra signal's length");
  for (const auto& [begin, end] : pb.signals->segments) {
    double running = 0.0;
    for (std::size_t k = begin + pb.delay; k < std::min(end, n); ++k) {
      signal[0][k] = pb.error[k];
      signal[1][k] = running += pb.error[k] * options.cycle_s;
      for (int m = 0; m < kLevels; ++m) signal[std::size_t(2 + m)][k] = pb.x(m, k);
      signal[5][k] = pb.signals->model_torque_nm[k - pb.delay];
      for (std::size_t x = 0; x < extra.size(); ++x) signal[6 + x][k] = extra[x][k - pb.delay];
    }
  }
  const auto width = std::size_t(std::max(1, options.smoothing_samples));
  for (auto& x : signal) {
    std::vector<double> smooth(n, 0.0);
    for (const auto& [begin, end] : pb.signals->segments) {
      double window = 0.0;
      for (std::size_t k = begin + pb.delay; k < std::min(end, n); ++k) {
        window += x[k];
        if (k >= begin + pb.delay + width) window -= x[k - width];
        smooth[k] = window / double(width);
      }
    }
    x = std::move(smooth);
  }
  columns.resize(Eigen::Index(pb.rows.size()), lags + 2 + kLevels + Eigen::Index(extra.size()));
  target.resize(columns.rows());
  for (std::size_t row = 0; row < pb.rows.size(); ++row) {
    const std::size_t k = pb.rows[row];
    const auto i = Eigen::Index(row);
    for (int a = 0; a < lags; ++a) columns(i, a) = signal[0][k - std::size_t(a)];
    columns(i, sum) = signal[1][k];
    columns(i, one) = 1.0;
    for (int m = 0; m < kLevels; ++m) columns(i, level + m) = -signal[std::size_t(2 + m)][k];
    target(i) = signal[5][k];
    for (std::size_t x = 0; x < extra.size(); ++x)
      columns(i, level + kLevels + Eigen::Index(x)) = signal[6 + x][k];
  }
}

// The inverse of JᵀJ with the columns scaled to unit norm (the columns' units differ by many
// orders); empty when the matrix is numerically singular.
Eigen::MatrixXd normal_inverse(const Eigen::MatrixXd& jacobian) {
  const Eigen::VectorXd norms = jacobian.colwise().norm().transpose();
  if ((norms.array() <= 0.0).any()) return {};
  const Eigen::VectorXd scale = norms.cwiseInverse();
  const Eigen::MatrixXd scaled = jacobian * scale.asDiagonal();
  const Eigen::MatrixXd normal = scaled.transpose() * scaled;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(normal);
  if (eigen.eigenvalues().minCoeff() <= 1e-12 * eigen.eigenvalues().maxCoeff()) return {};
  const Eigen::MatrixXd inverse = eigen.eigenvectors() *
                                  eigen.eigenvalues().cwiseInverse().asDiagonal() *
                                  eigen.eigenvectors().transpose();
  return scale.asDiagonal() * inverse * scale.asDiagonal();
}

// 1 + 2 Σ ρ_k over the lags up to the first ρ_k <= 0 (at most 200 rows).
double correlation_factor(const Eigen::VectorXd& r) {
  const double variance = r.squaredNorm();
  if (variance <= 0.0) return 1.0;
  double factor = 1.0;
  for (Eigen::Index lag = 1; lag < std::min<Eigen::Index>(200, r.size()); ++lag) {
    const double rho = r.head(r.size() - lag).dot(r.tail(r.size() - lag)) / variance;
    if (rho <= 0.0) break;
    factor += 2.0 * rho;
  }
  return factor;
}

}  // namespace

namespace {

// The regression at one dead time: the levels' estimates, or not estimated with the reason.
JointFrictionLevels estimate_at(const JointFrictionSignals& signals,
                                const FrictionLevelOptions& options, int dead_time,
                                double& residual_norm) {
  const FrictionProblem pb = make_problem(signals, options, dead_time);
  JointFrictionLevels out;
  out.rows = pb.rows.size();
  out.dead_time_cycles = dead_time;
  const int parameters = pb.parameter_count();
  if (pb.rows.size() < std::size_t(20 * parameters)) {
    out.not_estimated = "too few samples in the record's segments";
    return out;
  }
  Eigen::MatrixXd columns;
  Eigen::VectorXd target;
  regression(pb, options, {}, columns, target);
  const Eigen::MatrixXd inverse = normal_inverse(columns);
  if (inverse.size() == 0) {
    out.not_estimated = "the joint's motion does not separate the friction levels";
    return out;
  }
  const Eigen::VectorXd p = inverse * (columns.transpose() * target);
  const Eigen::VectorXd r = target - columns * p;
  residual_norm = r.norm();
  out.correlation_factor = correlation_factor(r);
  const double residual_variance = r.squaredNorm() / double(r.size() - parameters);
  const Eigen::MatrixXd covariance = residual_variance * out.correlation_factor * inverse;
  FrictionLevel* levels[kLevels] = {&out.coulomb_nm, &out.viscous_nm_s_per_rad,
                                    &out.reflected_inertia_kg_m2};
  for (int m = 0; m < kLevels; ++m) {
    const Eigen::Index i = parameters - kLevels + m;
    levels[m]->value = p(i);
    levels[m]->sigma = std::sqrt(covariance(i, i));
  }
  const double spread = (target.array() - target.mean()).matrix().norm();
  out.torque_rms_nm = spread / std::sqrt(double(target.size()));
  out.torque_fit_percent = 100.0 * (1.0 - residual_norm / spread);
  out.estimated = true;
  return out;
}

}  // namespace

JointFrictionLevels estimate_friction_levels(const JointFrictionSignals& signals,
                                             const FrictionPrior& prior,
                                             const FrictionLevelOptions& options,
                                             int dead_time_cycles) {
  if (dead_time_cycles < 0)
    throw std::invalid_argument("friction levels: dead time must be >= 0 cycles");
  double norm = 0.0;
  JointFrictionLevels out = estimate_at(signals, options, dead_time_cycles, norm);
  out.coulomb_nm.nominal = prior.coulomb_nm;
  out.viscous_nm_s_per_rad.nominal = prior.viscous_nm_s_per_rad;
  out.reflected_inertia_kg_m2.nominal = prior.reflected_inertia_kg_m2;
  if (out.estimated && !(out.torque_rms_nm >= options.min_torque_to_coulomb * prior.coulomb_nm)) {
    out.estimated = false;
    out.not_estimated = "the model torque is too small against the friction to fix the scale";
  }
  return out;
}

FrictionBalanceRegression friction_balance_regression(
    const JointFrictionSignals& signals, const FrictionLevelOptions& options, int dead_time_cycles,
    std::span<const std::span<const double>> extra) {
  if (dead_time_cycles < 0)
    throw std::invalid_argument("friction balance: dead time must be >= 0 cycles");
  const FrictionProblem pb = make_problem(signals, options, dead_time_cycles);
  FrictionBalanceRegression out;
  out.drive_columns = pb.parameter_count();
  regression(pb, options, extra, out.columns, out.target);
  out.samples = pb.rows;
  return out;
}

}  // namespace imscal::ident
