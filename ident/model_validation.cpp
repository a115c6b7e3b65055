#include "ident/model_validation.hpp"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace imscal::ident {
namespace {

using Segments = std::vector<std::span<const double>>;

// The segments of one signal with the pooled mean removed.
struct Centered {
  std::vector<Eigen::VectorXd> segments;
  std::size_t count = 0;
};

Centered centered(const Segments& segments) {
  Centered out;
  double sum = 0.0;
  for (const auto& s : segments) {
    for (double v : s) sum += v;
    out.count += s.size();
  }
  if (out.count == 0) throw std::invalid_argument("correlation test: no samples");
  const double mean = sum / static_cast<double>(out.count);
  for (const auto& s : segments)
    out.segments.push_back(
        Eigen::Map<const Eigen::VectorXd>(s.data(), static_cast<Eigen::Index>(s.size())).array() -
        mean);
  return out;
}

// R_ab(τ) = (1/N) Σ a(k) b(k-τ) over the pairs that lie inside one segment (a, b centred).
double lagged_covariance(const Centered& a, const Centered& b, int lag) {
  double sum = 0.0;
  const Eigen::Index shift = std::abs(lag);
  for (std::size_t s = 0; s < a.segments.size(); ++s) {
    const Eigen::Index n = a.segments[s].size();
    if (shift >= n) continue;
    // lag >= 0: a(k) b(k - lag); lag < 0: a(k - |lag|) b(k).
    sum += lag >= 0 ? a.segments[s].tail(n - shift).dot(b.segments[s].head(n - shift))
                    : a.segments[s].head(n - shift).dot(b.segments[s].tail(n - shift));
  }
  return sum / static_cast<double>(a.count);
}

// Smallest k with P(Binomial(lag_count, α) > k) < α: the count of lags outside a band of
// two-sided level α that a white residual exceeds with probability below α.
int allowed_outside(int lag_count, double alpha) {
  double cumulative = 0.0;
  double pmf = std::pow(1.0 - alpha, lag_count);  // P(X = 0)
  for (int k = 0; k <= lag_count; ++k) {
    cumulative += pmf;
    if (1.0 - cumulative < alpha) return k;
    pmf *= (lag_count - k) / double(k + 1) * alpha / (1.0 - alpha);
  }
  return lag_count;
}

// Two-sided normal quantile z with erfc(z/√2) = level (bisection; erfc is monotone).
double two_sided_quantile(double level) {
  double low = 0.0, high = 40.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (low + high);
    (std::erfc(mid / std::sqrt(2.0)) > level ? low : high) = mid;
  }
  return 0.5 * (low + high);
}

void finish(CorrelationTest& test, double band_z) {
  const double alpha = std::erfc(band_z / std::sqrt(2.0));
  const int lag_count = static_cast<int>(test.correlation.size());
  test.outside_count = 0;
  test.max_abs_correlation = 0.0;
  for (double c : test.correlation) {
    if (std::abs(c) > test.band) ++test.outside_count;
    test.max_abs_correlation = std::max(test.max_abs_correlation, std::abs(c));
  }
  test.allowed_outside = allowed_outside(lag_count, alpha);
  const double per_lag_level = 1.0 - std::pow(1.0 - alpha, 1.0 / lag_count);
  test.family_band = test.band / band_z * two_sided_quantile(per_lag_level);
  test.passed =
      test.outside_count <= test.allowed_outside && test.max_abs_correlation <= test.family_band;
}

void check_options(const ValidationOptions& options) {
  if (options.max_lag < 1) throw std::invalid_argument("ValidationOptions: max_lag must be >= 1");
  if (!(options.band_z > 0.0)) throw std::invalid_argument("ValidationOptions: band_z must be > 0");
}

}  // namespace

double fit_percent(std::span<const double> measured, std::span<const double> estimate) {
  if (measured.size() != estimate.size() || measured.size() < 2)
    throw std::invalid_argument("fit_percent: need two equally long series of >= 2 samples");
  double mean = 0.0;
  for (double v : measured) mean += v;
  mean /= static_cast<double>(measured.size());
  double error = 0.0, spread = 0.0;
  for (std::size_t k = 0; k < measured.size(); ++k) {
    error += (measured[k] - estimate[k]) * (measured[k] - estimate[k]);
    spread += (measured[k] - mean) * (measured[k] - mean);
  }
  if (!(spread > 0.0)) throw std::invalid_argument("fit_percent: measured series is constant");
  return 100.0 * (1.0 - std::sqrt(error / spread));
}

CorrelationTest residual_whiteness_test(const Segments& residuals,
                                        const ValidationOptions& options) {
  check_options(options);
  const Centered e = centered(residuals);
  const double r0 = lagged_covariance(e, e, 0);
  if (!(r0 > 0.0)) throw std::invalid_argument("residual_whiteness_test: zero residual");
  CorrelationTest test;
  for (int lag = 1; lag <= options.max_lag; ++lag) {
    test.lags.push_back(lag);
    test.correlation.push_back(lagged_covariance(e, e, lag) / r0);
  }
  const std::size_t count = e.count;
  test.band = options.band_z / std::sqrt(static_cast<double>(count));
  finish(test, options.band_z);
  return test;
}

CorrelationTest input_residual_test(const Segments& residuals, const Segments& inputs,
                                    const ValidationOptions& options) {
  check_options(options);
  if (residuals.size() != inputs.size())
    throw std::invalid_argument("input_residual_test: segment counts differ");
  for (std::size_t s = 0; s < residuals.size(); ++s)
    if (residuals[s].size() != inputs[s].size())
      throw std::invalid_argument("input_residual_test: segment " + std::to_string(s) +
                                  " sizes differ");
  const Centered e = centered(residuals), u = centered(inputs);
  const double re0 = lagged_covariance(e, e, 0);
  const double ru0 = lagged_covariance(u, u, 0);
  if (!(re0 > 0.0) || !(ru0 > 0.0))
    throw std::invalid_argument("input_residual_test: zero residual or constant input");
  CorrelationTest test;
  for (int lag = -options.max_lag; lag <= options.max_lag; ++lag) {
    test.lags.push_back(lag);
    test.correlation.push_back(lagged_covariance(e, u, lag) / std::sqrt(re0 * ru0));
  }
  // Σ_{k=-M..M} ρ_e(k) ρ_u(k), both even functions of k.
  double variance_factor = 1.0;
  for (int k = 1; k <= options.max_lag; ++k)
    variance_factor += 2.0 * lagged_covariance(e, e, k) / re0 * lagged_covariance(u, u, k) / ru0;
  const std::size_t count = e.count;
  test.band = options.band_z * std::sqrt(std::max(variance_factor, 0.0) / double(count));
  finish(test, options.band_z);
  return test;
}

ArxValidationReport validate_arx(const ArxModel& model, std::span<const IoSegment> segments,
                                 const ValidationOptions& options) {
  const std::size_t first = static_cast<std::size_t>(model.structure().max_lag());
  std::vector<std::vector<double>> residual_store;
  Segments residuals, inputs;
  std::vector<double> measured, one_step, simulated;
  std::vector<double> prediction, simulation;
  for (const IoSegment& segment : segments) {
    const std::size_t n = segment.output.size();
    if (segment.input.size() != n)
      throw std::invalid_argument("validate_arx: segment input and output sizes differ");
    if (n <= first) continue;
    prediction.resize(n);
    simulation.resize(n);
    model.predict_one_step(segment, prediction);
    model.simulate(segment, simulation);
    std::vector<double>& e = residual_store.emplace_back(n - first);
    for (std::size_t k = first; k < n; ++k) {
      e[k - first] = segment.output[k] - prediction[k];
      measured.push_back(segment.output[k]);
      one_step.push_back(prediction[k]);
      simulated.push_back(simulation[k]);
    }
    inputs.push_back(segment.input.subspan(first));
  }
  for (const auto& e : residual_store) residuals.emplace_back(e);
  if (measured.size() < 2) throw std::invalid_argument("validate_arx: too few samples");

  ArxValidationReport report;
  report.sample_count = measured.size();
  report.one_step_fit_percent = fit_percent(measured, one_step);
  report.simulation_fit_percent = fit_percent(measured, simulated);
  double sum_sq = 0.0;
  for (const auto& e : residual_store)
    for (double v : e) sum_sq += v * v;
  report.residual_rms = std::sqrt(sum_sq / static_cast<double>(measured.size()));
  report.residual_whiteness = residual_whiteness_test(residuals, options);
  report.input_residual = input_residual_test(residuals, inputs, options);
  return report;
}

}  // namespace imscal::ident
