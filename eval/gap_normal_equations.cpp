#include "eval/gap_normal_equations.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>

namespace imscal::eval {
namespace {

// Up to this many columns the Gram matrix is summed as dot products of the columns' runs: a
// matrix product's packing costs more than it saves for so few.
constexpr Eigen::Index kDotProductColumns = 4;

// From this many columns on, the columns that are zero on every sample (the other joints' blocks
// of a fit stacked over joints, eval/gap_joint_stack.hpp) are left out of the products: their
// Gram entries stay as they are. Fewer columns: checking them costs about what it saves.
constexpr Eigen::Index kSkipZeroColumnsFrom = 8;

// The columns of x with a value other than 0 (NaN counts).
std::vector<Eigen::Index> nonzero_columns(const Eigen::MatrixXd& x) {
  std::vector<Eigen::Index> cols;
  for (Eigen::Index c = 0; c < x.cols(); ++c)
    for (Eigen::Index k = 0; k < x.rows(); ++k)
      if (x(k, c) != 0.0) {
        cols.push_back(c);
        break;
      }
  return cols;
}

void add_gram_of_runs(const Eigen::MatrixXd& x, const std::vector<double>& y,
                      const std::vector<Eigen::Index>& rows, Eigen::MatrixXd& a);

// add_augmented_gram of the columns `cols` of x only (ascending): their rows gathered into one
// run, its Gram matrix added at their places in `a`.
void add_gram_of_columns(const Eigen::MatrixXd& x, const std::vector<double>& y,
                         const std::vector<Eigen::Index>& rows,
                         const std::vector<Eigen::Index>& cols, Eigen::MatrixXd& a) {
  const Eigen::Index p = x.cols(), k = Eigen::Index(cols.size());
  const Eigen::MatrixXd gathered = x(rows, cols);
  std::vector<double> y_gathered(rows.size());
  std::vector<Eigen::Index> all(rows.size());
  for (std::size_t i = 0; i < rows.size(); ++i)
    y_gathered[i] = y[std::size_t(rows[i])], all[i] = Eigen::Index(i);
  Eigen::MatrixXd g = Eigen::MatrixXd::Zero(k + 1, k + 1);
  add_gram_of_runs(gathered, y_gathered, all, g);
  for (Eigen::Index c = 0; c < k; ++c) {
    for (Eigen::Index d = 0; d <= c; ++d) a(cols[std::size_t(c)], cols[std::size_t(d)]) += g(c, d);
    a(p, cols[std::size_t(c)]) += g(k, c);
  }
  a(p, p) += g(k, k);
}

// add_augmented_gram over every column of x, run of consecutive rows by run.
void add_gram_of_runs(const Eigen::MatrixXd& x, const std::vector<double>& y,
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

}  // namespace

void add_augmented_gram(const Eigen::MatrixXd& x, const std::vector<double>& y,
                        const std::vector<Eigen::Index>& rows, Eigen::MatrixXd& a) {
  if (x.cols() >= kSkipZeroColumnsFrom) {
    const std::vector<Eigen::Index> cols = nonzero_columns(x);
    if (Eigen::Index(cols.size()) < x.cols()) return add_gram_of_columns(x, y, rows, cols, a);
  }
  add_gram_of_runs(x, y, rows, a);
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
