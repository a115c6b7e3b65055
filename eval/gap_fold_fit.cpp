#include "eval/gap_fold_fit.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>

#include "eval/gap_normal_equations.hpp"

namespace imscal::eval {
namespace {

// The scaled normal equations g theta_s = b of the augmented Gram matrix `a` (lower triangle),
// theta = theta_s / scale.
struct ScaledProblem {
  Eigen::MatrixXd g;
  Eigen::VectorXd b, inverse_scale;
};
ScaledProblem scaled(const Eigen::MatrixXd& a, const Eigen::VectorXd& scale) {
  const Eigen::Index p = a.rows() - 1;
  ScaledProblem out;
  out.inverse_scale = Eigen::VectorXd::Zero(p);
  for (Eigen::Index c = 0; c < p; ++c)
    if (scale[c] > 0.0) out.inverse_scale[c] = 1.0 / scale[c];
  out.g = out.inverse_scale.asDiagonal() *
          Eigen::MatrixXd(a.topLeftCorner(p, p).selfadjointView<Eigen::Lower>()) *
          out.inverse_scale.asDiagonal();
  out.b = out.inverse_scale.cwiseProduct(a.row(p).head(p).transpose());
  return out;
}

// The pseudo-inverse of the symmetric g over its eigen-directions with an eigenvalue above
// `min_relative` of the largest (and above 0); nothing kept when g is zero.
Eigen::MatrixXd truncated_inverse(const Eigen::MatrixXd& g, double min_relative) {
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(g);
  const Eigen::Index p = g.rows();
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(p, p);
  if (eigen.info() != Eigen::Success || p == 0) return out;
  const Eigen::VectorXd& lambda = eigen.eigenvalues();  // ascending
  const double cut = min_relative * lambda[p - 1];
  for (Eigen::Index k = 0; k < p; ++k)
    if (lambda[k] > cut && lambda[k] > 0.0) {
      const auto v = eigen.eigenvectors().col(k);
      out.noalias() += (v / lambda[k]) * v.transpose();
    }
  return out;
}

// theta = P b within the bound (scaled weights w / scale), unscaled.
Eigen::VectorXd bounded_solution(const ScaledProblem& sp, const Eigen::MatrixXd& pinv,
                                 const FoldBound& bound) {
  Eigen::VectorXd theta_s = pinv * sp.b;
  if (bound.weights.size() == theta_s.size()) {
    const Eigen::VectorXd w = bound.weights.cwiseProduct(sp.inverse_scale);
    const double level = w.dot(theta_s), violation = bound.lower - level;
    // Tolerance: rounding of the level (as eval/gap_bounds.cpp).
    if (violation > 1e-9 * (std::abs(bound.lower) + std::abs(level))) {
      const Eigen::VectorXd d = pinv * w;
      const double curvature = w.dot(d);
      if (curvature > 0.0) theta_s += d * (violation / curvature);
    }
  }
  return theta_s.cwiseProduct(sp.inverse_scale);
}

}  // namespace

Eigen::VectorXd truncated_fit(const Eigen::MatrixXd& fit, const Eigen::VectorXd& scale,
                              const FoldBound& bound) {
  const ScaledProblem sp = scaled(fit, scale);
  return bounded_solution(sp, truncated_inverse(sp.g, 1.0 / kMaxGramCondition), bound);
}

double folds_validation_sse(const std::vector<Eigen::MatrixXd>& grams,
                            const std::vector<FoldBound>& bounds) {
  if (grams.empty()) return 0.0;
  Eigen::MatrixXd total = Eigen::MatrixXd::Zero(grams[0].rows(), grams[0].cols());
  for (const Eigen::MatrixXd& a : grams) total += a;
  const Eigen::Index p = total.rows() - 1;
  const Eigen::VectorXd scale = total.diagonal().head(p).cwiseMax(0.0).cwiseSqrt();
  static const FoldBound none;
  double sse = 0.0;
  for (std::size_t i = 0; i < grams.size(); ++i) {
    Eigen::MatrixXd fit = Eigen::MatrixXd::Zero(total.rows(), total.cols());
    for (std::size_t j = 0; j < grams.size(); ++j)
      if (j != i) fit += grams[j];
    const FoldBound& bound = i < bounds.size() ? bounds[i] : none;
    sse += sse_of_gram(grams[i], truncated_fit(fit, scale, bound));
  }
  return sse;
}

std::vector<FoldBound> fold_bounds(const std::vector<Eigen::VectorXd>& cross,
                                   const std::vector<double>& uu, double lower) {
  std::vector<FoldBound> out(cross.size());
  for (std::size_t i = 0; i < cross.size(); ++i) {
    Eigen::VectorXd c = Eigen::VectorXd::Zero(cross[i].size());
    double u = 0.0;
    for (std::size_t j = 0; j < cross.size(); ++j)
      if (j != i) c += cross[j], u += uu[j];
    if (u > 0.0) out[i] = {c / u, lower};
  }
  return out;
}

}  // namespace imscal::eval
