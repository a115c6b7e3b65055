// `imscal mechanize`: strapdown mechanization of a raw IMS record (ims/strapdown.hpp) into the
// trajectory of the sensor frame S in W, written as DIR/trajectory.csv and DIR/trajectory.tum
// (ims/nav_trajectory_io.hpp).
//
// The initial attitude comes either from the command line (--initial-attitude, angles as in
// ims/coarse_alignment.hpp) or from a coarse alignment over the first seconds of the record,
// which must then be at rest (--align-s). Position and velocity start at zero.
//
// The work is in three stages, prepare -> mechanize -> write, so that a later stage (e.g.
// zero-velocity smoothing, which also yields 1-sigma columns) slots in between the last two.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "core/atomic_file.hpp"
#include "core/input_error.hpp"
#include "core/output_folder.hpp"
#include "core/units.hpp"
#include "ims/coarse_alignment.hpp"
#include "ims/earth_model.hpp"
#include "ims/imu_conversion.hpp"
#include "ims/imu_file.hpp"
#include "ims/mechanization_start.hpp"
#include "ims/nav_trajectory_io.hpp"
#include "ims/sensor_error_model.hpp"
#include "ims/sensor_spec.hpp"
#include "ims/strapdown.hpp"
#include "ims/zupt_smoother.hpp"
#include "tools/command_registry.hpp"

namespace {

using imscal::kRadPerDeg;

namespace fs = std::filesystem;
namespace ims = imscal::ims;
constexpr const char* kCommandLine = "<command line>";

struct MechanizeArgs {
  std::string input;
  std::string out_dir;
  std::string initial_attitude;  // "ROLL,PITCH,HEADING" [deg]
  std::optional<double> align_s;
  std::string site;
  std::string smooth_spec;    // sensor spec YAML: zero-velocity smoothing (ims/zupt_smoother.hpp)
  std::string sensor_errors;  // sensor error model YAML applied on read (ims/sensor_error_model)
  // Heading from an external reference, replacing the gyrocompassed one: a few seconds of
  // gyrocompassing give degrees (sigma ~ gyro noise / horizontal Earth rate).
  std::optional<double> heading_deg;
  double heading_sigma_deg = 0.001;
  bool force = false;
};

using Prepared = ims::MechanizationStart;

// Three comma-separated finite numbers.
Eigen::Vector3d parse_triple(const std::string& text, const std::string& option,
                             const std::string& expected) {
  Eigen::Vector3d values;
  std::istringstream in(text);
  for (int i = 0; i < 3; ++i) {
    std::string token;
    const bool last = i == 2;
    if (!std::getline(in, token, last ? '\n' : ',')) {
      throw imscal::InputError(kCommandLine, 0, option,
                               fmt::format("expected {}, got '{}'", expected, text));
    }
    try {
      std::size_t used = 0;
      values[i] = std::stod(token, &used);
      if (used != token.size() || !std::isfinite(values[i])) throw std::invalid_argument(token);
    } catch (const std::exception&) {
      throw imscal::InputError(kCommandLine, 0, option,
                               fmt::format("'{}' is not a number (expected {})", token, expected));
    }
  }
  if (in.peek() != std::char_traits<char>::eof()) {
    throw imscal::InputError(kCommandLine, 0, option,
                             fmt::format("expected {}, got '{}'", expected, text));
  }
  return values;
}

Prepared prepare(const MechanizeArgs& args) {
  ims::MechanizationRequest request;
  request.input = args.input;
  if (!args.initial_attitude.empty()) {
    request.initial_attitude_deg =
        parse_triple(args.initial_attitude, "--initial-attitude", "ROLL,PITCH,HEADING (deg)");
  }
  request.align_s = args.align_s;
  if (!args.site.empty()) {
    const Eigen::Vector3d v = parse_triple(args.site, "--site", "LAT,LON,H (deg, deg, m)");
    request.site = ims::Site{v.x(), v.y(), v.z()};
  }
  request.sensor_errors = args.sensor_errors;
  request.heading_deg = args.heading_deg;
  request.heading_sigma_deg = args.heading_sigma_deg;
  request.origin = kCommandLine;
  return ims::prepare_mechanization(request);
}

// Both outputs, refused before any work when they exist and --force is not given.
struct Outputs {
  fs::path csv;
  fs::path tum;
};

Outputs check_outputs(const MechanizeArgs& args) {
  const fs::path dir(args.out_dir);
  Outputs o{dir / "trajectory.csv", dir / "trajectory.tum"};
  if (!args.force) {
    for (const fs::path& f : {o.csv, o.tum}) {
      if (fs::exists(f)) {
        throw imscal::InputError(kCommandLine, 0, "--out",
                                 f.string() + " exists; give --force to overwrite it");
      }
    }
  }
  return o;
}

void write_outputs(const Outputs& o, const std::vector<ims::NavState>& states,
                   const std::vector<ims::NavSigma>* sigmas, bool force) {
  // Both or neither: staged together and published together.
  const fs::path dir = o.csv.parent_path().empty() ? fs::path(".") : o.csv.parent_path();
  imscal::OutputFolder folder(dir, {o.csv.filename(), o.tum.filename()},
                              force ? imscal::Overwrite::kAllow : imscal::Overwrite::kRefuse);
  ims::write_trajectory_csv(folder.staged(o.csv.filename()), states, sigmas,
                            imscal::Overwrite::kAllow);
  ims::write_trajectory_tum(folder.staged(o.tum.filename()), states, imscal::Overwrite::kAllow);
  folder.commit();
}

// --smooth: zero-velocity-aided smoothing instead of the plain mechanization; starts at rest
// with the alignment's attitude sigma, zero velocity and the position that defines the origin.
void smooth(const MechanizeArgs& args, const Outputs& outputs, const Prepared& p) {
  if (!args.align_s) {
    throw imscal::InputError(kCommandLine, 0, "--smooth",
                             "needs --align-s (the initial attitude and its 1-sigma)");
  }
  const ims::SensorSpec spec = ims::load_sensor_spec(args.smooth_spec);
  const ims::ZuptOptions options = ims::zupt_options_from_spec(spec);
  // Levelling at rest cannot tell tilt from a horizontal accelerometer bias: the tilt sigma is
  // at least the turn-on bias over g, whatever the noise of the alignment says.
  Eigen::Vector3d attitude_sigma = p.attitude_sigma_rad;
  const double bias_tilt_rad = spec.acc.turn_on_bias_sigma / p.earth->normal_gravity_magnitude();
  for (int i = 0; i < 2; ++i) attitude_sigma[i] = std::hypot(attitude_sigma[i], bias_tilt_rad);
  ims::NavSigma initial_sigma;
  initial_sigma << attitude_sigma, Eigen::Vector3d::Constant(options.zero_velocity_sigma_m_s),
      Eigen::Vector3d::Zero();
  const ims::ZuptSmootherResult result =
      ims::smooth_with_zupt(p.increments, *p.earth, p.initial, initial_sigma, options);
  std::vector<ims::NavState> states;
  std::vector<ims::NavSigma> sigmas;
  for (const ims::SmoothedState& s : result.states) {
    states.push_back(s.state);
    sigmas.push_back(s.sigma);
  }
  write_outputs(outputs, states, &sigmas, args.force);
  const auto& zv = result.summary.zero_velocity;
  const auto& zr = result.summary.zero_angular_rate;
  std::cout << fmt::format(
      "smoothed {} samples; {} rests; zero-velocity updates {} (gated {}, mean NIS {:.2f}), "
      "zero-rate updates {} (gated {}, mean NIS {:.2f}); final position sigma [{:.3e}, {:.3e}, "
      "{:.3e}] m\ninitial attitude: {}\nwritten: {}\nwritten: {}\n",
      states.size(), result.summary.rest_intervals.size(), zv.accepted, zv.rejected, zv.mean_nis,
      zr.accepted, zr.rejected, zr.mean_nis, sigmas.back()[6], sigmas.back()[7], sigmas.back()[8],
      p.attitude_source, outputs.csv.string(), outputs.tum.string());
}

void run(const MechanizeArgs& args) {
  const Outputs outputs = check_outputs(args);
  const Prepared p = prepare(args);
  if (!args.smooth_spec.empty()) return smooth(args, outputs, p);
  std::vector<ims::NavState> states;
  try {
    states = ims::mechanize(p.increments, *p.earth, p.initial);
  } catch (const std::invalid_argument& e) {
    throw imscal::InputError(args.input, 0, "", e.what());
  }
  write_outputs(outputs, states, nullptr, args.force);

  const ims::NavState& last = states.back();
  std::cout << fmt::format(
      "mechanized {} samples ({:.3f} s) from {}\ninitial attitude: {}\nfinal position "
      "[{:.6f}, {:.6f}, {:.6f}] m, velocity [{:.6f}, {:.6f}, {:.6f}] m/s (W = ENU)\nwritten: "
      "{}\nwritten: {}\n",
      p.increments.samples.size(), last.t_s - p.initial.t_s, args.input, p.attitude_source,
      last.p_W.x(), last.p_W.y(), last.p_W.z(), last.v_W.x(), last.v_W.y(), last.v_W.z(),
      outputs.csv.string(), outputs.tum.string());
}

imscal::tools::CommandRegistration registration{
    "mechanize",
    "Strapdown mechanization of an IMS record into a trajectory (trajectory.csv, .tum)",
    [](CLI::App& sub) {
      auto args = std::make_shared<MechanizeArgs>();
      sub.add_option("--input", args->input, "Raw IMS file (.csv, .imsb, .imu PSINS)")->required();
      sub.add_option("--out", args->out_dir, "Output folder (created if missing)")->required();
      auto* attitude = sub.add_option(
          "--initial-attitude", args->initial_attitude,
          "ROLL,PITCH,HEADING in deg (heading clockwise from North, ims/coarse_alignment.hpp)");
      auto* align = sub.add_option("--align-s", args->align_s,
                                   "Coarse alignment over the first SECONDS of the record (at "
                                   "rest); the trajectory starts in its middle");
      attitude->excludes(align);
      sub.add_option("--site", args->site,
                     "LAT,LON,H (deg, deg, m, WGS84) if the file names no site or to override it");
      sub.add_option("--smooth", args->smooth_spec,
                     "Sensor spec YAML: zero-velocity-aided smoothing with 1-sigma columns "
                     "(needs --align-s)");
      sub.add_option("--sensor-errors", args->sensor_errors,
                     "Sensor error model YAML (bias, scale factor, misalignment) to correct the "
                     "raw data with on read (datasets/FORMAT.md)");
      sub.add_option("--heading-deg", args->heading_deg,
                     "Initial heading from an external reference (deg clockwise from North of "
                     "the sensor's +Y axis), replacing gyrocompassing; with --align-s");
      sub.add_option("--heading-sigma-deg", args->heading_sigma_deg,
                     "1-sigma of --heading-deg (deg)")
          ->capture_default_str();
      sub.add_flag("--force", args->force, "Overwrite existing outputs");
      sub.callback([args] { run(*args); });
    }};

}  // namespace
