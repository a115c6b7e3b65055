#include "ident/arx_fit.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/Householder>
#include <Eigen/QR>
#include <Eigen/SVD>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "ident/lagged_products.hpp"

namespace imscal::ident {
namespace {

using ConstMap = Eigen::Map<const Eigen::VectorXd>;

// Rows per block of the blocked passes: small enough that the block and its lagged copies stay
// in the L1/L2 cache, large enough that the dot products run at full vector speed.
constexpr std::size_t kChunkRows = 2048;
// Rows per block of the streamed QR (the block plus the running R are factored together).
constexpr int kQrBlockRows = 512;

void check_segment(const IoSegment& segment, int extra_inputs) {
  if (segment.input.size() != segment.output.size())
    throw std::invalid_argument("ARX data segment: input has " +
                                std::to_string(segment.input.size()) + " samples, output has " +
                                std::to_string(segment.output.size()));
  if (segment.extra_count < extra_inputs)
    throw std::invalid_argument("ARX data segment: " + std::to_string(segment.extra_count) +
                                " further inputs, the model needs " + std::to_string(extra_inputs));
  for (int e = 0; e < extra_inputs; ++e)
    if (segment.extra[static_cast<std::size_t>(e)].size() != segment.output.size())
      throw std::invalid_argument(
          "ARX data segment: further input " + std::to_string(e) + " has " +
          std::to_string(segment.extra[static_cast<std::size_t>(e)].size()) +
          " samples, output has " + std::to_string(segment.output.size()));
}

// One signal of a LaggedGram: its samples and its lag range [lag_min, lag_max], whose columns
// start at `column`.
struct LaggedSignal {
  const double* data = nullptr;
  int lag_min = 0, lag_max = 0, column = 0;
  int count() const { return lag_max - lag_min + 1; }
};

// The signals of a segment in LagSet column order: y, u, x_0, x_1, ...
std::vector<LaggedSignal> lagged_signals(const IoSegment& segment, const LagSet& lags) {
  std::vector<LaggedSignal> out{
      {segment.output.data(), 0, lags.output_lag_max, lags.output_column(0)},
      {segment.input.data(), lags.input_lag_min, lags.input_lag_max,
       lags.input_column(lags.input_lag_min)}};
  for (int e = 0; e < lags.extra_count; ++e)
    out.push_back({segment.extra[static_cast<std::size_t>(e)].data(), lags.input_lag_min,
                   lags.extra_lag_max[static_cast<std::size_t>(e)],
                   lags.extra_column(e, lags.input_lag_min)});
  return out;
}

// Adds one segment's contribution to `gram` (see build_lagged_gram). For every pair of signals
// (a, b), E(la, lb) = Σ_k a(k-la) b(k-lb): the entries with la or lb at its signal's smallest lag
// are dot products over the data (blocked, one pass); every other entry follows from its
// neighbour (la-1, lb-1) by the sliding update, which moves the summation window by one sample.
void add_segment_gram(const IoSegment& segment, const LagSet& lags, int first_row,
                      Eigen::MatrixXd& local, Eigen::MatrixXd& gram) {
  const std::size_t n = segment.output.size();
  const std::size_t f = static_cast<std::size_t>(first_row);
  const std::vector<LaggedSignal> signals = lagged_signals(segment, lags);
  local.setZero();
  // Upper-triangle entry of (signal a at lag la, signal b at lag lb).
  auto entry = [&](const LaggedSignal& a, int la, const LaggedSignal& b, int lb) -> double& {
    const int r = a.column + la - a.lag_min, c = b.column + lb - b.lag_min;
    return r <= c ? local(r, c) : local(c, r);
  };

  // Sums of the blocked pass: per pair (a, b), the row against b's lags, the column against
  // a's further lags (ident/lagged_products.hpp).
  std::vector<double> row_sums, column_sums;
  for (std::size_t c = f; c < n; c += kChunkRows) {
    const std::size_t len = std::min(kChunkRows, n - c);
    for (std::size_t ia = 0; ia < signals.size(); ++ia) {
      const LaggedSignal& a = signals[ia];
      for (std::size_t ib = ia; ib < signals.size(); ++ib) {
        const LaggedSignal& b = signals[ib];
        // Row la = a.lag_min against every lag of b, and column lb = b.lag_min against the
        // other lags of a (for a == b the first row covers the upper triangle's base).
        const double* a0 = a.data + c - a.lag_min;
        const double* b0 = b.data + c - b.lag_min;
        row_sums.assign(std::size_t(b.count()), 0.0);
        add_lagged_dots(a0, b0, len, b.count(), row_sums.data());
        for (int lb = b.lag_min; lb <= b.lag_max; ++lb)
          entry(a, a.lag_min, b, lb) += row_sums[std::size_t(lb - b.lag_min)];
        if (ia == ib || a.count() == 1) continue;
        column_sums.assign(std::size_t(a.count() - 1), 0.0);
        add_lagged_dots(b0, a0 - 1, len, a.count() - 1, column_sums.data());
        for (int la = a.lag_min + 1; la <= a.lag_max; ++la)
          entry(a, la, b, b.lag_min) += column_sums[std::size_t(la - a.lag_min - 1)];
      }
    }
  }

  for (std::size_t ia = 0; ia < signals.size(); ++ia) {
    const LaggedSignal& a = signals[ia];
    for (std::size_t ib = ia; ib < signals.size(); ++ib) {
      const LaggedSignal& b = signals[ib];
      for (int la = a.lag_min + 1; la <= a.lag_max; ++la) {
        for (int lb = (ia == ib ? la : b.lag_min + 1); lb <= b.lag_max; ++lb) {
          entry(a, la, b, lb) = entry(a, la - 1, b, lb - 1) + a.data[f - la] * b.data[f - lb] -
                                a.data[n - la] * b.data[n - lb];
        }
      }
    }
  }

  gram.triangularView<Eigen::Upper>() += local;  // only the upper triangle of local is filled
}

// Σ a[i] b[i] as 8 partial sums (entry i to sum i mod 8, the tail to the first sums) reduced
// by a fixed tree: independent chains that the compiler maps to SIMD registers of any width,
// with the same additions in the same order, so the same rounding, at every width.
[[gnu::always_inline]] inline double lane_dot(const double* a, const double* b, int n) {
  double sum[8] = {};
  int i = 0;
  for (; i + 8 <= n; i += 8)
    for (int l = 0; l < 8; ++l) sum[l] += a[i + l] * b[i + l];
  for (int l = 0; i < n; ++i, ++l) sum[l] += a[i] * b[i];
  return ((sum[0] + sum[4]) + (sum[2] + sum[6])) + ((sum[1] + sum[5]) + (sum[3] + sum[7]));
}

// Householder QR of [R; B] for R upper triangular (the top q rows of the column-major `stack`,
// leading dimension ld) and a block B of `rows` rows below it; R is overwritten by the new
// triangular factor, B by zeros. The reflector of column j is v = [e_j; v_B]: it touches row j
// of R and the block only (the rest of R is zero in that column), so each later column costs
// one dot product and one axpy over the block's rows, instead of a dense QR of the whole stack.
// Same reflectors as LAPACK's dlarfg (and Eigen's makeHouseholder).
[[gnu::always_inline]] inline void absorb_rows_body(double* stack, int ld, int q, int rows) {
  for (int j = 0; j < q; ++j) {
    double* v = stack + static_cast<std::ptrdiff_t>(j) * ld + q;
    const double tail = lane_dot(v, v, rows);
    if (tail == 0.0) continue;  // already triangular in this column: H = I
    double& r_jj = stack[static_cast<std::ptrdiff_t>(j) * ld + j];
    const double x0 = r_jj;
    const double norm = std::sqrt(x0 * x0 + tail);
    const double beta = x0 >= 0.0 ? -norm : norm;
    const double tau = (beta - x0) / beta;
    const double inverse = 1.0 / (x0 - beta);
    for (int i = 0; i < rows; ++i) v[i] *= inverse;  // block part of v (1 in row j of R)
    r_jj = beta;
    for (int c = j + 1; c < q; ++c) {
      double* column = stack + static_cast<std::ptrdiff_t>(c) * ld;
      const double w = tau * (column[j] + lane_dot(v, column + q, rows));
      column[j] -= w;
      for (int i = 0; i < rows; ++i) column[q + i] -= w * v[i];
    }
    for (int i = 0; i < rows; ++i) v[i] = 0.0;
  }
}

// The same code compiled for SSE2 (every x86-64) and for AVX, chosen on first use with the
// kernels' CPU check (ident/lagged_products.hpp): the AVX version halves the time of the QR
// (bench_identify), bitwise the same result.
void absorb_rows_sse2(double* stack, int ld, int q, int rows) {
  absorb_rows_body(stack, ld, q, rows);
}
__attribute__((target("avx"))) void absorb_rows_avx(double* stack, int ld, int q, int rows) {
  absorb_rows_body(stack, ld, q, rows);
}

void absorb_rows(Eigen::MatrixXd& stack, int q, int rows) {
  static const auto kernel = detail::cpu_has_avx() ? absorb_rows_avx : absorb_rows_sse2;
  kernel(stack.data(), static_cast<int>(stack.rows()), q, rows);
}

// Streamed Householder QR of the column-scaled [Φ y]: returns the (p+1)-square R factor.
Eigen::MatrixXd streamed_qr_factor(std::span<const IoSegment> segments,
                                   const ArxStructure& structure, const Eigen::VectorXd& scale,
                                   std::size_t first) {
  const int na = structure.na;
  const int nb = structure.nb;
  const int p = structure.parameter_count();
  const int q = p + 1;
  const std::size_t d = static_cast<std::size_t>(structure.dead_time);
  Eigen::MatrixXd stack = Eigen::MatrixXd::Zero(q + kQrBlockRows, q);
  int rows = 0;
  auto flush = [&]() {
    absorb_rows(stack, q, rows);
    rows = 0;
  };
  for (const IoSegment& segment : segments) {
    const auto& y = segment.output;
    const auto& u = segment.input;
    for (std::size_t k = first; k < y.size(); ++k) {
      auto row = stack.row(q + rows);
      for (int i = 0; i < na; ++i) row(i) = -y[k - 1 - i] * scale(i);
      for (int j = 0; j < nb; ++j) row(na + j) = u[k - d - j] * scale(na + j);
      for (int e = 0; e < structure.extra_inputs; ++e) {
        const auto& x = segment.extra[static_cast<std::size_t>(e)];
        const int c0 = na + nb + structure.extra_offset(e);
        for (int j = 0; j < structure.nx[std::size_t(e)]; ++j)
          row(c0 + j) = x[k - d - j] * scale(c0 + j);
      }
      row(p) = y[k];
      if (++rows == kQrBlockRows) flush();
    }
  }
  if (rows > 0) flush();
  return stack.topRows(q);
}

// One blocked pass over the data: the residual r(k) = y(k) - φ(k)ᵀθ of every regression row
// k >= first (>= structure.max_lag()) of every segment; returns Σ r² and, when wanted,
// accumulates Φᵀr (θ order) into *phi_t_r.
double residual_pass(std::span<const IoSegment> segments, const ArxStructure& structure,
                     const Eigen::VectorXd& theta, Eigen::VectorXd* phi_t_r, std::size_t first) {
  structure.validate();
  if (theta.size() != structure.parameter_count())
    throw std::invalid_argument("residual pass: θ size does not match the structure");
  const std::size_t d = static_cast<std::size_t>(structure.dead_time);
  const int na = structure.na;
  std::array<double, kChunkRows> residual_buffer;
  const int nb = structure.nb;
  std::vector<double> sums(std::size_t(std::max({na, nb, structure.max_nx()})));  // lagged dots
  if (phi_t_r != nullptr) phi_t_r->setZero(theta.size());
  double sum = 0.0;
  // The output regressors enter as -y: their FIR taps are -a.
  const Eigen::VectorXd minus_a = -theta.head(na);
  for (const IoSegment& segment : segments) {
    check_segment(segment, structure.extra_inputs);
    const double* y = segment.output.data();
    const double* u = segment.input.data();
    const std::size_t n = segment.output.size();
    for (std::size_t c = first; c < n; c += kChunkRows) {
      const std::size_t len = std::min(kChunkRows, n - c);
      double* e = residual_buffer.data();
      std::copy(y + c, y + c + len, e);
      if (na > 0) subtract_fir(y + c - 1, minus_a.data(), na, len, e);
      subtract_fir(u + c - d, theta.data() + na, nb, len, e);
      for (int x = 0; x < structure.extra_inputs; ++x) {
        const int c0 = na + nb + structure.extra_offset(x);
        subtract_fir(segment.extra[static_cast<std::size_t>(x)].data() + c - d, theta.data() + c0,
                     structure.nx[std::size_t(x)], len, e);
      }
      sum += ConstMap(e, static_cast<Eigen::Index>(len)).squaredNorm();
      if (phi_t_r == nullptr) continue;
      // Φᵀr: -Σ r(k) y(k-1-i), Σ r(k) u(k-d-j), Σ r(k) x_e(k-d-j).
      auto add_dots = [&](const double* signal, int count, int at, double sign) {
        std::fill(sums.begin(), sums.begin() + count, 0.0);
        add_lagged_dots(e, signal, len, count, sums.data());
        for (int j = 0; j < count; ++j) (*phi_t_r)(at + j) += sign * sums[std::size_t(j)];
      };
      if (na > 0) add_dots(y + c - 1, na, 0, -1.0);
      add_dots(u + c - d, nb, na, 1.0);
      for (int x = 0; x < structure.extra_inputs; ++x)
        add_dots(segment.extra[static_cast<std::size_t>(x)].data() + c - d,
                 structure.nx[std::size_t(x)], na + nb + structure.extra_offset(x), 1.0);
    }
  }
  return sum;
}

}  // namespace

const char* to_string(LeastSquaresMethod method) {
  switch (method) {
    case LeastSquaresMethod::kAuto:
      return "auto";
    case LeastSquaresMethod::kNormalEquations:
      return "normal";
    case LeastSquaresMethod::kQr:
      return "qr";
    case LeastSquaresMethod::kRefinedNormalEquations:
      return "refined-normal";
  }
  return "?";
}

LaggedGram build_lagged_gram(std::span<const IoSegment> segments, const LagSet& lags,
                             int first_row) {
  if (lags.output_lag_max < 0 || lags.input_lag_min < 0 ||
      lags.input_lag_max < lags.input_lag_min || lags.extra_count < 0 ||
      lags.extra_count > kMaxExtraInputs)
    throw std::invalid_argument("build_lagged_gram: invalid lag set");
  for (int e = 0; e < lags.extra_count; ++e)
    if (lags.extra_lag_max[std::size_t(e)] < lags.input_lag_min)
      throw std::invalid_argument("build_lagged_gram: invalid lag set (further input " +
                                  std::to_string(e) + ")");
  if (first_row < lags.max_lag())
    throw std::invalid_argument("build_lagged_gram: first_row " + std::to_string(first_row) +
                                " is below the largest lag " + std::to_string(lags.max_lag()));
  LaggedGram result;
  result.lags = lags;
  result.first_row = first_row;
  const int columns = lags.columns();
  result.gram = Eigen::MatrixXd::Zero(columns, columns);
  Eigen::MatrixXd local(columns, columns);
  for (const IoSegment& segment : segments) {
    check_segment(segment, lags.extra_count);
    if (segment.output.size() <= static_cast<std::size_t>(first_row)) continue;
    result.row_count += segment.output.size() - static_cast<std::size_t>(first_row);
    add_segment_gram(segment, lags, first_row, local, result.gram);
  }
  result.gram.triangularView<Eigen::StrictlyLower>() = result.gram.transpose();
  return result;
}

double residual_sum_of_squares(std::span<const IoSegment> segments, const ArxStructure& structure,
                               const Eigen::VectorXd& theta) {
  return residual_pass(segments, structure, theta, nullptr, std::size_t(structure.max_lag()));
}

ArxFitResult fit_arx(std::span<const IoSegment> segments, const ArxStructure& structure,
                     const ArxFitOptions& options) {
  structure.validate();
  LagSet lags{structure.na,
              structure.dead_time,
              structure.dead_time + structure.nb - 1,
              structure.extra_inputs,
              {}};
  for (int e = 0; e < structure.extra_inputs; ++e)
    lags.extra_lag_max[std::size_t(e)] = structure.dead_time + structure.nx[std::size_t(e)] - 1;
  return fit_arx(segments, structure, build_lagged_gram(segments, lags, structure.max_lag()),
                 options);
}

ArxFitResult fit_arx(std::span<const IoSegment> segments, const ArxStructure& structure,
                     const LaggedGram& lagged, const ArxFitOptions& options) {
  structure.validate();
  const int na = structure.na;
  const int nb = structure.nb;
  const int p = structure.parameter_count();
  const LagSet& lags = lagged.lags;
  {  // the Gram must hold every lag of the structure
    bool covers = lags.output_lag_max >= na && lags.input_lag_min <= structure.dead_time &&
                  lags.input_lag_max >= structure.dead_time + nb - 1 &&
                  lags.extra_count == structure.extra_inputs &&
                  lagged.first_row >= structure.max_lag();
    for (int e = 0; e < structure.extra_inputs; ++e)
      covers = covers && lags.extra_lag_max[std::size_t(e)] >=
                             structure.dead_time + structure.nx[std::size_t(e)] - 1;
    if (!covers)
      throw std::invalid_argument("fit_arx: the Gram matrix does not hold the lags of " +
                                  to_string(structure));
  }
  const std::size_t first = static_cast<std::size_t>(lagged.first_row);
  if (lagged.row_count <= static_cast<std::size_t>(p))
    throw std::invalid_argument("fit_arx: " + std::to_string(lagged.row_count) +
                                " regression rows for " + std::to_string(p) + " parameters (" +
                                to_string(structure) + ")");

  // ΦᵀΦ and Φᵀy in θ order; output regressors enter as -y, hence the signs.
  std::vector<int> column(p);
  Eigen::VectorXd sign(p);
  for (int i = 0; i < na; ++i) column[i] = lags.output_column(i + 1), sign(i) = -1.0;
  for (int j = 0; j < nb; ++j)
    column[na + j] = lags.input_column(structure.dead_time + j), sign(na + j) = 1.0;
  for (int e = 0; e < structure.extra_inputs; ++e)
    for (int j = 0; j < structure.nx[std::size_t(e)]; ++j) {
      const int r = na + nb + structure.extra_offset(e) + j;
      column[r] = lags.extra_column(e, structure.dead_time + j);
      sign(r) = 1.0;
    }
  Eigen::MatrixXd normal(p, p);
  Eigen::VectorXd rhs(p);
  for (int r = 0; r < p; ++r) {
    rhs(r) = sign(r) * lagged.gram(column[r], 0);
    for (int c = 0; c < p; ++c)
      normal(r, c) = sign(r) * sign(c) * lagged.gram(column[r], column[c]);
  }
  Eigen::VectorXd scale(p);
  for (int r = 0; r < p; ++r) {
    if (!(normal(r, r) > 0.0))
      throw std::runtime_error("fit_arx: regressor " + std::to_string(r) +
                               " is zero over all rows (no excitation)");
    scale(r) = 1.0 / std::sqrt(normal(r, r));
  }
  const Eigen::MatrixXd scaled = scale.asDiagonal() * normal * scale.asDiagonal();
  const Eigen::VectorXd scaled_rhs = scale.cwiseProduct(rhs);
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(scaled, Eigen::EigenvaluesOnly);
  const double lambda_min = eigen.eigenvalues().minCoeff();
  const double condition = lambda_min > 0.0 ? eigen.eigenvalues().maxCoeff() / lambda_min
                                            : std::numeric_limits<double>::infinity();

  LeastSquaresMethod method = options.method;
  if (method == LeastSquaresMethod::kAuto)
    method = condition <= options.max_condition_normal_equations
                 ? LeastSquaresMethod::kNormalEquations
             : condition <= options.max_condition_refined_normal_equations
                 ? LeastSquaresMethod::kRefinedNormalEquations
                 : LeastSquaresMethod::kQr;
  Eigen::VectorXd scaled_theta;
  Eigen::MatrixXd scaled_inverse;
  double reported_condition = condition;
  if (method != LeastSquaresMethod::kQr) {
    Eigen::LLT<Eigen::MatrixXd> llt(scaled);
    if (llt.info() == Eigen::Success) {
      scaled_theta = llt.solve(scaled_rhs);
      scaled_inverse = llt.solve(Eigen::MatrixXd::Identity(p, p));
    } else if (options.method == LeastSquaresMethod::kNormalEquations) {
      throw std::runtime_error("fit_arx: normal equations not positive definite (" +
                               to_string(structure) + ")");
    } else {
      method = LeastSquaresMethod::kQr;
    }
  }

  // One refinement step: θ += S (S ΦᵀΦ S)⁻¹ S Φᵀr, r from the data; returns the step's size
  // in the scaled basis. rss becomes the residual sum of squares of the new θ (header, 4.).
  Eigen::VectorXd theta, phi_t_r;
  int steps_taken = 0;
  double rss = std::numeric_limits<double>::quiet_NaN();
  auto refine = [&]() {
    const double rss_before = residual_pass(segments, structure, theta, &phi_t_r, first);
    const Eigen::VectorXd scaled_step = scaled_inverse * scale.cwiseProduct(phi_t_r);
    theta += scale.cwiseProduct(scaled_step);
    ++steps_taken;
    rss = std::max(0.0, rss_before - 2.0 * scaled_step.dot(scale.cwiseProduct(phi_t_r)) +
                            scaled_step.dot(scaled * scaled_step));
    return scaled_step.norm();
  };
  if (method == LeastSquaresMethod::kRefinedNormalEquations) {
    // Iterated to the rounding level of a backward-stable solver (arx_fit.hpp, step 3); a step
    // that does not halve the one before means κ ε is too large to contract: QR instead.
    theta = scale.cwiseProduct(scaled_theta);
    const double floor = 8.0 * std::sqrt(condition) * std::numeric_limits<double>::epsilon();
    double previous = std::numeric_limits<double>::infinity();
    bool converged = false;
    for (int i = 0; i < options.max_refinement_steps && !converged; ++i) {
      const double step = refine();
      converged = step <= floor * theta.cwiseQuotient(scale).norm();
      if (!converged && !(step <= 0.5 * previous)) break;
      previous = step;
    }
    if (!converged) method = LeastSquaresMethod::kQr;
  }
  if (method == LeastSquaresMethod::kQr) {
    steps_taken = 0;
    const Eigen::MatrixXd r_aug = streamed_qr_factor(segments, structure, scale, first);
    const auto r = r_aug.topLeftCorner(p, p).triangularView<Eigen::Upper>();
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(r_aug.topLeftCorner(p, p));
    const double s_min = svd.singularValues().minCoeff();
    if (!(s_min > 0.0))
      throw std::runtime_error("fit_arx: regressors are rank deficient (" + to_string(structure) +
                               ")");
    reported_condition = std::pow(svd.singularValues().maxCoeff() / s_min, 2);
    scaled_theta = r.solve(r_aug.topRightCorner(p, 1));
    const Eigen::MatrixXd r_inverse = r.solve(Eigen::MatrixXd::Identity(p, p));
    scaled_inverse = r_inverse * r_inverse.transpose();
  }
  // Iterative refinement with residuals computed from the data: the normal equations' error
  // (≈ condition × ε of yᵀy-sized sums) shrinks to that of Φᵀr, r being the small residual. On
  // the QR path the same step is the corrected semi-normal equations (R⁻¹R⁻ᵀ = scaled_inverse):
  // it removes the rounding of the streamed factorisation (an order-32 noise-free fit went from
  // 1.06e-9 relative error to the test's bound). A pass costs O(N p), the QR O(N p²).
  if (method != LeastSquaresMethod::kRefinedNormalEquations) {
    theta = scale.cwiseProduct(scaled_theta);
    for (int step = 0; step < options.refinement_steps; ++step) refine();
  }
  if (steps_taken == 0) rss = residual_pass(segments, structure, theta, nullptr, first);
  const double variance = rss / static_cast<double>(lagged.row_count - static_cast<std::size_t>(p));
  Eigen::MatrixXd covariance = variance * scale.asDiagonal() * scaled_inverse * scale.asDiagonal();
  Eigen::VectorXd std_dev = covariance.diagonal().cwiseMax(0.0).cwiseSqrt();
  return ArxFitResult{ArxModel(structure, theta.head(na), theta.segment(na, nb),
                               theta.tail(p - na - nb), options.sample_time_s),
                      std::move(std_dev),
                      std::move(covariance),
                      rss,
                      variance,
                      lagged.row_count,
                      reported_condition,
                      method,
                      steps_taken};
}

}  // namespace imscal::ident
