#include "eval/gap_imu_signals.hpp"
#include "core/units.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <set>

namespace imscal::eval {
namespace {

// The gyro samples the gap is evaluated on: outside the spans the record's own check flags as
// motion the sensor did not record (kSensorMissedMotion: no model of the sensor bridges a lost
// stretch of data; those spans are reported, not modelled).
struct GyroSamples {
  std::vector<double> t_s;
  std::vector<Eigen::Vector3d> w;
};

GyroSamples usable(const calib::ToolImuRecord& r, const calib::ToolImuAnalysis& check,
                   double& excluded_s) {
  GyroSamples g;
  excluded_s = 0.0;
  for (const auto& [b, e] : check.missed_motion_spans_s) excluded_s += e - b;
  for (std::size_t k = 0; k < r.t_s.size(); ++k) {
    bool missed = false;
    for (const auto& [b, e] : check.missed_motion_spans_s) missed |= r.t_s[k] >= b && r.t_s[k] <= e;
    if (missed) continue;
    g.t_s.push_back(r.t_s[k]);
    g.w.push_back(r.gyro_rad_s[k]);
  }
  return g;
}

bool on_rail(const Eigen::Vector3d& w, const ImuGapModel& m) {
  for (int i = 0; i < 3; ++i)
    if (std::abs(w[i]) >= 0.99 * m.rail_rad_s[i]) return true;
  return false;
}

Eigen::Vector3d predicted(const Eigen::Vector3d& w_T, const ImuGapModel& m) {
  Eigen::Vector3d w = m.scale.cwiseProduct(m.R_T_S.transpose() * w_T) + m.bias_rad_s;
  for (int i = 0; i < 3; ++i) w[i] = std::clamp(w[i], -m.rail_rad_s[i], m.rail_rad_s[i]);
  return w;
}

// The gyro samples (sensor clock) paired with the robot's rate at t - dt.
struct Pairs {
  std::vector<Eigen::Vector3d> meas, robot;
};

Pairs pairs(const GyroSamples& r, const calib::RobotRateSeries& rate, double dt,
            const ImuGapModel& m, bool skip_rail) {
  Pairs p;
  for (std::size_t k = 0; k < r.t_s.size(); ++k) {
    Eigen::Vector3d w_T;
    if (!calib::robot_rate_at(rate, r.t_s[k] - dt, w_T)) continue;
    if (skip_rail && on_rail(r.w[k], m)) continue;
    p.meas.push_back(r.w[k]);
    p.robot.push_back(w_T);
  }
  return p;
}

// Fits R, K and b (those of `effects`) at a given dt on the training pairs; returns the SSE.
double fit_at(const GyroSamples& r, const calib::RobotRateSeries& rate, double dt,
              const std::set<ImuGapEffect>& effects, ImuGapModel& m) {
  m.time_offset_s = dt;
  const bool saturation = effects.count(ImuGapEffect::kSaturation) > 0;
  const Pairs p = pairs(r, rate, dt, m, saturation);
  if (p.meas.size() < 10) return 1e300;
  m.R_T_S = Eigen::Matrix3d::Identity();
  if (effects.count(ImuGapEffect::kAxisMisalignment))
    m.R_T_S = calib::fit_rotation(p.meas, p.robot);
  const bool scale = effects.count(ImuGapEffect::kScaleFactors) > 0;
  const bool bias = effects.count(ImuGapEffect::kBias) > 0;
  double sse = 0.0;
  for (int i = 0; i < 3; ++i) {
    // w_meas_i = K_i x_i + b_i, x = R^T w_T: 2x2 normal equations (or 1x1, or none).
    double sxx = 0, sx = 0, sxy = 0, sy = 0, n = 0;
    for (std::size_t k = 0; k < p.meas.size(); ++k) {
      const double x = (m.R_T_S.transpose() * p.robot[k])[i], y = p.meas[k][i];
      sxx += x * x, sx += x, sxy += x * y, sy += y, n += 1;
    }
    double K = 1.0, b = 0.0;
    if (scale && bias) {
      const double det = n * sxx - sx * sx;
      if (det > 0) K = (n * sxy - sx * sy) / det, b = (sy - K * sx) / n;
    } else if (scale) {
      if (sxx > 0) K = sxy / sxx;
    } else if (bias) {
      b = (sy - sx) / n;
    }
    m.scale[i] = K;
    m.bias_rad_s[i] = b;
  }
  for (std::size_t k = 0; k < p.meas.size(); ++k)
    sse += (p.meas[k] - predicted(p.robot[k], m)).squaredNorm();
  return sse;
}

ImuGapModel fit_model(const GyroSamples& r, const calib::RobotRateSeries& rate,
                      const std::set<ImuGapEffect>& effects, const Eigen::Vector3d& rails,
                      const ImuGapOptions& o) {
  ImuGapModel m;
  if (effects.count(ImuGapEffect::kSaturation)) m.rail_rad_s = rails;
  if (!effects.count(ImuGapEffect::kTimeOffset)) {
    fit_at(r, rate, 0.0, effects, m);
    return m;
  }
  // Coarse grid of 10 steps, then the step around the best.
  const double coarse = 10.0 * o.time_offset_step_s;
  double best_dt = 0.0, best = 1e300;
  for (double dt = -o.max_abs_time_offset_s; dt <= o.max_abs_time_offset_s + 1e-12; dt += coarse) {
    ImuGapModel t = m;
    const double sse = fit_at(r, rate, dt, effects, t);
    if (sse < best) best = sse, best_dt = dt;
  }
  const double centre = best_dt;
  for (double dt = centre - coarse; dt <= centre + coarse + 1e-12; dt += o.time_offset_step_s) {
    ImuGapModel t = m;
    const double sse = fit_at(r, rate, dt, effects, t);
    if (sse < best) best = sse, best_dt = dt;
  }
  fit_at(r, rate, best_dt, effects, m);
  return m;
}

std::string size_of(ImuGapEffect e, const ImuGapModel& m) {
  switch (e) {
    case ImuGapEffect::kTimeOffset:
      return fmt::format("dt = {:.3f} s (sensor clock behind the robot's poses)", m.time_offset_s);
    case ImuGapEffect::kAxisMisalignment:
      return fmt::format("sensor axes turned {:.1f} deg from the tool axes",
                         Eigen::AngleAxisd(m.R_T_S).angle() * kDegPerRad);
    case ImuGapEffect::kScaleFactors:
      return fmt::format("scale factors x {:.3f}, y {:.3f}, z {:.3f}", m.scale.x(), m.scale.y(),
                         m.scale.z());
    case ImuGapEffect::kBias:
      return fmt::format("bias ({:.2f}, {:.2f}, {:.2f}) deg/s", m.bias_rad_s.x() * kDegPerRad,
                         m.bias_rad_s.y() * kDegPerRad, m.bias_rad_s.z() * kDegPerRad);
    case ImuGapEffect::kSaturation: {
      std::vector<std::string> axes;
      for (int i = 0; i < 3; ++i)
        if (m.rail_rad_s[i] < 1e299)
          axes.push_back(fmt::format("{} at {:.0f} deg/s", "xyz"[i], m.rail_rad_s[i] * kDegPerRad));
      return fmt::format("rails {}", fmt::join(axes, ", "));
    }
  }
  return "";
}

// White noise of the residual per axis: sample-to-sample differences of a smooth signal are
// tiny, those of white noise have variance 2 sigma² (neighbouring samples ~10 ms apart).
double noise_floor(const GyroSamples& r, const calib::RobotRateSeries& rate, const ImuGapModel& m) {
  double sum = 0.0;
  std::size_t n = 0;
  Eigen::Vector3d previous = Eigen::Vector3d::Zero();
  bool have = false;
  for (std::size_t k = 0; k < r.t_s.size(); ++k) {
    Eigen::Vector3d w_T;
    if (!calib::robot_rate_at(rate, r.t_s[k] - m.time_offset_s, w_T) || on_rail(r.w[k], m)) {
      have = false;
      continue;
    }
    const Eigen::Vector3d res = r.w[k] - predicted(w_T, m);
    if (have) sum += (res - previous).squaredNorm(), ++n;
    previous = res;
    have = true;
  }
  return n ? std::sqrt(sum / double(n) / 2.0 / 3.0) : 0.0;
}

}  // namespace

const char* to_string(ImuGapEffect effect) {
  switch (effect) {
    case ImuGapEffect::kTimeOffset:
      return "time_offset";
    case ImuGapEffect::kAxisMisalignment:
      return "axis_misalignment";
    case ImuGapEffect::kScaleFactors:
      return "scale_factors";
    case ImuGapEffect::kBias:
      return "bias";
    case ImuGapEffect::kSaturation:
      return "saturation";
  }
  return "?";
}

namespace {

double gap_rms(const GyroSamples& r, const calib::RobotRateSeries& rate, const ImuGapModel& m) {
  double sum = 0.0;
  std::size_t n = 0;
  for (std::size_t k = 0; k < r.t_s.size(); ++k) {
    Eigen::Vector3d w_T;
    if (!calib::robot_rate_at(rate, r.t_s[k] - m.time_offset_s, w_T)) continue;
    sum += (r.w[k] - predicted(w_T, m)).squaredNorm();
    ++n;
  }
  return n ? std::sqrt(sum / double(n)) : 0.0;
}

}  // namespace

double imu_gap_rms(const calib::ToolImuRecord& record, const calib::RobotRateSeries& rate,
                   const ImuGapModel& model) {
  return gap_rms(GyroSamples{record.t_s, record.gyro_rad_s}, rate, model);
}

namespace {

// The unit check's ratio |gyro as labelled| / |robot rate| when it calls the labelled unit wrong
// (further from 1 than the check's scale tolerance), else 1.
double unit_scale_of(const calib::ToolImuAnalysis& check, const ImuGapOptions& o) {
  const double ratio = check.gyro_scale_ratio;
  return ratio > 0.0 && std::abs(ratio - 1.0) > o.check.scale_tolerance ? ratio : 1.0;
}

GyroSamples divided(GyroSamples g, double unit_scale) {
  for (Eigen::Vector3d& w : g.w) w /= unit_scale;
  return g;
}

struct GapInputs {
  GyroSamples train, held;
  calib::RobotRateSeries rate_train, rate_held;
  Eigen::Vector3d rails;  // in the units the gap is measured in
};

// Effects added greedily while each shrinks the held-out gap by min_gain_percent; returns the
// held-out RMS after the last one kept.
double add_effects(const GapInputs& in, const ImuGapOptions& o, std::set<ImuGapEffect>& chosen,
                   ImuGapDiagnosis& d) {
  double current = d.heldout_rms_rad_s;
  const auto shrink = [&](double rms) { return 100.0 * (1.0 - rms / d.heldout_rms_rad_s); };
  for (;;) {
    int best = -1;
    double best_rms = current;
    ImuGapModel best_model;
    for (int e = 0; e < kImuGapEffectCount; ++e) {
      const auto effect = ImuGapEffect(e);
      if (chosen.count(effect)) continue;
      std::set<ImuGapEffect> trial = chosen;
      trial.insert(effect);
      const ImuGapModel m = fit_model(in.train, in.rate_train, trial, in.rails, o);
      const double rms = gap_rms(in.held, in.rate_held, m);
      if (rms < best_rms) best_rms = rms, best = e, best_model = m;
    }
    if (best < 0 || shrink(best_rms) - shrink(current) < o.min_gain_percent) break;
    chosen.insert(ImuGapEffect(best));
    current = best_rms;
    d.model = best_model;
    d.steps.push_back({ImuGapEffect(best), best_rms, shrink(best_rms), "", false});
  }
  for (auto& step : d.steps) {
    if (!step.from_unit_check) step.size = size_of(step.effect, d.model);
  }
  return current;
}

// The model for the gyro as labelled: the fit was made on the gyro divided by the unit scale.
void to_labelled_units(double unit_scale, ImuGapModel& m) {
  m.scale *= unit_scale;
  m.bias_rad_s *= unit_scale;
  for (int i = 0; i < 3; ++i) {
    if (m.rail_rad_s[i] < 1e299) m.rail_rad_s[i] *= unit_scale;
  }
}

std::string verdict_of(const ImuGapDiagnosis& d, double excluded_train, double excluded_held) {
  std::vector<std::string> found, absent;
  for (const auto& s : d.steps) {
    found.push_back(s.from_unit_check
                        ? fmt::format("{} ({})", to_string(s.effect), s.size)
                        : fmt::format("{} ({}; held-out gap {:.0f} % smaller)", to_string(s.effect),
                                      s.size, s.heldout_shrinkage_percent));
  }
  for (auto e : d.not_supported) absent.push_back(to_string(e));
  const double shrunk = 100.0 * (1.0 - d.heldout_rms_modelled_rad_s / d.heldout_rms_rad_s);
  return fmt::format(
      "Gyro gap (measured minus the rate of the robot's reported tool motion{}) on the held-out "
      "record: RMS {:.2f} deg/s before, {:.2f} deg/s once modelled ({:.0f} % smaller). Found, "
      "in order: {}. Not supported: {}. Left: sensor noise ~{:.2f} deg/s per axis (white part "
      "of the residual) and what the 15 Hz robot poses do not resolve. Left out as data "
      "defects (motion the sensor did not record, calib::check_tool_imu_record): {:.2f} s of "
      "the training and {:.2f} s of the held-out record.",
      d.unit_scale != 1.0 ? ", the gyro divided by the unit check's scale" : "",
      d.heldout_rms_rad_s * kDegPerRad, d.heldout_rms_modelled_rad_s * kDegPerRad, shrunk,
      found.empty() ? std::string("nothing") : fmt::format("{}", fmt::join(found, "; ")),
      absent.empty() ? std::string("none") : fmt::format("{}", fmt::join(absent, ", ")),
      d.heldout_noise_rad_s * kDegPerRad, excluded_train, excluded_held);
}

}  // namespace

ImuGapDiagnosis diagnose_imu_gap(const calib::ToolImuRecord& training,
                                 const calib::ToolImuRecord& heldout, const ImuGapOptions& o) {
  // The rails the record's own check confirms as clipping (training record only).
  const calib::ToolImuAnalysis check = calib::check_tool_imu_record(training, o.check);
  const calib::ToolImuAnalysis check_heldout = calib::check_tool_imu_record(heldout, o.check);
  ImuGapDiagnosis d;
  d.unit_scale = unit_scale_of(check, o);
  GapInputs in{{},
               {},
               calib::robot_tool_rate(training),
               calib::robot_tool_rate(heldout),
               Eigen::Vector3d::Constant(1e300)};
  const GyroSamples held_as_labelled = usable(heldout, check_heldout, d.excluded_heldout_s);
  in.train = divided(usable(training, check, d.excluded_training_s), d.unit_scale);
  in.held = divided(held_as_labelled, d.unit_scale);
  for (std::size_t i = 0; i < check.clipped_axes.size(); ++i)
    in.rails[check.clipped_axes[i]] = check.clipped_axis_rail_rad_s[i] / d.unit_scale;

  const ImuGapModel naive;
  d.heldout_rms_as_labelled_rad_s = gap_rms(held_as_labelled, in.rate_held, naive);
  d.training_rms_rad_s = gap_rms(in.train, in.rate_train, naive);
  d.heldout_rms_rad_s = gap_rms(in.held, in.rate_held, naive);
  if (d.unit_scale != 1.0) {
    d.steps.push_back(
        {ImuGapEffect::kScaleFactors, d.heldout_rms_rad_s, 0.0,
         fmt::format("unit check: the gyro reads {:.4f} x the robot's rate, 1/{:.1f} of the "
                     "labelled unit; the gap is measured after dividing by it",
                     d.unit_scale, 1.0 / d.unit_scale),
         true});
  }
  std::set<ImuGapEffect> chosen;
  d.heldout_rms_modelled_rad_s = add_effects(in, o, chosen, d);
  if (d.unit_scale != 1.0) chosen.insert(ImuGapEffect::kScaleFactors);
  for (int e = 0; e < kImuGapEffectCount; ++e)
    if (!chosen.count(ImuGapEffect(e))) d.not_supported.push_back(ImuGapEffect(e));
  d.heldout_noise_rad_s = noise_floor(in.held, in.rate_held, d.model);
  to_labelled_units(d.unit_scale, d.model);
  d.verdict = verdict_of(d, d.excluded_training_s, d.excluded_heldout_s);
  return d;
}

}  // namespace imscal::eval
