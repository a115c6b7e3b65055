#include "ims/mechanize_session.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>

#include "core/input_error.hpp"
#include "core/units.hpp"
#include "ims/coarse_alignment.hpp"
#include "ims/earth_model.hpp"
#include "ims/imu_conversion.hpp"
#include "ims/imu_file.hpp"
#include "ims/sensor_error_model.hpp"
#include "ims/sensor_spec.hpp"
#include "ims/strapdown.hpp"
#include "ims/zupt_smoother.hpp"

namespace imscal::ims {

namespace {

constexpr const char* kCommandLine = "<command line>";
using MechanizeArgs = MechanizeSessionOptions;

// Everything the mechanization starts from.
struct Prepared {
  ImuSeries increments;  // from the first sample after initial.t_s
  std::unique_ptr<EarthModel> earth;
  NavState initial;
  std::string attitude_source;
  Eigen::Vector3d attitude_sigma_rad = Eigen::Vector3d::Zero();  // E, N, U; from the alignment
};

// Three comma-separated finite numbers.
Eigen::Vector3d parse_triple(const std::string& text, const std::string& option,
                             const std::string& expected) {
  Eigen::Vector3d values;
  std::istringstream in(text);
  for (int i = 0; i < 3; ++i) {
    std::string token;
    const bool last = i == 2;
    if (!std::getline(in, token, last ? '\n' : ',')) {
      throw InputError(kCommandLine, 0, option,
                       fmt::format("expected {}, got '{}'", expected, text));
    }
    try {
      std::size_t used = 0;
      values[i] = std::stod(token, &used);
      if (used != token.size() || !std::isfinite(values[i])) throw std::invalid_argument(token);
    } catch (const std::exception&) {
      throw InputError(kCommandLine, 0, option,
                       fmt::format("'{}' is not a number (expected {})", token, expected));
    }
  }
  if (in.peek() != std::char_traits<char>::eof()) {
    throw InputError(kCommandLine, 0, option, fmt::format("expected {}, got '{}'", expected, text));
  }
  return values;
}

Site choose_site(const MechanizeArgs& args, const ImuSeries& series) {
  if (!args.site.empty()) {
    const Eigen::Vector3d v = parse_triple(args.site, "--site", "LAT,LON,H (deg, deg, m)");
    return Site{v.x(), v.y(), v.z()};
  }
  if (series.site) return *series.site;
  throw InputError(args.input, 0, "site",
                   "the file names no site; give --site LAT,LON,H (needed for the Earth "
                   "rate and gravity)");
}

// The record as increments, corrected with the unit's error model when one is given.
ImuSeries read_increments(const MechanizeArgs& args) {
  ImuSeries series = read_imu_file(args.input);
  if (series.samples.size() < 2) {
    throw InputError(args.input, 0, "", "fewer than two samples: nothing to mechanize");
  }
  if (series.quantity == ImuQuantity::kRates) {
    // The rectangle rule of ims/imu_conversion.hpp: errs by -(1/2) d(rate)/dt dt^2 per sample.
    spdlog::warn(
        "{} holds rates, not increments: converted by the rectangle rule, which is not "
        "exact for a changing rate (ims/imu_conversion.hpp)",
        args.input);
    series = rates_to_increments(series);
  }
  if (!args.sensor_errors.empty()) {
    // Error correction on read: the unit's calibration (bias, scale factor, misalignment).
    series = correct(series, load_sensor_error_model(args.sensor_errors));
    spdlog::info("corrected {} with the sensor error model {}", args.input, args.sensor_errors);
  }
  return series;
}

// The initial attitude from a coarse alignment over the first align_s of the record (at rest),
// its heading replaced by --heading-deg when given; returns the first sample after it.
std::size_t align_initial_state(const MechanizeArgs& args, const ImuSeries& series,
                                double record_start, Prepared& p) {
  const auto& samples = series.samples;
  if (!(*args.align_s > 0.0) || record_start + *args.align_s > samples.back().t_s) {
    throw InputError(kCommandLine, 0, "--align-s",
                     fmt::format("{} s is not inside the record ({} s long)", *args.align_s,
                                 samples.back().t_s - record_start));
  }
  CoarseAlignment alignment;
  try {
    alignment =
        align_at_rest(series, samples_in_interval(series, record_start, *args.align_s), *p.earth);
  } catch (const std::invalid_argument& e) {
    throw InputError(kCommandLine, 0, "--align-s", e.what());
  }
  // The alignment holds at t_ref (a sample time in the middle of the interval); the
  // trajectory starts there, at rest.
  p.initial.t_s = alignment.t_ref_s;
  p.initial.q_W_S = alignment.q_W_S;
  const double level_sigma = std::max(alignment.sigma_roll_rad, alignment.sigma_pitch_rad);
  p.attitude_sigma_rad = {level_sigma, level_sigma, alignment.sigma_heading_rad};
  if (args.heading_deg) {
    alignment.angles.heading_rad = *args.heading_deg * kRadPerDeg;
    alignment.sigma_heading_rad = args.heading_sigma_deg * kRadPerDeg;
    p.initial.q_W_S = Eigen::Quaterniond(R_W_S_from_angles(
        alignment.angles.roll_rad, alignment.angles.pitch_rad, -alignment.angles.heading_rad));
    p.attitude_sigma_rad.z() = alignment.sigma_heading_rad;
  }
  std::size_t first_sample = 0;
  while (first_sample < samples.size() && samples[first_sample].t_s <= alignment.t_ref_s) {
    ++first_sample;
  }
  p.attitude_source = fmt::format(
      "coarse alignment over the first {} s (roll {:.4f} +- {:.4f}, pitch {:.4f} +- {:.4f}, "
      "heading {:.4f} +- {:.4f} deg{})",
      *args.align_s, alignment.angles.roll_rad / kRadPerDeg, alignment.sigma_roll_rad / kRadPerDeg,
      alignment.angles.pitch_rad / kRadPerDeg, alignment.sigma_pitch_rad / kRadPerDeg,
      alignment.angles.heading_rad / kRadPerDeg, alignment.sigma_heading_rad / kRadPerDeg,
      args.heading_deg ? " from --heading-deg" : " by gyrocompassing");
  return first_sample;
}

Prepared prepare(const MechanizeArgs& args) {
  if (args.initial_attitude.empty() == !args.align_s.has_value()) {
    throw InputError(kCommandLine, 0, "--initial-attitude/--align-s",
                     "give exactly one of --initial-attitude ROLL,PITCH,HEADING_DEG and "
                     "--align-s SECONDS");
  }
  Prepared p;
  ImuSeries series = read_increments(args);
  try {
    p.earth = std::make_unique<EarthModel>(choose_site(args, series));
  } catch (const std::invalid_argument& e) {
    throw InputError(kCommandLine, 0, "--site", e.what());
  }
  const auto& samples = series.samples;
  const double first_dt =
      series.nominal_dt_s > 0.0 ? series.nominal_dt_s : samples[1].t_s - samples[0].t_s;
  const double record_start = samples.front().t_s - first_dt;
  std::size_t first_sample = 0;
  p.initial.t_s = record_start;
  if (!args.initial_attitude.empty()) {
    const Eigen::Vector3d deg =
        parse_triple(args.initial_attitude, "--initial-attitude", "ROLL,PITCH,HEADING (deg)");
    // Heading is clockwise from North; the angle convention's yaw counter-clockwise.
    p.initial.q_W_S = Eigen::Quaterniond(
        R_W_S_from_angles(deg.x() * kRadPerDeg, deg.y() * kRadPerDeg, -deg.z() * kRadPerDeg));
    p.attitude_source = "command line";
  } else {
    first_sample = align_initial_state(args, series, record_start, p);
  }
  p.increments = std::move(series);
  p.increments.samples.erase(p.increments.samples.begin(),
                             p.increments.samples.begin() + static_cast<long>(first_sample));
  return p;
}

// --smooth: zero-velocity-aided smoothing instead of the plain mechanization; starts at rest
// with the alignment's attitude sigma, zero velocity and the position that defines the origin.
MechanizedTrajectory smooth(const MechanizeArgs& args, const Prepared& p) {
  if (!args.align_s) {
    throw InputError(kCommandLine, 0, "--smooth",
                     "needs --align-s (the initial attitude and its 1-sigma)");
  }
  const SensorSpec spec = load_sensor_spec(args.smooth_spec);
  const ZuptOptions options = zupt_options_from_spec(spec);
  // Levelling at rest cannot tell tilt from a horizontal accelerometer bias: the tilt sigma is
  // at least the turn-on bias over g, whatever the noise of the alignment says.
  Eigen::Vector3d attitude_sigma = p.attitude_sigma_rad;
  const double bias_tilt_rad = spec.acc.turn_on_bias_sigma / p.earth->normal_gravity_magnitude();
  for (int i = 0; i < 2; ++i) attitude_sigma[i] = std::hypot(attitude_sigma[i], bias_tilt_rad);
  NavSigma initial_sigma;
  initial_sigma << attitude_sigma, Eigen::Vector3d::Constant(options.zero_velocity_sigma_m_s),
      Eigen::Vector3d::Zero();
  const ZuptSmootherResult result =
      smooth_with_zupt(p.increments, *p.earth, p.initial, initial_sigma, options);
  std::vector<NavState> states;
  std::vector<NavSigma> sigmas;
  for (const SmoothedState& s : result.states) {
    states.push_back(s.state);
    sigmas.push_back(s.sigma);
  }
  const auto& zv = result.summary.zero_velocity;
  const auto& zr = result.summary.zero_angular_rate;
  const std::string summary = fmt::format(
      "smoothed {} samples; {} rests; zero-velocity updates {} (gated {}, mean NIS {:.2f}), "
      "zero-rate updates {} (gated {}, mean NIS {:.2f}); final position sigma [{:.3e}, {:.3e}, "
      "{:.3e}] m\ninitial attitude: {}\n",
      states.size(), result.summary.rest_intervals.size(), zv.accepted, zv.rejected, zv.mean_nis,
      zr.accepted, zr.rejected, zr.mean_nis, sigmas.back()[6], sigmas.back()[7], sigmas.back()[8],
      p.attitude_source);
  return {std::move(states), std::move(sigmas), summary};
}

}  // namespace

MechanizedTrajectory mechanize_session(const MechanizeSessionOptions& args) {
  const Prepared p = prepare(args);
  if (!args.smooth_spec.empty()) return smooth(args, p);
  MechanizedTrajectory r;
  try {
    r.states = mechanize(p.increments, *p.earth, p.initial);
  } catch (const std::invalid_argument& e) {
    throw InputError(args.input, 0, "", e.what());
  }
  const NavState& last = r.states.back();
  r.summary = fmt::format(
      "mechanized {} samples ({:.3f} s) from {}\ninitial attitude: {}\nfinal position "
      "[{:.6f}, {:.6f}, {:.6f}] m, velocity [{:.6f}, {:.6f}, {:.6f}] m/s (W = ENU)\n",
      p.increments.samples.size(), last.t_s - p.initial.t_s, args.input, p.attitude_source,
      last.p_W.x(), last.p_W.y(), last.p_W.z(), last.v_W.x(), last.v_W.y(), last.v_W.z());
  return r;
}

}  // namespace imscal::ims
