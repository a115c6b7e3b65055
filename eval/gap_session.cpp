#include "eval/gap_session.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include "core/input_error.hpp"
#include "core/payload_plausibility.hpp"
#include "eval/joint_error_limits.hpp"
#include "eval/model_joint_errors.hpp"
#include "ident/joint_error_io.hpp"
#include "ident/parameter_table_io.hpp"
#include "robot/robot_description.hpp"
#include "sim/scenario.hpp"

namespace imscal::eval {

namespace {

// The sim's joint errors from the second joint_errors.csv, row by row with the real ones.
std::vector<std::vector<double>> sim_log_joint_errors(const GapSessionOptions& args,
                                                      const ident::JointErrorLog& real) {
  const ident::JointErrorLog sim = ident::read_joint_errors_csv(args.sim_joint_errors);
  if (sim.joint_names != real.joint_names || sim.sample_count() != real.sample_count())
    throw InputError(args.sim_joint_errors, sim.first_data_line, "",
                     fmt::format("{} samples of joints {}; the real joint errors have {} "
                                 "samples of joints {} (they must match row by row)",
                                 sim.sample_count(), fmt::join(sim.joint_names, ","),
                                 real.sample_count(), fmt::join(real.joint_names, ",")));
  for (std::size_t k = 0; k < sim.sample_count(); ++k)
    if (std::abs(sim.time_s[k] - real.time_s[k]) > 0.25 * real.cycle_s)
      throw InputError(
          args.sim_joint_errors, sim.first_data_line + k, "t_s",
          fmt::format("{} s where the real joint errors have {} s", sim.time_s[k], real.time_s[k]));
  return measured_joint_errors(sim);
}

// The IMS chain's error budget: the floor from the real joint errors' header, the frames'
// covariance from --frames. Frames without a floor cannot be tested: refused.
MeasurementPrior measurement_prior(const GapSessionOptions& args,
                                   const ident::JointErrorLog& real) {
  MeasurementPrior prior;
  prior.noise_floor_rad = noise_floor_from_log(real, args.joint_errors);
  if (!args.frames.empty()) {
    if (!prior.known())
      throw InputError(args.joint_errors, 0, kNoiseFloorKey,
                       "no IMS noise floor in the header (imscal calibrate writes it), so the "
                       "frames' covariance cannot be tested against it");
    prior.covariance_si = chain_covariance_from_frames(args.frames, real.joint_names);
  }
  prior.source = !prior.known()        ? ""
                 : args.frames.empty() ? fmt::format("noise floor of {}", args.joint_errors)
                                       : fmt::format("noise floor of {}, frames of {}",
                                                     args.joint_errors, args.frames);
  if (!prior.known())
    spdlog::info(
        "diagnose: {} has no IMS noise floor ({}): the gap is not tested against the "
        "measurement's own error",
        args.joint_errors, kNoiseFloorKey);
  return prior;
}

}  // namespace

namespace {

// A record longer than max_s [s]: its analysed windows only (eval/gap_windows.hpp), in both the
// real joint errors and the sim's.
void keep_analysed_windows(double max_s, ident::JointErrorLog& real,
                           std::vector<std::vector<double>>& sim_errors,
                           std::optional<NominalPlant>& nominal) {
  AnalysisWindows windows;
  windows.max_s = max_s;
  const std::vector<bool> keep = analysed_samples(real.time_s, windows);
  const auto kept = std::size_t(std::count(keep.begin(), keep.end(), true));
  if (kept == keep.size()) return;
  std::size_t windows_count = 0;
  for (std::size_t k = 0; k < keep.size(); ++k)
    windows_count += keep[k] && (k == 0 || !keep[k - 1]);
  spdlog::info(
      "diagnose: a {:.0f} s record: analysed on {} windows spread over it, {} of {} "
      "samples (--max-analysed-s {})",
      real.time_s.back() - real.time_s.front(), windows_count, kept, keep.size(), max_s);
  real = keep_samples(real, keep);
  sim_errors = keep_samples(sim_errors, keep);
  if (!nominal) return;
  std::vector<std::size_t> kept_samples;
  for (std::size_t k = 0; k < keep.size(); ++k)
    if (keep[k]) kept_samples.push_back(nominal->samples[k]);
  nominal->samples = std::move(kept_samples);
}

// The nominal model of --scenario as the refinement's simulator (its nominal robot, never its
// plant), along the real record's desired path; none without --scenario.
std::optional<NominalPlant> scenario_nominal_plant(const GapSessionOptions& args,
                                                   const ident::JointErrorLog& real,
                                                   const calib::RobotDescription& robot) {
  if (args.scenario.empty()) return std::nullopt;
  const sim::Scenario scenario = sim::load_scenario(sim::resolve_scenario(args.scenario));
  const sim::NominalRobot nominal = sim::load_nominal_robot(scenario);
  if (nominal.description.name != robot.name)
    throw InputError(args.scenario, 0, "nominal_robot",
                     fmt::format("'{}', but --robot {} is '{}'", nominal.description.name,
                                 args.robot, robot.name));
  try {
    return nominal_plant_along(real, nominal, &scenario);
  } catch (const std::invalid_argument& e) {
    throw InputError(args.joint_errors, 0, "robot", e.what());
  }
}

}  // namespace

GapSession diagnose_gap_session(const GapSessionOptions& args) {
  ident::JointErrorLog real = ident::read_joint_errors_csv(args.joint_errors);
  const calib::RobotDescription robot = calib::load_robot_description(args.robot);
  if (robot.name != real.robot)
    throw InputError(args.joint_errors, 2, "robot",
                     fmt::format("'{}', but the robot file {} describes '{}'", real.robot,
                                 args.robot, robot.name));
  check_payload_series(
      real.payload_kg, real.time_s, robot.nominal_payload_kg,
      {args.joint_errors, 0, "payload_kg", fmt::format("robot {} ({})", robot.name, robot.source)});
  check_joint_error_limits(real, args.joint_errors, robot);
  if (!real.has_q_internal())
    spdlog::warn(
        "{}: no q_internal_<joint>_rad columns (motor encoders): the transmission error "
        "is not tried, the friction and payload candidates follow q_desired",
        args.joint_errors);
  std::vector<std::vector<double>> sim_errors;
  std::optional<ident::ParameterTable> table;
  if (!args.table.empty()) {
    table = ident::read_parameters_json(args.table);
    if (table->sample_time_s != real.cycle_s)
      throw InputError(args.table, 0, "sample_time_s",
                       fmt::format("{} s, but {} has cycle_s {} s", table->sample_time_s,
                                   args.joint_errors, real.cycle_s));
    try {
      sim_errors = predict_table_joint_errors(*table, real);
    } catch (const std::invalid_argument& e) {
      throw InputError(args.table, 0, "joints", e.what());
    }
  } else {
    sim_errors = sim_log_joint_errors(args, real);
  }
  const MeasurementPrior measurement = measurement_prior(args, real);
  std::optional<NominalPlant> nominal = scenario_nominal_plant(args, real, robot);
  keep_analysed_windows(args.max_analysed_s, real, sim_errors, nominal);
  GapSession session;
  try {
    session.signals = make_gap_signals(real, sim_errors, robot, table ? &*table : nullptr);
  } catch (const std::invalid_argument& e) {
    throw InputError(args.robot, 0, "joints", e.what());
  }
  session.signals.measurement = measurement;
  spdlog::info("diagnose: {} samples, {} joints, gap RMS to be analysed",
               session.signals.sample_count(), session.signals.joint_count());
  session.diagnosis = diagnose_gap(session.signals, {}, nominal ? &*nominal : nullptr);
  return session;
}

}  // namespace imscal::eval
