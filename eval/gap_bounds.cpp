#include "eval/gap_bounds.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace imscal::eval {
namespace {

// The level's weights w (level = w^T theta) over all parameters of `columns`.
Eigen::VectorXd level_weights(const std::vector<Eigen::MatrixXd>& columns, const LevelBound& b,
                              const std::vector<bool>& use) {
  Eigen::Index p = 0;
  for (const auto& m : columns) p = std::max(p, m.cols());
  Eigen::VectorXd w = Eigen::VectorXd::Zero(p);
  const Eigen::MatrixXd& x = columns[b.joint];
  if (x.size() == 0) return w;
  double uu = 0.0;
  for (Eigen::Index k = 0; k < x.rows(); ++k) {
    if (!use[std::size_t(k)]) continue;
    uu += b.signal[k] * b.signal[k];
    w.segment(b.first, b.count) += b.signal[k] * x.row(k).segment(b.first, b.count).transpose();
  }
  return uu > 0.0 ? Eigen::VectorXd(w / uu) : Eigen::VectorXd(Eigen::VectorXd::Zero(p));
}

// X^T X and X^T y over the stacked rows `use` of the joints with columns.
void normal_equations(const std::vector<Eigen::MatrixXd>& columns,
                      const std::vector<std::vector<double>>& gap, const std::vector<bool>& use,
                      Eigen::Index p, Eigen::MatrixXd& xtx, Eigen::VectorXd& xty, double& yy) {
  xtx = Eigen::MatrixXd::Zero(p, p);
  xty = Eigen::VectorXd::Zero(p);
  yy = 0.0;
  for (std::size_t j = 0; j < columns.size(); ++j) {
    const Eigen::MatrixXd& x = columns[j];
    if (x.size() == 0) continue;
    Eigen::Index m = 0;
    for (bool u : use) m += u;
    Eigen::MatrixXd xs(m, p);
    Eigen::VectorXd ys(m);
    Eigen::Index i = 0;
    for (Eigen::Index k = 0; k < x.rows(); ++k)
      if (use[std::size_t(k)]) xs.row(i) = x.row(k), ys[i++] = gap[j][std::size_t(k)];
    xtx.noalias() += xs.transpose() * xs;
    xty.noalias() += xs.transpose() * ys;
    yy += ys.squaredNorm();
  }
}

}  // namespace

double bound_level(const std::vector<Eigen::MatrixXd>& columns, const LevelBound& bound,
                   const Eigen::VectorXd& parameters, const std::vector<bool>& use) {
  return level_weights(columns, bound, use).dot(parameters);
}

bool apply_level_bounds(const std::vector<Eigen::MatrixXd>& columns,
                        const std::vector<std::vector<double>>& gap, const std::vector<bool>& use,
                        const std::vector<LevelBound>& bounds, LinearFit& fit) {
  std::vector<Eigen::VectorXd> w;
  for (const LevelBound& b : bounds) w.push_back(level_weights(columns, b, use));
  const auto violation = [&](std::size_t i, const Eigen::VectorXd& theta) {
    return bounds[i].lower - w[i].dot(theta);
  };
  // Tolerance of a bound: 1e-9 of the level's size (rounding of the constrained solution).
  const auto broken = [&](std::size_t i, const Eigen::VectorXd& theta) {
    return violation(i, theta) > 1e-9 * (std::abs(bounds[i].lower) + std::abs(w[i].dot(theta)));
  };
  std::vector<std::size_t> active;
  Eigen::VectorXd theta = fit.parameters;
  const Eigen::Index p = theta.size();
  Eigen::MatrixXd xtx, g;
  Eigen::VectorXd xty;
  double yy = 0.0;
  for (std::size_t it = 0; it < bounds.size(); ++it) {
    std::size_t worst = bounds.size();
    for (std::size_t i = 0; i < bounds.size(); ++i)
      if (std::find(active.begin(), active.end(), i) == active.end() && broken(i, theta) &&
          w[i].squaredNorm() > 0.0 &&
          (worst == bounds.size() || violation(i, theta) > violation(worst, theta)))
        worst = i;
    if (worst == bounds.size()) break;
    if (active.empty()) {
      normal_equations(columns, gap, use, p, xtx, xty, yy);
      // Column scaling for the pseudo-inverse (columns of very different sizes).
      const Eigen::VectorXd d = xtx.diagonal().cwiseMax(1e-300).cwiseSqrt().cwiseInverse();
      g = d.asDiagonal() *
          (d.asDiagonal() * xtx * d.asDiagonal())
              .completeOrthogonalDecomposition()
              .pseudoInverse() *
          d.asDiagonal();
    }
    active.push_back(worst);
    const Eigen::VectorXd theta_ls = g * xty;
    Eigen::MatrixXd a(Eigen::Index(active.size()), p);
    Eigen::VectorXd b(a.rows());
    for (std::size_t i = 0; i < active.size(); ++i) {
      a.row(Eigen::Index(i)) = w[active[i]].transpose();
      b[Eigen::Index(i)] = bounds[active[i]].lower;
    }
    const Eigen::MatrixXd aga = a * g * a.transpose();
    theta = theta_ls +
            g * a.transpose() * aga.completeOrthogonalDecomposition().solve(b - a * theta_ls);
    Eigen::Index m = 0;
    for (bool u : use) m += u;
    std::size_t joints = 0;
    for (const auto& c : columns) joints += c.size() > 0;
    const double sse = std::max(0.0, yy - 2.0 * theta.dot(xty) + theta.dot(xtx * theta));
    fit.rms = std::sqrt(sse / double(std::max<Eigen::Index>(m * Eigen::Index(joints), 1)));
  }
  fit.parameters = theta;
  return !active.empty();
}

}  // namespace imscal::eval
