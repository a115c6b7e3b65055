#include "eval/transmission_error_order_spectrum.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <stdexcept>

namespace imscal::eval {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;
constexpr double kArcsecPerRad = 180.0 / std::numbers::pi * 3600.0;

// One window's samples: [begin, end) of the log, all turning one way.
struct Window {
  std::size_t begin = 0;
  std::size_t end = 0;
};

// The windows of one joint: within each segment, the runs where the motor turns one way at a
// steady rate (at least min_rate_rad_s, within max_rate_change of the window's first rate), cut
// into spans of span_rad of motor angle (a run's rest is dropped). At a steady rate the joint
// error's slow part (the path's dynamics, at a few hertz) falls below the first order.
std::vector<Window> steady_windows(const ident::JointErrorLog& log,
                                   const std::vector<double>& theta, double min_rate_rad_s,
                                   double max_rate_change, double span_rad) {
  std::vector<Window> windows;
  for (const auto& [seg_begin, seg_end] : log.segments()) {
    std::size_t start = seg_end;  // start of the current window; seg_end: none
    double start_rate = 0.0;
    for (std::size_t i = seg_begin + 1; i + 1 < seg_end; ++i) {
      const double rate = (theta[i + 1] - theta[i - 1]) / (log.time_s[i + 1] - log.time_s[i - 1]);
      const bool steady = std::abs(rate) >= min_rate_rad_s;
      if (!steady) {
        start = seg_end;
        continue;
      }
      if (start == seg_end ||
          std::abs(rate - start_rate) > max_rate_change * std::abs(start_rate)) {
        start = i;
        start_rate = rate;
        continue;
      }
      if (std::abs(theta[i] - theta[start]) >= span_rad) {
        windows.push_back({start, i + 1});
        start = i;
        start_rate = rate;
      }
    }
  }
  return windows;
}

// The window's residual: r minus its weighted least-squares quadratic in u (weights dθ).
std::vector<double> detrended(const std::vector<double>& r, const std::vector<double>& u,
                              const std::vector<double>& weight) {
  Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
  Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < r.size(); ++i) {
    const Eigen::Vector3d row(1.0, u[i], u[i] * u[i]);
    normal += weight[i] * row * row.transpose();
    rhs += weight[i] * r[i] * row;
  }
  const Eigen::Vector3d c = normal.ldlt().solve(rhs);
  std::vector<double> out(r.size());
  for (std::size_t i = 0; i < r.size(); ++i)
    out[i] = r[i] - (c[0] + c[1] * u[i] + c[2] * u[i] * u[i]);
  return out;
}

// Adds each order's |amplitude|² of one window to power (the angle-domain Fourier integral
// with Hann weights, normalised so a pure a cos(h θ + φ) gives a).
std::vector<double> window_power(const std::vector<double>& error, const std::vector<double>& theta,
                                 const Window& w, const std::vector<double>& orders) {
  std::vector<double> power(orders.size());
  const std::size_t n = w.end - w.begin;
  std::vector<double> r(n), u(n), dtheta(n), ang(n);
  const double span = std::abs(theta[w.end - 1] - theta[w.begin]);
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t i = w.begin + k;
    r[k] = error[i];
    ang[k] = theta[i];
    u[k] = std::abs(theta[i] - theta[w.begin]) / span;
    const std::size_t lo = i > w.begin ? i - 1 : i, hi = i + 1 < w.end ? i + 1 : i;
    dtheta[k] = std::abs(theta[hi] - theta[lo]) / double(hi - lo);
  }
  const std::vector<double> rest = detrended(r, u, dtheta);
  double gain = 0.0;
  std::vector<double> hann(n);
  for (std::size_t k = 0; k < n; ++k) {
    hann[k] = 0.5 * (1.0 - std::cos(kTwoPi * u[k])) * dtheta[k];
    gain += hann[k];
  }
  for (std::size_t o = 0; o < orders.size(); ++o) {
    std::complex<double> sum = 0.0;
    for (std::size_t k = 0; k < n; ++k)
      sum += hann[k] * rest[k] * std::polar(1.0, -orders[o] * ang[k]);
    power[o] = std::norm(2.0 * sum / gain);
  }
  return power;
}

// One order's line: its mean power over the windows against its neighbours' (the grid orders
// either side; the one there at the grid's ends). Two measures of the excess: its t statistic
// over the windows (a gear's error stands out in every window, the rest of the joint error by
// chance), and its size in σ of a noise-only floor (χ² with two degrees of freedom in each
// window, so the mean of n windows' has σ = floor / sqrt(n)).
OrderLine line_of(const std::vector<std::vector<double>>& powers, const std::vector<double>& orders,
                  std::size_t o) {
  const std::size_t below = o > 0 ? o - 1 : o + 1;
  const std::size_t above = o + 1 < orders.size() ? o + 1 : o - 1;
  const double n = double(powers.size());
  double power = 0.0, floor = 0.0, excess_sq = 0.0;
  for (const std::vector<double>& p : powers) {
    const double f = 0.5 * (p[below] + p[above]);
    power += p[o] / n;
    floor += f / n;
    excess_sq += (p[o] - f) * (p[o] - f) / n;
  }
  const double excess = power - floor;
  const double sigma = std::sqrt(std::max(excess_sq - excess * excess, 0.0) / (n - 1.0));
  const double noise_sigma = floor / std::sqrt(n);
  return {orders[o], std::sqrt(power), std::sqrt(floor), sigma > 0.0 ? excess / sigma : 0.0,
          noise_sigma > 0.0 ? excess / noise_sigma : 0.0};
}

bool is_candidate(double order) {
  return std::abs(order * 2.0 - std::round(order * 2.0)) < 1e-9 && order > 0.25;
}

}  // namespace

std::vector<JointOrderSpectrum> transmission_error_order_spectra(
    const ident::JointErrorLog& log, const std::vector<double>& gear_ratio,
    const OrderSpectrumOptions& options) {
  if (!(options.window_motor_revs > 0.0) || !(options.order_step > 0.0) ||
      !(options.max_order >= options.order_step) || !(options.min_motor_speed_rev_s > 0.0))
    throw std::invalid_argument("order spectrum: options out of range");
  std::vector<double> orders;
  for (int k = 1; double(k) * options.order_step <= options.max_order + 1e-9; ++k)
    orders.push_back(double(k) * options.order_step);
  std::vector<JointOrderSpectrum> out(log.joint_count());
  for (std::size_t j = 0; j < log.joint_count() && j < gear_ratio.size(); ++j) {
    if (!(gear_ratio[j] > 0.0)) continue;
    std::vector<double> theta(log.sample_count()), error(log.sample_count());
    for (std::size_t i = 0; i < theta.size(); ++i) {
      theta[i] = gear_ratio[j] * log.q_desired_rad[j][i];
      error[i] = log.q_desired_rad[j][i] - log.q_measured_rad[j][i];
    }
    const std::vector<Window> windows =
        steady_windows(log, theta, kTwoPi * options.min_motor_speed_rev_s, options.max_speed_change,
                       kTwoPi * options.window_motor_revs);
    if (windows.size() < 2) continue;
    std::vector<std::vector<double>> powers;  // [window][order]
    for (const Window& w : windows) powers.push_back(window_power(error, theta, w, orders));
    JointOrderSpectrum& s = out[j];
    s.windows = windows.size();
    for (std::size_t o = 0; o < orders.size(); ++o) s.lines.push_back(line_of(powers, orders, o));
    for (const OrderLine& line : s.lines)
      if (is_candidate(line.order) && line.order <= options.max_candidate + 1e-9 &&
          line.significance_sigma > options.min_significance &&
          line.amplitude_rad > options.min_amplitude_ratio * line.floor_rad &&
          line.t_statistic > options.min_t_statistic)
        s.significant.push_back(line);
    std::ranges::sort(s.significant, [](const OrderLine& a, const OrderLine& b) {
      return a.amplitude_rad > b.amplitude_rad;
    });
  }
  return out;
}

std::string describe_order_spectrum(const JointOrderSpectrum& spectrum) {
  std::string text = fmt::format("{} windows; significant:", spectrum.windows);
  if (spectrum.significant.empty()) text += " none";
  for (const OrderLine& line : spectrum.significant)
    text += fmt::format(" {} ({:.1f}″ over {:.1f}″, t {:.1f}, {:.0f}σ)", line.order,
                        line.amplitude_rad * kArcsecPerRad, line.floor_rad * kArcsecPerRad,
                        line.t_statistic, line.significance_sigma);
  text += "; spectrum [″]:";
  for (const OrderLine& line : spectrum.lines)
    text += fmt::format(" {}:{:.2f}", line.order, line.amplitude_rad * kArcsecPerRad);
  return text;
}

}  // namespace imscal::eval
