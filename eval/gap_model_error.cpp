#include "eval/gap_model_error.hpp"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "eval/gap_candidates.hpp"

namespace imscal::eval {

namespace {

// cos / -sin of the taps' phases at f: Re G = c.b, Im G = s.b.
std::pair<Eigen::VectorXd, Eigen::VectorXd> phase_vectors(Eigen::Index n, double tap_period_s,
                                                          double frequency_hz) {
  Eigen::VectorXd c(n), s(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const double angle = 2.0 * M_PI * frequency_hz * double(i) * tap_period_s;
    c[i] = std::cos(angle);
    s[i] = -std::sin(angle);
  }
  return {c, s};
}

}  // namespace

double response_chi2(const Eigen::VectorXd& taps, const Eigen::MatrixXd& covariance,
                     double tap_period_s, double frequency_hz) {
  const auto [c, s] = phase_vectors(taps.size(), tap_period_s, frequency_hz);
  Eigen::Matrix2d cov2;
  cov2 << c.dot(covariance * c), c.dot(covariance * s), s.dot(covariance * c),
      s.dot(covariance * s);
  const Eigen::Vector2d z(c.dot(taps), s.dot(taps));
  // At f = 0 (or the Nyquist frequency) Im G is 0 by construction: a 1-dof test on Re G.
  if (cov2(1, 1) <= 1e-12 * cov2(0, 0)) return cov2(0, 0) > 0.0 ? z[0] * z[0] / cov2(0, 0) : 0.0;
  const double det = cov2.determinant();
  return det > 0.0 ? z.dot(cov2.inverse() * z) : 0.0;
}

FrequencyPoint fir_response(const Eigen::VectorXd& taps, const Eigen::MatrixXd& covariance,
                            double tap_period_s, double frequency_hz, double band_sigma) {
  const auto [c, s] = phase_vectors(taps.size(), tap_period_s, frequency_hz);
  FrequencyPoint p;
  p.frequency_hz = frequency_hz;
  const double re = c.dot(taps), im = s.dot(taps);
  p.magnitude = std::hypot(re, im);
  p.phase_rad = std::atan2(im, re);
  // d|G|/db = (Re c + Im s) / |G|; at |G| = 0 the spread of the complex value instead.
  double var = 0.5 * (c.dot(covariance * c) + s.dot(covariance * s));
  if (p.magnitude > 0.0) {
    const Eigen::VectorXd grad = (re * c + im * s) / p.magnitude;
    var = grad.dot(covariance * grad);
  }
  p.magnitude_sigma = std::sqrt(std::max(var, 0.0));
  p.lower = std::max(0.0, p.magnitude - band_sigma * p.magnitude_sigma);
  p.upper = p.magnitude + band_sigma * p.magnitude_sigma;
  // One frequency alone at the level 0.01: chi²_2 quantile -2 ln 0.01.
  p.significant =
      response_chi2(taps, covariance, tap_period_s, frequency_hz) > -2.0 * std::log(0.01);
  return p;
}

ModelErrorModel fit_model_error_model(const std::vector<double>& input,
                                      const std::vector<double>& gap,
                                      const std::vector<std::pair<std::size_t, std::size_t>>& runs,
                                      double cycle_s, const std::vector<bool>& training,
                                      const ModelErrorOptions& o) {
  const std::size_t n = input.size();
  if (gap.size() != n || training.size() != n)
    throw std::invalid_argument("model-error model: input, gap and training rows differ in size");
  if (o.taps == 0 || o.tap_spacing == 0)
    throw std::invalid_argument("model-error model: taps and tap spacing must be positive");
  const std::size_t memory = (o.taps - 1) * o.tap_spacing;
  // Columns: the lagged inputs, then the constant.
  Eigen::MatrixXd columns = Eigen::MatrixXd::Zero(Eigen::Index(n), Eigen::Index(o.taps) + 1);
  std::vector<bool> valid(n, false);
  for (const auto& [b, e] : runs)
    for (std::size_t k = b + memory; k < e; ++k) {
      valid[k] = true;
      for (std::size_t i = 0; i < o.taps; ++i)
        columns(Eigen::Index(k), Eigen::Index(i)) = input[k - i * o.tap_spacing];
      columns(Eigen::Index(k), Eigen::Index(o.taps)) = 1.0;
    }
  std::vector<bool> use(n), heldout(n);
  for (std::size_t k = 0; k < n; ++k) {
    use[k] = valid[k] && training[k];
    heldout[k] = valid[k] && !training[k];
  }
  ModelErrorModel m;
  m.tap_period_s = double(o.tap_spacing) * cycle_s;
  if (std::count(use.begin(), use.end(), true) <= long(o.taps) + 1) return m;
  // The lagged samples of a smooth input are nearly collinear, so the taps come from an SVD with
  // the honest covariance s² V S^-2 V^T: a direction the input does not excite (singular value
  // below 1e-9 of the largest, on unit-norm columns) gets the variance of that floor, i.e. an
  // enormous one, instead of the pseudo-inverse's zero, so its frequencies are not "certain".
  const LinearFit inflation_fit = fit_columns(columns, gap, use);  // the same residual
  std::vector<Eigen::Index> rows;
  for (std::size_t k = 0; k < n; ++k)
    if (use[k]) rows.push_back(Eigen::Index(k));
  const Eigen::Index nr = Eigen::Index(rows.size()), np = columns.cols();
  Eigen::MatrixXd x(nr, np);
  Eigen::VectorXd y(nr);
  for (Eigen::Index i = 0; i < nr; ++i) {
    x.row(i) = columns.row(rows[std::size_t(i)]);
    y[i] = gap[std::size_t(rows[std::size_t(i)])];
  }
  Eigen::VectorXd scale(np);
  for (Eigen::Index c = 0; c < np; ++c) {
    scale[c] = x.col(c).norm() > 0.0 ? x.col(c).norm() : 1.0;
    x.col(c) /= scale[c];
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(x, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const Eigen::VectorXd sv = svd.singularValues();
  const double floor_sv = 1e-9 * sv[0];
  Eigen::VectorXd inverse_sv(sv.size()), inverse_sv2(sv.size());
  for (Eigen::Index i = 0; i < sv.size(); ++i) {
    inverse_sv[i] = sv[i] > floor_sv ? 1.0 / sv[i] : 0.0;  // min-norm taps
    inverse_sv2[i] = 1.0 / std::pow(std::max(sv[i], floor_sv), 2);
  }
  const Eigen::VectorXd theta_scaled =
      svd.matrixV() * inverse_sv.asDiagonal() * (svd.matrixU().transpose() * y);
  const Eigen::VectorXd residual = y - x * theta_scaled;
  const double s2 = residual.squaredNorm() / std::max<double>(double(nr - np), 1.0) *
                    inflation_fit.inflation * inflation_fit.inflation;
  const Eigen::MatrixXd cov_scaled =
      s2 * svd.matrixV() * inverse_sv2.asDiagonal() * svd.matrixV().transpose();
  const Eigen::VectorXd inverse_scale = scale.cwiseInverse();
  const Eigen::VectorXd theta = theta_scaled.cwiseProduct(inverse_scale);
  const Eigen::MatrixXd cov = inverse_scale.asDiagonal() * cov_scaled * inverse_scale.asDiagonal();
  const Eigen::Index nt = Eigen::Index(o.taps);
  m.taps = theta.head(nt);
  m.tap_covariance = cov.topLeftCorner(nt, nt);
  m.tap_sigma = m.tap_covariance.diagonal().cwiseMax(0.0).cwiseSqrt();
  m.offset_rad = theta[nt];

  double e_gap = 0.0, e_res = 0.0;
  const Eigen::VectorXd prediction = columns * theta;
  for (std::size_t k = 0; k < n; ++k)
    if (heldout[k]) {
      const double r = gap[k] - prediction[Eigen::Index(k)];
      e_gap += gap[k] * gap[k];
      e_res += r * r;
    }
  m.heldout_explained_percent = e_gap > 0.0 ? 100.0 * (1.0 - std::sqrt(e_res / e_gap)) : 0.0;

  // Log-spaced frequencies from 0.1 Hz to the taps' Nyquist frequency; a frequency is
  // significant when its chi² exceeds the level 0.01 shared over the grid (Bonferroni).
  const double f_low = 0.1, f_high = 0.5 / m.tap_period_s;
  const std::size_t nf = std::max<std::size_t>(o.frequencies, 2);
  const double chi2_threshold = -2.0 * std::log(0.01 / double(nf));
  for (std::size_t i = 0; i < nf; ++i) {
    const double f = f_low * std::pow(f_high / f_low, double(i) / double(nf - 1));
    FrequencyPoint p = fir_response(m.taps, m.tap_covariance, m.tap_period_s, f, o.band_sigma);
    p.significant = response_chi2(m.taps, m.tap_covariance, m.tap_period_s, f) > chi2_threshold;
    m.significant |= p.significant;
    m.response.push_back(p);
  }
  return m;
}

}  // namespace imscal::eval
