#include "ident/order_selection.hpp"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace imscal::ident {
namespace {

std::string taps_text(const OrderGrid& g) {
  std::string text;
  for (const int n : g.extra_taps) text += (text.empty() ? "" : ",") + std::to_string(n);
  return text;
}

void validate_grid(const OrderGrid& g) {
  if (g.na_min < 0 || g.na_max < g.na_min || g.nb_min < 1 || g.nb_max < g.nb_min ||
      g.dead_time_min < 0 || g.dead_time_max < g.dead_time_min ||
      std::any_of(g.extra_taps.begin(), g.extra_taps.end(), [](int n) { return n < 1; }))
    throw std::invalid_argument(
        "select_arx_order: invalid grid (na " + std::to_string(g.na_min) + ".." +
        std::to_string(g.na_max) + ", nb " + std::to_string(g.nb_min) + ".." +
        std::to_string(g.nb_max) + ", d " + std::to_string(g.dead_time_min) + ".." +
        std::to_string(g.dead_time_max) + ", further inputs' taps " + taps_text(g) +
        "; every tap count >= 1, also for the unused inputs)");
}

// Relative floor of the Gram-derived RSS: yᵀy - ‖z‖² loses digits to cancellation at about this
// level, so smaller values (noise-free data) are not told apart.
constexpr double kRssFloorRelative = 1e-14;

double criterion_value(const OrderCandidate& c, OrderCriterion criterion) {
  switch (criterion) {
    case OrderCriterion::kAic:
      return c.aic;
    case OrderCriterion::kBic:
      return c.bic;
    case OrderCriterion::kValidation:
      return c.validation_loss;
  }
  return c.bic;
}

}  // namespace

const char* to_string(OrderCriterion criterion) {
  switch (criterion) {
    case OrderCriterion::kAic:
      return "aic";
    case OrderCriterion::kBic:
      return "bic";
    case OrderCriterion::kValidation:
      return "validation";
  }
  return "?";
}

OrderSweepResult sweep_arx_orders(std::span<const IoSegment> segments,
                                  const OrderSelectionOptions& options,
                                  std::span<const IoSegment> validation,
                                  LaggedGram* estimation_gram) {
  const OrderGrid& grid = options.grid;
  validate_grid(grid);
  if (!(options.validation_fraction >= 0.0 && options.validation_fraction < 1.0))
    throw std::invalid_argument("select_arx_order: validation_fraction must be in [0, 1)");

  // Estimation and validation segments.
  std::vector<IoSegment> estimation;
  std::vector<IoSegment> held_out(validation.begin(), validation.end());
  for (const IoSegment& s : segments) {
    if (s.input.size() != s.output.size())
      throw std::invalid_argument("select_arx_order: segment input and output sizes differ");
    if (!validation.empty() || options.validation_fraction == 0.0) {
      estimation.push_back(s);
      continue;
    }
    const std::size_t n = s.output.size();
    const std::size_t cut =
        n - static_cast<std::size_t>(std::llround(options.validation_fraction * double(n)));
    estimation.push_back(s.subspan(0, cut));
    held_out.push_back(s.subspan(cut));
  }
  // Further inputs: as many as the data carry (the same in every segment).
  const int extras = segments.empty() ? 0 : segments.front().extra_count;
  for (const IoSegment& s : segments)
    if (s.extra_count != extras)
      throw std::invalid_argument("select_arx_order: segments carry different further inputs");
  // The further inputs' coefficients (OrderGrid::extra_taps, fixed), in every candidate.
  std::array<int, kMaxExtraInputs> nx{};
  int fixed = 0;
  LagSet lags{grid.na_max, grid.dead_time_min, grid.dead_time_max + grid.nb_max - 1, extras, {}};
  for (int e = 0; e < extras; ++e) {
    nx[std::size_t(e)] = grid.extra_taps[std::size_t(e)];
    fixed += nx[std::size_t(e)];
    lags.extra_lag_max[std::size_t(e)] = grid.dead_time_max + nx[std::size_t(e)] - 1;
  }
  const int first_row = lags.max_lag();
  LaggedGram est = build_lagged_gram(estimation, lags, first_row);
  const LaggedGram val = build_lagged_gram(held_out, lags, first_row);
  const std::size_t n_rows = est.row_count;
  const int q_max = fixed + grid.nb_max + grid.na_max;
  if (n_rows <= static_cast<std::size_t>(q_max) + 1)
    throw std::invalid_argument("select_arx_order: " + std::to_string(n_rows) +
                                " estimation rows for up to " + std::to_string(q_max) +
                                " parameters");
  const bool has_validation = val.row_count > 0;
  if (options.criterion == OrderCriterion::kValidation && !has_validation)
    throw std::invalid_argument("select_arx_order: validation criterion without validation data");

  const double n = static_cast<double>(n_rows);
  const double yy = est.gram(0, 0);
  const double rss_floor = kRssFloorRelative * yy;
  const double nan = std::numeric_limits<double>::quiet_NaN();

  std::vector<OrderCandidate> candidates;
  candidates.reserve(static_cast<std::size_t>(grid.dead_time_max - grid.dead_time_min + 1) *
                     (grid.nb_max - grid.nb_min + 1) * (grid.na_max - grid.na_min + 1));
  // Work space, reused for every (d, nb).
  std::vector<int> column(q_max);
  Eigen::VectorXd scale(q_max), rhs(q_max), z(q_max), theta(q_max), val_rhs(q_max);
  // Row-major: the left-looking Cholesky below takes dot products of the factor's rows.
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> factor(q_max, q_max);
  Eigen::MatrixXd val_gram(q_max, q_max);

  for (int d = grid.dead_time_min; d <= grid.dead_time_max; ++d) {
    // The columns are the further inputs' and the input's lags first, then the output's: the
    // leading fixed + nb - 1 rows of nb's factor (and of z) are those of nb - 1's, so each nb
    // factors only its last input column and the output block (bitwise the same rows: the same
    // entries, the same sums).
    int reused = 0;       // leading rows of the factor (and of z) valid from the last nb
    int prefix_rank = 0;  // rank of the last nb's factor, where it stopped short of its prefix
    for (int nb = grid.nb_min; nb <= grid.nb_max; ++nb) {
      const int q = fixed + nb + grid.na_max;
      for (int e = 0, r = 0; e < extras; ++e)
        for (int j = 0; j < nx[std::size_t(e)]; ++j) column[r++] = lags.extra_column(e, d + j);
      for (int j = 0; j < nb; ++j) column[fixed + j] = lags.input_column(d + j);
      for (int i = 1; i <= grid.na_max; ++i) column[fixed + nb + i - 1] = lags.output_column(i);
      for (int r = 0; r < q; ++r) {
        const double diag = est.gram(column[r], column[r]);
        scale(r) = diag > 0.0 ? 1.0 / std::sqrt(diag) : 0.0;
        rhs(r) = scale(r) * est.gram(column[r], 0);
      }
      // Left-looking Cholesky of the scaled block, with the forward substitution z = L⁻¹ rhs
      // carried along; stops at the first pivot that shows numerical dependence.
      int rank = q;
      if (prefix_rank < reused) rank = prefix_rank;  // the shared prefix is already dependent
      // Rows past the reused prefix against the prefix's columns.
      for (int j = 0; j < std::min(reused, rank); ++j) {
        const double l_jj = factor(j, j);
        for (int i = reused; i < q; ++i) {
          const double a_ij = scale(i) * scale(j) * est.gram(column[i], column[j]);
          factor(i, j) = (a_ij - factor.row(i).head(j).dot(factor.row(j).head(j))) / l_jj;
        }
      }
      for (int j = reused; j < rank; ++j) {
        const double a_jj = scale(j) * scale(j) * est.gram(column[j], column[j]);
        const double pivot = a_jj - factor.row(j).head(j).squaredNorm();
        if (!(pivot > options.min_relative_pivot)) {
          rank = j;
          break;
        }
        const double l_jj = std::sqrt(pivot);
        factor(j, j) = l_jj;
        for (int i = j + 1; i < q; ++i) {
          const double a_ij = scale(i) * scale(j) * est.gram(column[i], column[j]);
          factor(i, j) = (a_ij - factor.row(i).head(j).dot(factor.row(j).head(j))) / l_jj;
        }
        z(j) = (rhs(j) - factor.row(j).head(j).dot(z.head(j))) / l_jj;
      }
      reused = fixed + nb;  // the next nb shares the columns up to this nb's last input lag
      prefix_rank = rank;
      if (has_validation) {
        for (int r = 0; r < q; ++r) {
          val_rhs(r) = val.gram(column[r], 0);
          for (int c = 0; c < q; ++c) val_gram(r, c) = val.gram(column[r], column[c]);
        }
      }

      double explained = z.head(std::min(fixed + nb + grid.na_min, rank)).squaredNorm();
      for (int na = grid.na_min; na <= grid.na_max; ++na) {
        const int p = fixed + nb + na;
        if (na > grid.na_min && p <= rank) explained += z(p - 1) * z(p - 1);
        OrderCandidate c;
        c.structure = {na, nb, d, extras, nx};
        c.valid = p <= rank;
        c.validation_loss = nan;
        if (!c.valid) {
          c.loss = c.aic = c.bic = nan;
          candidates.push_back(c);
          continue;
        }
        const double rss = std::max(yy - explained, rss_floor);
        c.loss = rss / n;
        c.aic = n * std::log(c.loss) + 2.0 * p;
        c.bic = n * std::log(c.loss) + p * std::log(n);
        if (has_validation) {
          // θ in the raw (unscaled, +y lag) basis of the Gram matrices: Lᵀ θs = z, θ = S θs.
          auto t = theta.head(p);
          t = factor.topLeftCorner(p, p).transpose().triangularView<Eigen::Upper>().solve(
              z.head(p));
          t = t.cwiseProduct(scale.head(p));
          const double sse = val.gram(0, 0) - 2.0 * t.dot(val_rhs.head(p)) +
                             t.dot(val_gram.topLeftCorner(p, p) * t);
          c.validation_loss = std::max(sse, 0.0) / static_cast<double>(val.row_count);
        }
        candidates.push_back(c);
      }
    }
  }

  const OrderCandidate* best = nullptr;
  for (const OrderCandidate& c : candidates) {
    if (!c.valid) continue;
    if (best == nullptr ||
        criterion_value(c, options.criterion) < criterion_value(*best, options.criterion))
      best = &c;
  }
  if (best == nullptr)
    throw std::runtime_error("select_arx_order: every candidate is rank deficient");
  const ArxStructure chosen = best->structure;
  if (estimation_gram != nullptr) *estimation_gram = std::move(est);
  return OrderSweepResult{chosen, options.criterion, std::move(candidates), n_rows, val.row_count};
}

OrderSelectionResult select_arx_order(std::span<const IoSegment> segments,
                                      const OrderSelectionOptions& options,
                                      std::span<const IoSegment> validation) {
  OrderSweepResult sweep = sweep_arx_orders(segments, options, validation);
  std::vector<IoSegment> all(segments.begin(), segments.end());
  all.insert(all.end(), validation.begin(), validation.end());
  ArxFitResult final_fit = fit_arx(all, sweep.chosen, options.final_fit);
  return OrderSelectionResult{
      sweep.chosen,          sweep.criterion,       std::move(sweep.candidates),
      sweep.estimation_rows, sweep.validation_rows, std::move(final_fit)};
}

}  // namespace imscal::ident
