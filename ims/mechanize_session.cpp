#include "ims/mechanize_session.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>

#include "core/input_error.hpp"
#include "ims/earth_model.hpp"
#include "ims/mechanization_start.hpp"
#include "ims/sensor_spec.hpp"
#include "ims/strapdown.hpp"
#include "ims/zupt_smoother.hpp"

namespace imscal::ims {

namespace {

constexpr const char* kCommandLine = "<command line>";
using MechanizeArgs = MechanizeSessionOptions;

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

// The options as the start of a mechanization (ims/mechanization_start.hpp) asks for them.
MechanizationRequest request_of(const MechanizeArgs& args) {
  MechanizationRequest request;
  request.input = args.input;
  if (!args.initial_attitude.empty())
    request.initial_attitude_deg =
        parse_triple(args.initial_attitude, "--initial-attitude", "ROLL,PITCH,HEADING (deg)");
  request.align_s = args.align_s;
  if (!args.site.empty()) {
    const Eigen::Vector3d v = parse_triple(args.site, "--site", "LAT,LON,H (deg, deg, m)");
    request.site = Site{v.x(), v.y(), v.z()};
  }
  request.sensor_errors = args.sensor_errors;
  request.heading_deg = args.heading_deg;
  request.heading_sigma_deg = args.heading_sigma_deg;
  request.origin = kCommandLine;
  return request;
}

// --smooth: zero-velocity-aided smoothing instead of the plain mechanization; starts at rest
// with the alignment's attitude sigma, zero velocity and the position that defines the origin.
MechanizedTrajectory smooth(const MechanizeArgs& args, const MechanizationStart& p) {
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
  const MechanizationStart p = prepare_mechanization(request_of(args));
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
