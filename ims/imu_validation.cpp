#include "ims/imu_validation.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>

#include "core/input_error.hpp"
#include "ims/earth_model.hpp"

namespace imscal::ims {
namespace {

// Locates sample i in messages: a text line, or a binary record (1-based).
class Locator {
 public:
  // record_count: the records the file holds (0: the series is complete, its size counts).
  Locator(const ImuSeries& series, const ImuColumnNames& columns, std::size_t record_count)
      : series_(series), columns_(columns), record_count_(record_count) {}

  std::size_t line(std::size_t i) const {
    return series_.first_data_line > 0 ? series_.first_data_line + i : 0;
  }
  std::string at(std::size_t i) const {
    return series_.first_data_line > 0 ? fmt::format("line {}", line(i))
                                       : fmt::format("record {}", i + 1);
  }
  const std::string& column(std::size_t c) const { return columns_[c]; }

  // Binary files have no lines: the record number goes into the problem text.
  [[noreturn]] void fail(std::size_t i, std::size_t column_index,
                         const std::string& problem) const {
    const std::string prefix = series_.first_data_line > 0
                                   ? std::string()
                                   : fmt::format("record {} of {}: ", i + 1, records());
    throw InputError(series_.source, line(i), columns_[column_index], prefix + problem);
  }

 private:
  // While a reader streams, the series holds only the records decoded so far.
  std::size_t records() const { return record_count_ > 0 ? record_count_ : series_.samples.size(); }
  const ImuSeries& series_;
  const ImuColumnNames& columns_;
  std::size_t record_count_;
};

double value_of(const ImuSample& s, std::size_t column) {
  if (column == 0) return s.t_s;
  return column <= 3 ? s.gyro[static_cast<Eigen::Index>(column - 1)]
                     : s.acc[static_cast<Eigen::Index>(column - 4)];
}

// Median of the time steps. Beyond kMaxMedianSteps steps a regular subsample is used: the
// median of a record's steps is a robust statistic and does not need every step.
double median_step(const ImuSeries& series) {
  constexpr std::size_t kMaxMedianSteps = 1u << 16;
  const std::size_t n_steps = series.samples.size() - 1;
  if (n_steps == 0) return series.nominal_dt_s;
  const std::size_t stride = std::max<std::size_t>(1, n_steps / kMaxMedianSteps);
  std::vector<double> steps;
  steps.reserve(n_steps / stride + 1);
  for (std::size_t i = 1; i < series.samples.size(); i += stride) {
    const double step = series.samples[i].t_s - series.samples[i - 1].t_s;
    // Bad stamps are reported by the scan, in file order; here they would only spoil the order.
    if (std::isfinite(step) && step > 0.0) steps.push_back(step);
  }
  if (steps.empty()) return series.nominal_dt_s;
  auto middle = steps.begin() + static_cast<std::ptrdiff_t>(steps.size() / 2);
  std::nth_element(steps.begin(), middle, steps.end());
  return *middle;
}

// Finite values and a stamp after the previous one, before anything divides by a step.
void check_finite_and_increasing(const ImuSeries& series, std::size_t i, const Locator& where) {
  const auto& samples = series.samples;
  const ImuSample& s = samples[i];
  // One test per sample on the sum keeps the loop cheap; the slow path finds the field.
  // (Finite values whose sum overflows are legal; the saturation check judges them.)
  if (!std::isfinite(s.t_s + s.gyro.sum() + s.acc.sum())) {
    for (std::size_t c = 0; c < 7; ++c) {
      const double v = value_of(s, c);
      if (!std::isfinite(v))
        where.fail(i, c, fmt::format("value is {}; expected a finite number", v));
    }
  }
  if (i == 0 || s.t_s > samples[i - 1].t_s) return;
  if (s.t_s == samples[i - 1].t_s) {
    where.fail(i, 0,
               fmt::format("duplicated time stamp {} s (the same as {}); time stamps must "
                           "increase strictly",
                           s.t_s, where.at(i - 1)));
  }
  where.fail(i, 0,
             fmt::format("time stamp {} s is not after {} s at {}; time stamps must increase "
                         "strictly",
                         s.t_s, samples[i - 1].t_s, where.at(i - 1)));
}

// Which unit mistake turns |g| into the static magnitude found.
std::string diagnose_specific_force(double magnitude, double gravity, const ImuSeries& series) {
  const bool rates = series.quantity == ImuQuantity::kRates;
  struct Candidate {
    double expected;
    std::string meaning;
  };
  const double dt = series.nominal_dt_s;
  const std::vector<Candidate> candidates = {
      rates ? Candidate{gravity * dt,
                        "velocity increments over the nominal interval, not specific force "
                        "(increments in rate columns)"}
            : Candidate{gravity / dt,
                        "specific force [m/s^2], not velocity increments (rates in increment "
                        "columns)"},
      {1.0, rates ? "g, not m/s^2" : "g*s, not m/s"},
      {1000.0, rates ? "mg, not m/s^2" : "mg*s, not m/s"},
      {gravity * 100.0, rates ? "cm/s^2 (Gal), not m/s^2" : "cm/s, not m/s"},
      {gravity * 1000.0, rates ? "mm/s^2, not m/s^2" : "mm/s, not m/s"},
      {gravity / 0.3048, rates ? "ft/s^2, not m/s^2" : "ft/s, not m/s"},
  };
  for (const auto& c : candidates) {
    if (std::abs(magnitude / c.expected - 1.0) < 0.05) return "the values look like " + c.meaning;
  }
  return "check the accelerometer units and scale factors (and the site)";
}

}  // namespace

// Everything that looks at the values, the steps and the motion, in one pass over the samples,
// which a reader can run while the samples it just parsed are still in cache: an hour at 2 kHz
// is 400 MB and does not fit in a cache. Errors found on the way (non-finite values, stamps out
// of order, degree-like rates) are thrown at once. The rest waits for finish(): the nominal
// interval is checked against the median step first (a wrong nominal_dt_s would otherwise show
// as gaps), then gaps, then gravity (it needs all rest windows), then saturation (a unit
// mistake such as mm/s^2 saturates everything and is the better diagnosis).
class ImuValidator::Scan {
 public:
  Scan(const ImuSeries& series, const ImuReadOptions& options, const ImuSourceInfo& info,
       ImuReadReport& report)
      : series_(series),
        options_(options),
        columns_(info.columns ? *info.columns : si_column_names(series.quantity)),
        nominal_dt_line_(info.nominal_dt_line),
        where_(series, columns_, info.record_count),
        report_(report),
        rates_(series.quantity == ImuQuantity::kRates),
        nominal_(series.nominal_dt_s),
        window_length_(std::max<std::size_t>(
            10, static_cast<std::size_t>(std::llround(options.static_window_s / nominal_)))) {}

  void check_up_to(std::size_t n) {
    const auto& samples = series_.samples;
    for (std::size_t i = checked_; i < n; ++i) {
      check_finite_and_increasing(series_, i, where_);
      const double step = i == 0 ? nominal_ : samples[i].t_s - samples[i - 1].t_s;
      if (i > 0) time_step(i, step);
      const double scale = rates_ ? 1.0 : 1.0 / step;  // increments -> mean rate
      const Eigen::Vector3d omega = samples[i].gyro * scale;
      const Eigen::Vector3d f = samples[i].acc * scale;
      if (options_.check_units) {
        sustained_rate(i, omega);
        rest_window(i, omega, f);
      }
      if (omega.cwiseAbs().maxCoeff() >= options_.gyro_range_rad_s ||
          f.cwiseAbs().maxCoeff() >= options_.acc_range_m_s2) {
        saturated(i, omega, f, step);
      }
    }
    checked_ = std::max(checked_, n);
  }

  void finish() {
    check_up_to(series_.samples.size());
    if (series_.samples.empty()) {
      throw InputError(series_.source, series_.first_data_line, columns_[0],
                       "no samples; expected at least one data line or record");
    }
    report_.samples = series_.samples.size();
    report_.duration_s = series_.samples.back().t_s - series_.samples.front().t_s;
    report_.median_dt_s = median_step(series_);
    if (std::abs(report_.median_dt_s - nominal_) > options_.jitter_fraction * nominal_) {
      throw InputError(series_.source, nominal_dt_line_, "nominal_dt_s",
                       fmt::format("the header says {} s but the median time step is {} s; the "
                                   "nominal interval must match the data",
                                   nominal_, report_.median_dt_s));
    }
    if (first_refused_gap_ > 0) {
      const std::size_t i = first_refused_gap_;
      const double step = series_.samples[i].t_s - series_.samples[i - 1].t_s;
      where_.fail(
          i, 0,
          fmt::format("gap of {} s ({:.3g} nominal intervals of {} s) after {}; a "
                      "step longer than {} intervals is a gap "
                      "(ImuReadOptions::gap_factor, allow_gaps)",
                      step, step / nominal_, nominal_, where_.at(i - 1), options_.gap_factor));
    }
    time_summary();
    if (options_.check_units) gravity();
    saturation_summary();
  }

 private:
  void time_step(std::size_t i, double step) {
    report_.max_step_s = std::max(report_.max_step_s, step);
    if (step > options_.gap_factor * nominal_) {
      if (!options_.allow_gaps) {
        if (first_refused_gap_ == 0) first_refused_gap_ = i;  // judged in finish()
        return;
      }
      if (report_.gap_count++ == 0) first_gap_ = i;
      return;
    }
    const double deviation = std::abs(step - nominal_);
    jitter_sum_sq_ += deviation * deviation;
    ++regular_steps_;
    if (deviation > options_.jitter_fraction * nominal_) {
      ++report_.jitter_count;
      if (deviation > report_.jitter_max_abs_s) worst_jitter_ = i;
    }
    report_.jitter_max_abs_s = std::max(report_.jitter_max_abs_s, deviation);
  }

  void time_summary() {
    report_.jitter_rms_s =
        regular_steps_ > 0 ? std::sqrt(jitter_sum_sq_ / static_cast<double>(regular_steps_)) : 0;
    if (report_.gap_count > 0) {
      add_imu_warning(&report_, fmt::format("{}: {} gaps (steps > {} nominal intervals), the "
                                            "first after {}; the longest step is {} s",
                                            series_.source, report_.gap_count, options_.gap_factor,
                                            where_.at(first_gap_ - 1), report_.max_step_s));
    }
    if (report_.jitter_count > 0) {
      add_imu_warning(
          &report_,
          fmt::format("{}: time-stamp jitter: {} of {} steps differ from the nominal {} s by "
                      "more than {:.0f}%; the worst, {} s off, ends at {}; RMS deviation {:.3g} "
                      "s, median step {} s",
                      series_.source, report_.jitter_count, series_.samples.size() - 1, nominal_,
                      100.0 * options_.jitter_fraction, report_.jitter_max_abs_s,
                      where_.at(worst_jitter_), report_.jitter_rms_s, report_.median_dt_s));
    }
  }

  // Angular rate beyond max_plausible_rate_rad_s on every sample for sustained_rate_duration_s.
  void sustained_rate(std::size_t i, const Eigen::Vector3d& omega) {
    const double limit = options_.max_plausible_rate_rad_s;
    if (!(omega.squaredNorm() > limit * limit)) {
      in_run_ = false;
      return;
    }
    if (!in_run_) {
      in_run_ = true;
      run_start_ = i;
      omega.cwiseAbs().maxCoeff(&run_axis_);
    }
    // The run covers the intervals of its samples: from one interval before its first stamp.
    const auto& samples = series_.samples;
    const double duration = samples[i].t_s - samples[run_start_].t_s + nominal_;
    if (duration < options_.sustained_rate_duration_s) return;
    where_.fail(
        run_start_, 1 + static_cast<std::size_t>(run_axis_),
        fmt::format("|omega| > {} rad/s sustained for {} s ({} to {}): implausible for "
                    "rad/s; the values look like {}",
                    limit, duration, where_.at(run_start_), where_.at(i),
                    rates_ ? "deg/s, not rad/s" : "deg, not rad (or rates in increment columns)"));
  }

  // Rest windows: fixed windows of window_length_ samples whose rate and specific-force
  // components all vary little. Sums of deviations from the window's first sample avoid
  // cancellation in the variance.
  void rest_window(std::size_t i, const Eigen::Vector3d& omega, const Eigen::Vector3d& f) {
    if (window_fill_ == 0) {
      omega0_ = omega;
      f0_ = f;
      sum_w_.setZero();
      sum_w2_.setZero();
      sum_f_.setZero();
      sum_f2_.setZero();
    }
    const Eigen::Vector3d dw = omega - omega0_, df = f - f0_;
    sum_w_ += dw;
    sum_w2_ += dw.cwiseProduct(dw);
    sum_f_ += df;
    sum_f2_ += df.cwiseProduct(df);
    if (++window_fill_ < window_length_) return;  // (a counter: a division per sample is slow)
    window_fill_ = 0;
    const double m = static_cast<double>(window_length_);
    const Eigen::Vector3d var_w = (sum_w2_ - sum_w_.cwiseProduct(sum_w_) / m) / (m - 1);
    const Eigen::Vector3d var_f = (sum_f2_ - sum_f_.cwiseProduct(sum_f_) / m) / (m - 1);
    const Eigen::Vector3d mean_f = f0_ + sum_f_ / m;
    // The accelerometer limit grows with |f| so that data in a small unit (mm/s^2), whose noise
    // is large in numbers, is still found at rest and diagnosed.
    const double acc_std_limit = options_.static_acc_std_m_s2 + 0.005 * mean_f.norm();
    const double gyro_std_limit = options_.static_gyro_std_rad_s;
    if (var_w.maxCoeff() <= gyro_std_limit * gyro_std_limit &&
        var_f.maxCoeff() <= acc_std_limit * acc_std_limit) {
      if (report_.static_windows++ == 0) {
        first_rest_ = i + 1 - window_length_;
        mean_f.cwiseAbs().maxCoeff(&first_rest_axis_);
      }
      rest_magnitude_sum_ += mean_f.norm();
    }
  }

  void gravity() {
    if (report_.static_windows == 0) {
      add_imu_warning(&report_, fmt::format("{}: no rest window of {} s found; the "
                                            "accelerometer units were not checked against gravity",
                                            series_.source, options_.static_window_s));
      return;
    }
    const double magnitude = rest_magnitude_sum_ / static_cast<double>(report_.static_windows);
    const double gravity = series_.site ? EarthModel(*series_.site).normal_gravity_magnitude()
                                        : options_.default_gravity_m_s2;
    const double tolerance = options_.gravity_tolerance_m_s2 +
                             (series_.site ? 0.0 : options_.default_gravity_extra_tolerance_m_s2);
    report_.static_specific_force_m_s2 = magnitude;
    report_.expected_gravity_m_s2 = gravity;
    if (std::abs(magnitude - gravity) <= tolerance) return;
    where_.fail(first_rest_, 4 + static_cast<std::size_t>(first_rest_axis_),
                fmt::format("static |f| = {:#.4g}, expected {:.4g} m/s^2 (+-{} m/s^2, {}; mean "
                            "of {} rest windows, the first from {}): {}",
                            magnitude, gravity, tolerance,
                            series_.site ? "normal gravity at the file's site"
                                         : "default gravity, the file has no site",
                            report_.static_windows, where_.at(first_rest_),
                            diagnose_specific_force(magnitude, gravity, series_)));
  }

  void saturated(std::size_t i, const Eigen::Vector3d& omega, const Eigen::Vector3d& f,
                 double step) {
    for (std::size_t c = 1; c < 7; ++c) {
      const bool gyro = c <= 3;
      const double rate =
          gyro ? omega[static_cast<Eigen::Index>(c - 1)] : f[static_cast<Eigen::Index>(c - 4)];
      const double range = gyro ? options_.gyro_range_rad_s : options_.acc_range_m_s2;
      if (std::abs(rate) < range) continue;
      if (report_.saturated_count++ > 0) continue;
      first_saturated_ = i;
      first_saturated_column_ = c;
      const double value = value_of(series_.samples[i], c);
      const char* unit = gyro ? "rad/s" : "m/s^2";
      saturation_problem_ = fmt::format(
          "value {} is at or beyond the {} range +-{} {}: saturated (set ImuReadOptions::{}, "
          "or allow_saturation)",
          rates_ ? fmt::format("{} {}", value, unit)
                 : fmt::format("{} over {} s = {} {}", value, step, rate, unit),
          gyro ? "gyro" : "accelerometer", range, unit,
          gyro ? "gyro_range_rad_s" : "acc_range_m_s2");
    }
  }

  void saturation_summary() {
    if (report_.saturated_count == 0) return;
    if (!options_.allow_saturation) {
      where_.fail(first_saturated_, first_saturated_column_, saturation_problem_);
    }
    add_imu_warning(&report_,
                    fmt::format("{}: {} saturated values (at or beyond +-{} rad/s or +-{} "
                                "m/s^2), the first at {}, field '{}'",
                                series_.source, report_.saturated_count, options_.gyro_range_rad_s,
                                options_.acc_range_m_s2, where_.at(first_saturated_),
                                where_.column(first_saturated_column_)));
  }

  const ImuSeries& series_;
  const ImuReadOptions options_;
  const ImuColumnNames columns_;
  const std::size_t nominal_dt_line_;
  const Locator where_;
  ImuReadReport& report_;
  std::size_t checked_ = 0;  // samples [0, checked_) are checked
  std::size_t first_refused_gap_ = 0;
  const bool rates_;
  const double nominal_;
  const std::size_t window_length_;
  // time steps
  double jitter_sum_sq_ = 0.0;
  std::size_t regular_steps_ = 0, worst_jitter_ = 0, first_gap_ = 0;
  // sustained rates
  bool in_run_ = false;
  std::size_t run_start_ = 0;
  Eigen::Index run_axis_ = 0;
  // rest windows
  Eigen::Vector3d omega0_, f0_, sum_w_, sum_w2_, sum_f_, sum_f2_;
  std::size_t window_fill_ = 0;  // samples in the current window
  double rest_magnitude_sum_ = 0.0;
  std::size_t first_rest_ = 0;
  Eigen::Index first_rest_axis_ = 0;
  // saturation
  std::size_t first_saturated_ = 0, first_saturated_column_ = 0;
  std::string saturation_problem_;
};

ImuColumnNames si_column_names(ImuQuantity quantity) {
  if (quantity == ImuQuantity::kIncrements) {
    return {"t_s",      "dtheta_x_rad", "dtheta_y_rad", "dtheta_z_rad",
            "dv_x_m_s", "dv_y_m_s",     "dv_z_m_s"};
  }
  return {"t_s",        "gyro_x_rad_s", "gyro_y_rad_s", "gyro_z_rad_s",
          "acc_x_m_s2", "acc_y_m_s2",   "acc_z_m_s2"};
}

std::array<double, 7> finite_sample_values(const ImuSeries& series, std::size_t index) {
  const ImuSample& s = series.samples[index];
  const std::array<double, 7> values = {s.t_s,     s.gyro.x(), s.gyro.y(), s.gyro.z(),
                                        s.acc.x(), s.acc.y(),  s.acc.z()};
  for (std::size_t c = 0; c < values.size(); ++c) {
    if (!std::isfinite(values[c])) {
      throw std::invalid_argument(fmt::format("IMU sample {} has a non-finite value ({}) in {}",
                                              index, values[c],
                                              si_column_names(series.quantity)[c]));
    }
  }
  return values;
}

void add_imu_warning(ImuReadReport* report, const std::string& warning) {
  spdlog::warn("{}", warning);
  if (report != nullptr) report->warnings.push_back(warning);
}

ImuValidator::ImuValidator(const ImuSeries& series, const ImuReadOptions& options,
                           ImuReadReport* report, const ImuSourceInfo& info)
    : report_out_(report) {
  // Fresh statistics; warnings a reader gave already (unit conversions) are kept first.
  if (report_out_ != nullptr) report_.warnings = std::move(report_out_->warnings);
  report_.file = series.source;
  if (!(std::isfinite(series.nominal_dt_s) && series.nominal_dt_s > 0.0)) {
    publish();
    throw InputError(series.source, info.nominal_dt_line, "nominal_dt_s",
                     fmt::format("nominal interval is {} s; expected a positive number of seconds",
                                 series.nominal_dt_s));
  }
  scan_ = std::make_unique<Scan>(series, options, info, report_);
}

ImuValidator::~ImuValidator() = default;

void ImuValidator::check_up_to(std::size_t n) {
  scan_->check_up_to(n);
}

void ImuValidator::finish() {
  try {
    scan_->finish();
  } catch (...) {
    publish();
    throw;
  }
  publish();
}

void ImuValidator::publish() {
  if (report_out_ != nullptr) *report_out_ = std::move(report_);
  report_out_ = nullptr;
}

void validate_imu_series(const ImuSeries& series, const ImuReadOptions& options,
                         ImuReadReport* report, const ImuSourceInfo& info) {
  ImuValidator validator(series, options, report, info);
  validator.finish();
}

std::string ImuReadReport::brief() const {
  std::string text = fmt::format(
      "{}: {} samples over {:.6g} s, median step {:.6g} s, longest step {:.6g} s, {} gaps, {} "
      "jittered steps (RMS {:.3g} s, max {:.3g} s), {} saturated values",
      file, samples, duration_s, median_dt_s, max_step_s, gap_count, jitter_count, jitter_rms_s,
      jitter_max_abs_s, saturated_count);
  if (static_specific_force_m_s2 && expected_gravity_m_s2) {
    text += fmt::format(", static |f| {:.6g} m/s^2 vs |g| {:.6g} m/s^2 ({} rest windows)",
                        *static_specific_force_m_s2, *expected_gravity_m_s2, static_windows);
  }
  for (const auto& w : warnings) text += "\n  warning: " + w;
  return text;
}

}  // namespace imscal::ims
