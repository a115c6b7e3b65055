#include "calib/time_offset.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/input_error.hpp"
#include "core/parallel_tasks.hpp"
#include "robot/jacobian.hpp"

namespace imscal::calib {
namespace {

void check_series(const RateMagnitudeSeries& series, const std::string& what) {
  if (series.t_s.size() != series.rate_rad_s.size()) {
    throw InputError(
        series.source, 0, what,
        fmt::format("{} times but {} rates", series.t_s.size(), series.rate_rad_s.size()));
  }
  if (series.t_s.size() < 4) {
    throw InputError(series.source, 0, what, "fewer than 4 samples");
  }
  for (std::size_t k = 0; k < series.t_s.size(); ++k) {
    if (!std::isfinite(series.t_s[k]) || !std::isfinite(series.rate_rad_s[k])) {
      throw InputError(series.source, 0, what, fmt::format("sample {} is not finite", k));
    }
    if (k > 0 && !(series.t_s[k] > series.t_s[k - 1])) {
      throw InputError(series.source, 0, what,
                       fmt::format("time does not increase at sample {} ({} s after {} s)", k,
                                   series.t_s[k], series.t_s[k - 1]));
    }
  }
}

double median_interval(const std::vector<double>& t) {
  std::vector<double> dt(t.size() - 1);
  for (std::size_t k = 1; k < t.size(); ++k) dt[k - 1] = t[k] - t[k - 1];
  std::nth_element(dt.begin(), dt.begin() + dt.size() / 2, dt.end());
  return dt[dt.size() / 2];
}

// Cubic Hermite interpolation of a series with finite-difference tangents; queries must lie in
// [t.front(), t.back()] and be made in increasing order (the cursor only moves forward).
class HermiteCursor {
 public:
  explicit HermiteCursor(const RateMagnitudeSeries& s) : t_(s.t_s), y_(s.rate_rad_s) {}
  double at(double t) {
    while (k_ + 2 < t_.size() && t_[k_ + 1] <= t) ++k_;
    const double t0 = t_[k_], t1 = t_[k_ + 1];
    const double h = t1 - t0;
    const double u = (t - t0) / h;
    const double m0 = tangent(k_) * h;
    const double m1 = tangent(k_ + 1) * h;
    const double u2 = u * u, u3 = u2 * u;
    return (2 * u3 - 3 * u2 + 1) * y_[k_] + (u3 - 2 * u2 + u) * m0 +
           (-2 * u3 + 3 * u2) * y_[k_ + 1] + (u3 - u2) * m1;
  }

 private:
  double tangent(std::size_t k) const {
    const std::size_t lo = k == 0 ? 0 : k - 1;
    const std::size_t hi = std::min(k + 1, t_.size() - 1);
    return (y_[hi] - y_[lo]) / (t_[hi] - t_[lo]);
  }
  const std::vector<double>& t_;
  const std::vector<double>& y_;
  std::size_t k_ = 0;
};

struct Window {
  std::size_t begin = 0;  // IMS sample indices [begin, end)
  std::size_t end = 0;
};

// Pearson correlation of ims[k] and robot(t_k - lag) over the window.
double correlation_at(const RateMagnitudeSeries& robot, const RateMagnitudeSeries& ims,
                      const Window& w, double lag_s) {
  HermiteCursor cursor(robot);
  double sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
  for (std::size_t k = w.begin; k < w.end; ++k) {
    const double x = ims.rate_rad_s[k];
    const double y = cursor.at(ims.t_s[k] - lag_s);
    sx += x;
    sy += y;
    sxx += x * x;
    syy += y * y;
    sxy += x * y;
  }
  const double n = static_cast<double>(w.end - w.begin);
  const double cov = sxy - sx * sy / n;
  const double var_x = sxx - sx * sx / n;
  const double var_y = syy - sy * sy / n;
  if (var_x <= 0.0 || var_y <= 0.0) return 0.0;
  return cov / std::sqrt(var_x * var_y);
}

double standard_deviation(const std::vector<double>& v, std::size_t begin, std::size_t end) {
  double s = 0, ss = 0;
  for (std::size_t k = begin; k < end; ++k) {
    s += v[k];
    ss += v[k] * v[k];
  }
  const double n = static_cast<double>(end - begin);
  return std::sqrt(std::max(0.0, ss / n - (s / n) * (s / n)));
}

}  // namespace

RateMagnitudeSeries flange_rate_magnitude(const KinematicModel& model,
                                          const std::vector<double>& t_s,
                                          const std::vector<JointVector>& q_rad,
                                          const std::string& source) {
  if (t_s.size() != q_rad.size()) {
    throw InputError(source, 0, "q_rad",
                     fmt::format("{} times but {} joint samples", t_s.size(), q_rad.size()));
  }
  RateMagnitudeSeries out;
  out.source = source;
  if (t_s.size() > 2) {
    out.t_s.reserve(t_s.size() - 2);
    out.rate_rad_s.reserve(t_s.size() - 2);
  }
  for (std::size_t k = 1; k + 1 < t_s.size(); ++k) {
    const double span = t_s[k + 1] - t_s[k - 1];
    if (!(t_s[k] > t_s[k - 1]) || !(t_s[k + 1] > t_s[k])) {
      throw InputError(source, 0, "t_s", fmt::format("time does not increase at sample {}", k));
    }
    const JointVector q_dot = (q_rad[k + 1] - q_rad[k - 1]) / span;
    const Jacobian jacobian = geometric_jacobian(model, q_rad[k]);
    out.t_s.push_back(t_s[k]);
    out.rate_rad_s.push_back((jacobian.bottomRows<3>() * q_dot).norm());
  }
  return out;
}

RateMagnitudeSeries ims_rate_magnitude(const ims::ImuSeries& imu,
                                       const std::function<Eigen::Vector3d(double)>& earth_rate_S) {
  RateMagnitudeSeries out;
  out.source = imu.source.empty() ? std::string("IMS samples") : imu.source;
  out.t_s.reserve(imu.samples.size());
  out.rate_rad_s.reserve(imu.samples.size());
  for (std::size_t k = 0; k < imu.samples.size(); ++k) {
    const ims::ImuSample& s = imu.samples[k];
    double t = s.t_s;
    Eigen::Vector3d rate = s.gyro;
    if (imu.quantity == ims::ImuQuantity::kIncrements) {
      const double dt = k == 0 ? imu.nominal_dt_s : s.t_s - imu.samples[k - 1].t_s;
      if (!(dt > 0.0)) {
        throw InputError(out.source, imu.first_data_line == 0 ? 0 : imu.first_data_line + k, "t_s",
                         "sample interval is not positive");
      }
      rate = s.gyro / dt;
      t = s.t_s - 0.5 * dt;
    }
    out.t_s.push_back(t);
    out.rate_rad_s.push_back((rate - earth_rate_S(t)).norm());
  }
  return out;
}

RateMagnitudeSeries ims_rate_magnitude(const ims::ImuSeries& imu,
                                       const Eigen::Vector3d& earth_rate_S) {
  return ims_rate_magnitude(imu, [&](double) { return earth_rate_S; });
}

TimeOffsetResult estimate_time_offset(const RateMagnitudeSeries& robot,
                                      const RateMagnitudeSeries& ims,
                                      const TimeOffsetOptions& options) {
  check_series(robot, "robot_rate");
  check_series(ims, "ims_rate");
  const std::string where = robot.source + " / " + ims.source;
  const double max_lag = options.max_abs_offset_s;
  if (!(max_lag > 0.0)) {
    throw InputError(where, 0, "max_abs_offset_s", "must be positive");
  }
  // IMS samples whose t - lag stays inside the robot record for every lag in the range.
  const double first = robot.t_s.front() + max_lag;
  const double last = robot.t_s.back() - max_lag;
  Window w;
  w.begin = static_cast<std::size_t>(std::lower_bound(ims.t_s.begin(), ims.t_s.end(), first) -
                                     ims.t_s.begin());
  w.end = static_cast<std::size_t>(std::upper_bound(ims.t_s.begin(), ims.t_s.end(), last) -
                                   ims.t_s.begin());
  TimeOffsetResult result;
  result.overlap_s = w.end > w.begin + 1 ? ims.t_s[w.end - 1] - ims.t_s[w.begin] : 0.0;
  result.sample_count = w.end > w.begin ? w.end - w.begin : 0;
  if (result.sample_count < 4 || result.overlap_s < options.min_overlap_s) {
    throw InputError(
        where, 0, "overlap",
        fmt::format("only {:.3f} s of IMS data lie inside the robot record shrunk by the search "
                    "range +-{:.3f} s (robot {:.3f}..{:.3f} s, IMS {:.3f}..{:.3f} s); at least "
                    "{:.3f} s are needed",
                    result.overlap_s, max_lag, robot.t_s.front(), robot.t_s.back(), ims.t_s.front(),
                    ims.t_s.back(), options.min_overlap_s));
  }
  const double ims_std = standard_deviation(ims.rate_rad_s, w.begin, w.end);
  const double robot_std = standard_deviation(robot.rate_rad_s, 0, robot.rate_rad_s.size());
  if (ims_std < options.min_rate_std_rad_s || robot_std < options.min_rate_std_rad_s) {
    throw InputError(
        where, 0, "motion",
        fmt::format("the motion is too poor to time: std of |omega| is {:.4g} rad/s (robot) and "
                    "{:.4g} rad/s (IMS), at least {:.4g} rad/s is needed; move the wrist with "
                    "changing speed",
                    robot_std, ims_std, options.min_rate_std_rad_s));
  }

  // Coarse search.
  const double step =
      options.coarse_step_s > 0.0 ? options.coarse_step_s : median_interval(robot.t_s);
  const int half_count = static_cast<int>(std::floor(max_lag / step));
  if (half_count < 2) {
    throw InputError(
        where, 0, "coarse_step_s",
        fmt::format("step {:.4g} s too coarse for the range +-{:.4g} s", step, max_lag));
  }
  std::vector<double> rho(2 * half_count + 1);
  // Independent lags: on the cores.
  run_parallel_tasks(rho.size(), [&](std::size_t i) {
    rho[i] = correlation_at(robot, ims, w, (int(i) - half_count) * step);
  });
  result.lags_evaluated = rho.size();
  const int best = static_cast<int>(std::max_element(rho.begin(), rho.end()) - rho.begin());
  if (best == 0 || best == static_cast<int>(rho.size()) - 1) {
    throw InputError(where, 0, "offset",
                     fmt::format("the correlation peaks at the edge of the search range "
                                 "({:+.4f} s); the offset may exceed +-{:.4f} s",
                                 (best - half_count) * step, max_lag));
  }
  // Main lobe: the contiguous lags around the peak above half its height over the curve's
  // minimum. The secondary peak is the best local maximum outside it (range ends included).
  const int count = static_cast<int>(rho.size());
  const double half_height = 0.5 * (rho[best] + *std::min_element(rho.begin(), rho.end()));
  int lobe_lo = best, lobe_hi = best;
  while (lobe_lo > 0 && rho[lobe_lo - 1] > half_height) --lobe_lo;
  while (lobe_hi + 1 < count && rho[lobe_hi + 1] > half_height) ++lobe_hi;
  for (int m = 0; m < count; ++m) {
    if (m >= lobe_lo && m <= lobe_hi) continue;
    const bool local_max =
        (m == 0 || rho[m] >= rho[m - 1]) && (m == count - 1 || rho[m] >= rho[m + 1]);
    if (local_max) {
      result.secondary_peak_correlation = std::max(result.secondary_peak_correlation, rho[m]);
    }
  }

  // Golden-section refinement on [peak - step, peak + step].
  const double golden = 0.5 * (std::sqrt(5.0) - 1.0);
  double a = (best - half_count - 1) * step;
  double b = (best - half_count + 1) * step;
  double c = b - golden * (b - a);
  double d = a + golden * (b - a);
  double rho_c = correlation_at(robot, ims, w, c);
  double rho_d = correlation_at(robot, ims, w, d);
  while (b - a > options.tolerance_s) {
    if (rho_c > rho_d) {
      b = d;
      d = c;
      rho_d = rho_c;
      c = b - golden * (b - a);
      rho_c = correlation_at(robot, ims, w, c);
    } else {
      a = c;
      c = d;
      rho_c = rho_d;
      d = a + golden * (b - a);
      rho_d = correlation_at(robot, ims, w, d);
    }
    ++result.lags_evaluated;
  }
  result.offset_s = 0.5 * (a + b);
  result.peak_correlation = correlation_at(robot, ims, w, result.offset_s);
  const double h = 0.5 * step;
  result.peak_curvature_1_s2 =
      -(correlation_at(robot, ims, w, result.offset_s + h) - 2.0 * result.peak_correlation +
        correlation_at(robot, ims, w, result.offset_s - h)) /
      (h * h);
  result.peak_width_s = result.peak_curvature_1_s2 > 0.0
                            ? std::sqrt(0.02 / result.peak_curvature_1_s2)
                            : std::numeric_limits<double>::infinity();
  result.lags_evaluated += 3;

  if (result.peak_correlation < options.min_peak_correlation) {
    throw InputError(
        where, 0, "offset",
        fmt::format("the best correlation of the rate magnitudes is only {:.3f} (at "
                    "{:+.4f} s; at least {:.3f} needed): the records do not show the "
                    "same motion, or the motion is too poor",
                    result.peak_correlation, result.offset_s, options.min_peak_correlation));
  }
  if (result.peak_correlation - result.secondary_peak_correlation < options.min_peak_margin) {
    throw InputError(where, 0, "offset",
                     fmt::format("the correlation peak at {:+.4f} s ({:.3f}) is ambiguous: another "
                                 "lag reaches {:.3f} (margin below {:.3f}); the motion is too "
                                 "periodic, add non-repeating moves or narrow the search range",
                                 result.offset_s, result.peak_correlation,
                                 result.secondary_peak_correlation, options.min_peak_margin));
  }
  return result;
}

}  // namespace imscal::calib
