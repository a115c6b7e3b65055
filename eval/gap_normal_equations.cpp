#include "eval/gap_normal_equations.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>

namespace imscal::eval {
namespace {

// Up to this many columns the Gram matrix is summed as dot products of the columns' runs: a
// matrix product's packing costs more than it saves for so few.
constexpr Eigen::Index kDotProductColumns = 4;

}  // namespace

void add_augmented_gram(const Eigen::MatrixXd& x, const std::vector<double>& y,
                        const std::vector<Eigen::Index>& rows, Eigen::MatrixXd& a) {
  const Eigen::Index p = x.cols();
  auto xtx = a.topLeftCorner(p, p);
  for (std::size_t i = 0; i < rows.size();) {
    // A run of consecutive rows [begin, begin + length): contiguous in every column.
    std::size_t end = i + 1;
    while (end < rows.size() && rows[end] == rows[end - 1] + 1) ++end;
    const Eigen::Index begin = rows[i], length = Eigen::Index(end - i);
    const auto xb = x.middleRows(begin, length);
    const Eigen::Map<const Eigen::VectorXd> yb(y.data() + begin, length);
    if (p <= kDotProductColumns) {
      for (Eigen::Index c = 0; c < p; ++c) {
        for (Eigen::Index d = 0; d <= c; ++d) a(c, d) += xb.col(c).dot(xb.col(d));
        a(p, c) += yb.dot(xb.col(c));
      }
    } else {
      xtx.selfadjointView<Eigen::Lower>().rankUpdate(xb.transpose());
      a.row(p).head(p).noalias() += yb.transpose() * xb;
    }
    a(p, p) += yb.squaredNorm();
    i = end;
  }
}

Eigen::MatrixXd augmented_gram(const Eigen::MatrixXd& x, const std::vector<double>& y,
                               const std::vector<Eigen::Index>& rows) {
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(x.cols() + 1, x.cols() + 1);
  add_augmented_gram(x, y, rows, a);
  return a;
}

std::optional<GramSolution> solve_normal_equations(const Eigen::MatrixXd& a, bool with_inverse) {
  const Eigen::Index p = a.rows() - 1;
  GramSolution out;
  out.scale = a.diagonal().head(p).cwiseSqrt();
  if (p == 0 || !(out.scale.minCoeff() > 0.0)) return std::nullopt;
  const Eigen::VectorXd inverse_scale = out.scale.cwiseInverse();
  const Eigen::MatrixXd g = inverse_scale.asDiagonal() *
                            Eigen::MatrixXd(a.topLeftCorner(p, p).selfadjointView<Eigen::Lower>()) *
                            inverse_scale.asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(g, Eigen::EigenvaluesOnly);
  const Eigen::VectorXd& lambda = eigen.eigenvalues();  // ascending
  if (eigen.info() != Eigen::Success || !(lambda[0] * kMaxGramCondition >= lambda[p - 1]))
    return std::nullopt;
  const Eigen::LLT<Eigen::MatrixXd> llt(g);
  if (llt.info() != Eigen::Success) return std::nullopt;
  const Eigen::VectorXd b = inverse_scale.cwiseProduct(a.row(p).head(p).transpose());
  out.theta = llt.solve(b).cwiseProduct(inverse_scale);
  if (with_inverse) out.inverse_scaled_gram = llt.solve(Eigen::MatrixXd::Identity(p, p));
  return out;
}

double sse_of_gram(const Eigen::MatrixXd& a, const Eigen::VectorXd& theta) {
  const Eigen::Index p = theta.size();
  Eigen::VectorXd v(p + 1);
  v.head(p) = -theta;
  v[p] = 1.0;
  const double sse = v.dot(a.selfadjointView<Eigen::Lower>() * v);
  return std::max(sse, 0.0);
}

}  // namespace imscal::eval
