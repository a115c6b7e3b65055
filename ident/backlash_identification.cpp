#include "ident/backlash_identification.hpp"

#include <fmt/format.h>

#include <Eigen/Core>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace imscal::ident {
namespace {

// Samples used for the lag search: the correlation of smooth velocities peaks sharply, and
// 2^18 samples (~9 min at 2 ms) pin it down; more would only cost time on long recordings.
constexpr std::size_t kLagSearchSamples = std::size_t{1} << 16;

double sign_of(double v) {
  return v > 0.0 ? 1.0 : -1.0;
}

// Signed central-difference velocity and acceleration of q inside one segment [begin, end).
void derivatives(std::span<const double> q, std::size_t begin, std::size_t end, double dt,
                 std::vector<double>& v, std::vector<double>& a) {
  for (std::size_t k = begin; k < end; ++k) {
    const std::size_t lo = k == begin ? k : k - 1;
    const std::size_t hi = k + 1 == end ? k : k + 1;
    v[k] = hi > lo ? (q[hi] - q[lo]) / (double(hi - lo) * dt) : 0.0;
    if (end - begin >= 3) {
      const std::size_t c = std::clamp(k, begin + 1, end - 2);
      a[k] = (q[c + 1] - 2.0 * q[c] + q[c - 1]) / (dt * dt);
    }
  }
}

}  // namespace

std::size_t joint_lag_samples(std::span<const double> q_desired, std::span<const double> q_measured,
                              SampleRanges segments, std::size_t max_lag) {
  if (q_desired.size() != q_measured.size())
    throw std::invalid_argument("joint_lag_samples: signal lengths differ");
  std::vector<double> best_sum(max_lag + 1, 0.0);
  double norm_d = 0.0, norm_m = 0.0;
  std::size_t used = 0;
  for (const auto& [begin, end] : segments) {
    if (used >= kLagSearchSamples) break;
    const std::size_t stop = std::min(end, begin + (kLagSearchSamples - used));
    used += stop - begin;
    if (stop - begin < max_lag + 2) continue;
    // Velocities as first differences (the common 1/T factor does not change the argmax).
    const std::size_t n = stop - begin - 1;
    Eigen::VectorXd vd(n), vm(n);
    for (std::size_t k = 0; k < n; ++k) {
      vd(Eigen::Index(k)) = q_desired[begin + k + 1] - q_desired[begin + k];
      vm(Eigen::Index(k)) = q_measured[begin + k + 1] - q_measured[begin + k];
    }
    norm_d += vd.squaredNorm();
    norm_m += vm.squaredNorm();
    for (std::size_t lag = 0; lag <= max_lag; ++lag) {
      const Eigen::Index len = Eigen::Index(n - lag);
      best_sum[lag] += vm.tail(len).dot(vd.head(len));  // Σ v_m(k) v_d(k - lag)
    }
  }
  if (!(norm_d > 0.0) || !(norm_m > 0.0)) return 0;
  return std::size_t(std::max_element(best_sum.begin(), best_sum.end()) - best_sum.begin());
}

std::vector<double> motion_direction(std::span<const double> q_desired, SampleRanges segments,
                                     double cycle_s, double min_speed, std::size_t lag) {
  std::vector<double> raw(q_desired.size(), 0.0), out(q_desired.size(), 0.0);
  std::vector<double> v(q_desired.size(), 0.0), a(q_desired.size(), 0.0);
  for (const auto& [begin, end] : segments) {
    derivatives(q_desired, begin, end, cycle_s, v, a);
    double held = 0.0;
    for (std::size_t k = begin; k < end; ++k) {
      if (std::abs(v[k]) > min_speed) held = sign_of(v[k]);
      raw[k] = held;
    }
    for (std::size_t k = begin; k < end; ++k) out[k] = k >= begin + lag ? raw[k - lag] : 0.0;
  }
  return out;
}

BacklashEstimate identify_backlash(std::span<const double> q_desired,
                                   std::span<const double> q_measured, SampleRanges segments,
                                   double cycle_s, const BacklashOptions& options) {
  if (q_desired.size() != q_measured.size())
    throw std::invalid_argument("identify_backlash: signal lengths differ");
  if (!(cycle_s > 0.0) || !(options.window_s > 0.0) || options.settle_s < 0.0)
    throw std::invalid_argument("identify_backlash: bad cycle, window or settle time");
  BacklashEstimate est;
  const auto max_lag = std::size_t(std::llround(options.max_lag_s / cycle_s));
  est.lag_samples = joint_lag_samples(q_desired, q_measured, segments, max_lag);
  const std::size_t lag = est.lag_samples;
  const auto window =
      std::max<std::size_t>(4, std::size_t(std::llround(options.window_s / cycle_s)));
  const auto settle = std::size_t(std::llround(options.settle_s / cycle_s));

  const std::size_t n = q_desired.size();
  std::vector<double> v(n, 0.0), acc(n, 0.0);
  const std::vector<double> s =
      motion_direction(q_desired, segments, cycle_s, options.min_speed_rad_s, lag);
  Eigen::MatrixXd rows(2 * window, 4);
  Eigen::VectorXd target(2 * window);
  for (const auto& [begin, end] : segments) {
    derivatives(q_desired, begin, end, cycle_s, v, acc);
    // Reversals in the lagged direction: s changes between +1 and -1 at sample r (first sample
    // of the new direction); r_end: the last sample of the old direction.
    for (std::size_t r = begin + 1; r < end; ++r) {
      if (!(s[r] != 0.0 && s[r - 1] != 0.0 && s[r] != s[r - 1])) continue;
      ++est.reversals_found;
      if (r < begin + window) continue;
      const std::size_t before_first = r - window;
      const std::size_t after_first = r + settle;
      if (after_first + window > end) continue;
      bool clean = true;  // no other reversal inside either window
      for (std::size_t k = before_first; k < r && clean; ++k) clean = s[k] == s[r - 1];
      for (std::size_t k = r; k < after_first + window && clean; ++k) clean = s[k] == s[r];
      if (!clean) continue;
      for (std::size_t i = 0; i < 2 * window; ++i) {
        const std::size_t k = i < window ? before_first + i : after_first + (i - window);
        rows.row(Eigen::Index(i)) << 1.0, v[k], acc[k], s[k];
        target(Eigen::Index(i)) = q_desired[k] - q_measured[k];
      }
      // Column scaling, then a rank-revealing solve: [1, q̇, q̈] may be dependent (constant
      // acceleration), the coefficient of s stays determined as long as s is not in their span.
      Eigen::Vector4d scale;
      for (int c = 0; c < 4; ++c) {
        const double norm = rows.col(c).norm();
        scale(c) = norm > 0.0 ? 1.0 / norm : 0.0;
      }
      const Eigen::MatrixXd scaled = rows * scale.asDiagonal();
      // How much of s is independent of [1, q̇, q̈]: the residual of s projected on them.
      const Eigen::MatrixXd others = scaled.leftCols(3);
      const Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod_others(others);
      const Eigen::VectorXd s_col = scaled.col(3);
      const double s_norm = s_col.norm();
      const double independence =
          s_norm > 0.0 ? (s_col - others * cod_others.solve(s_col)).norm() / s_norm : 0.0;
      if (!(independence >= options.min_direction_independence)) {
        ++est.reversals_ill_conditioned;
        continue;
      }
      const Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod(scaled);
      const Eigen::VectorXd coefficients = scale.cwiseProduct(cod.solve(target));
      if (!std::isfinite(coefficients(3))) continue;
      if (std::abs(coefficients(3)) > options.max_l_rad) {
        ++est.reversals_implausible;
        continue;
      }
      est.per_reversal_rad.push_back(coefficients(3));
    }
  }
  est.reversals_used = int(est.per_reversal_rad.size());
  if (est.reversals_used < std::max(2, options.min_reversals)) {
    est.reason = fmt::format(
        "{} usable direction reversals (of {} found; {} skipped as not determining l, {} with "
        "|l_r| > {:.3g} rad), need {}: no backlash identified (l = 0)",
        est.reversals_used, est.reversals_found, est.reversals_ill_conditioned,
        est.reversals_implausible, options.max_l_rad, std::max(2, options.min_reversals));
    est.l_rad = 0.0;
    return est;
  }
  double mean = 0.0;
  for (double l : est.per_reversal_rad) mean += l;
  mean /= est.reversals_used;
  double var = 0.0;
  for (double l : est.per_reversal_rad) var += (l - mean) * (l - mean);
  var /= est.reversals_used - 1;
  est.l_sigma_rad = std::sqrt(var / est.reversals_used);
  est.identified = true;  // |l| <= max_l_rad: a mean of values that each are
  est.l_rad = mean;
  return est;
}

}  // namespace imscal::ident
