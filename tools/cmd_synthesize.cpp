// `imscal synthesize`: raw IMS data of a known motion, as a given kind of sensor would record
// it, with the truth beside it:
//   DIR/imu.csv                  increments with drawn sensor errors and noise (ims/imu_csv.hpp;
//                                --imu-format imsb writes the binary DIR/imu.imsb instead)
//   DIR/truth/trajectory.csv     the motion at begin_s and at the sample times
//                                (ims/nav_trajectory_io.hpp)
//   DIR/truth/sensor_errors.yaml the drawn deterministic errors (ims/sensor_error_model.hpp)
// Same seed, same files. Nothing is written if any output exists (unless --force) or if any
// input is bad.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <filesystem>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "core/atomic_file.hpp"
#include "core/input_error.hpp"
#include "core/output_folder.hpp"
#include "ims/analytic_trajectory.hpp"
#include "ims/imu_file.hpp"
#include "ims/imu_noise.hpp"
#include "ims/imu_synthesis.hpp"
#include "ims/nav_trajectory_io.hpp"
#include "ims/sensor_spec.hpp"
#include "tools/command_registry.hpp"

namespace {
namespace fs = std::filesystem;
using namespace imscal;

struct SynthesizeArgs {
  std::string motion;
  std::string sensor;
  std::string site;
  double rate_hz = 1000.0;
  std::uint64_t seed = 1;
  std::string out;
  std::string imu_format = "csv";  // csv or imsb (ims/imu_file.hpp)
  bool force = false;
};

ims::Site parse_site(const std::string& text) {
  double values[3];
  std::istringstream in(text);
  for (double& value : values) {
    std::string token;
    std::size_t used = 0;
    bool ok = static_cast<bool>(std::getline(in, token, ','));
    try {
      if (ok) value = std::stod(token, &used);
    } catch (const std::exception&) {
      ok = false;
    }
    if (!ok || used != token.size() || !std::isfinite(value)) {
      throw InputError("<command line>", 0, "--site",
                       "expected LAT,LON,H (deg, deg, m), got '" + text + "'");
    }
  }
  std::string rest;
  if (std::getline(in, rest)) {
    throw InputError("<command line>", 0, "--site", "expected exactly 3 numbers LAT,LON,H");
  }
  if (std::abs(values[0]) > 90.0) {
    throw InputError("<command line>", 0, "--site", "latitude must be within +-90 deg");
  }
  return {values[0], values[1], values[2]};
}

// The truth at begin_s (the state before the first increment) and at every IMS sample time.
std::vector<ims::NavState> truth_states(const ims::Trajectory& traj, const ims::ImuSeries& series) {
  std::vector<ims::NavState> states;
  states.reserve(series.samples.size() + 1);
  auto add = [&](double t) {
    const ims::KinematicState s = traj.at(t);
    states.push_back({t, s.q_W_S, s.v_W, s.p_W});
  };
  add(traj.begin_s());
  for (const auto& sample : series.samples) add(sample.t_s);
  return states;
}

void run(const SynthesizeArgs& args) {
  if (!(args.rate_hz > 0.0) || !std::isfinite(args.rate_hz)) {
    throw InputError("<command line>", 0, "--rate-hz", "expected a positive rate");
  }
  const fs::path out(args.out);
  const fs::path imu_file = out / ("imu." + args.imu_format);
  const auto motion = ims::load_motion_file(args.motion);
  const ims::SensorSpec spec = ims::load_sensor_spec(args.sensor);
  const ims::EarthModel earth(parse_site(args.site));
  // All three or none: staged, then published together.
  OutputFolder folder(out,
                      {imu_file.filename(), fs::path("truth") / "trajectory.csv",
                       fs::path("truth") / "sensor_errors.yaml"},
                      args.force ? Overwrite::kAllow : Overwrite::kRefuse);

  const ims::ImuSeries ideal = ims::synthesize_ideal_increments(*motion, earth, args.rate_hz);
  // One generator: first the unit's errors, then the seed of its noise.
  std::mt19937_64 rng(args.seed);
  const ims::SensorErrorModel errors = ims::draw_sensor_errors(spec, rng);
  ims::ImuSeries raw = ims::corrupt(ideal, errors, spec, rng());
  raw.metadata = {{"sensor", spec.name},
                  {"motion", fs::path(args.motion).filename().string()},
                  {"seed", std::to_string(args.seed)},
                  {"generator", "imscal synthesize"}};

  ims::write_imu_file(folder.staged(imu_file.filename()), raw, Overwrite::kAllow);
  ims::write_trajectory_csv(folder.staged(fs::path("truth") / "trajectory.csv"),
                            truth_states(*motion, ideal), nullptr, Overwrite::kAllow);
  write_file_atomically(
      folder.staged(fs::path("truth") / "sensor_errors.yaml"),
      fmt::format("# Drawn errors of the synthesised unit '{}', seed {}\n", spec.name, args.seed) +
          ims::to_yaml(errors));
  folder.commit();
  spdlog::info("synthesised {} samples ({:.3f} s at {} Hz) of '{}' into {}", raw.samples.size(),
               motion->end_s() - motion->begin_s(), args.rate_hz, spec.name, out.string());
}

tools::CommandRegistration registration{
    "synthesize", "Synthesise a raw IMS record (and its truth) from a motion and a sensor spec",
    [](CLI::App& sub) {
      auto args = std::make_shared<SynthesizeArgs>();
      sub.add_option("--motion", args->motion, "Motion YAML (datasets/motions/*.yaml)")->required();
      sub.add_option("--sensor", args->sensor, "Sensor spec YAML (datasets/sensors/*.yaml)")
          ->required();
      sub.add_option("--site", args->site, "Site LAT,LON,H [deg, deg, m] (WGS84)")->required();
      sub.add_option("--rate-hz", args->rate_hz, "IMS sample rate [Hz]")->capture_default_str();
      sub.add_option("--seed", args->seed, "Seed of the sensor errors and noise")
          ->capture_default_str();
      sub.add_option("--out", args->out, "Output directory")->required();
      sub.add_option("--imu-format", args->imu_format, "Raw IMS file format: csv or imsb (binary)")
          ->check(CLI::IsMember({"csv", "imsb"}))
          ->capture_default_str();
      sub.add_flag("--force", args->force, "Replace existing outputs");
      sub.callback([args] { run(*args); });
    }};
}  // namespace
