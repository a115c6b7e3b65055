#include "ident/identification_config_record.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "core/input_error.hpp"
#include "ident/precontrol.hpp"

namespace imscal::ident {
namespace {

constexpr double kDefaultCycle_s = 0.002;  // the KR 16's interpolation cycle

[[noreturn]] void refuse(const IdentificationConfig& config, const std::string& key,
                         const std::string& problem) {
  const auto line = config.key_lines.find(key);
  throw InputError(config.file, line == config.key_lines.end() ? 0 : line->second, key, problem);
}

// The whole cycles of `seconds` at cycle_s, within [lowest, highest] (else refused naming key).
int cycles_of(const IdentificationConfig& config, const std::string& key, double seconds,
              double cycle_s, int lowest, int highest, std::vector<std::string>* warnings) {
  const double exact = seconds / cycle_s;
  const double count = std::round(exact);
  if (count < lowest || count > highest)
    refuse(config, key,
           fmt::format("{} s is {} cycles of {} s; the identification and the precontrol take {} "
                       "to {}",
                       seconds, count, cycle_s, lowest, highest));
  if (warnings && std::abs(exact - count) > 0.01 * std::max(1.0, count))
    warnings->push_back(fmt::format("{}: {} s is not a whole number of {} s cycles; taken as {}",
                                    key, seconds, cycle_s, count));
  return int(count);
}

bool given(double duration_s) {
  return !std::isnan(duration_s);
}

void check_precontrol_capacity(const IdentificationConfig& config, double cycle_s) {
  const JointIdentificationOptions& o = config.options;
  const int taps = longest_extra_input_taps(o);
  if (taps + o.grid.dead_time_max <= kMaxPrecontrolOrder) return;
  refuse(config, given(config.durations.input_history_s) ? "model.input_history_s" : "model",
         fmt::format("at {} s per cycle the further inputs take {} coefficients, plus the largest "
                     "dead time {} that is {}; the precontrol holds at most {}",
                     cycle_s, taps, o.grid.dead_time_max, taps + o.grid.dead_time_max,
                     kMaxPrecontrolOrder));
}

}  // namespace

void apply_durations(IdentificationConfig& config, double cycle_s,
                     std::vector<std::string>* warnings) {
  const ConfigDurations& d = config.durations;
  JointIdentificationOptions& o = config.options;
  if (given(d.preview_s))
    o.preview_cycles = cycles_of(config, "model.preview_s", d.preview_s, cycle_s, 0, 32, warnings);
  if (given(d.input_history_s))
    o.input_taps =
        cycles_of(config, "model.input_history_s", d.input_history_s, cycle_s, 1, 64, warnings);
  if (given(d.torque_sign_history_s))
    o.torque_sign_taps = cycles_of(config, "model.torque_sign_history_s", d.torque_sign_history_s,
                                   cycle_s, 1, 64, warnings);
  if (given(d.transmission_error_history_s))
    o.transmission_error_taps = cycles_of(config, "model.transmission_error_history_s",
                                          d.transmission_error_history_s, cycle_s, 1, 64, warnings);
  if (given(d.transmission_error_gear_mode_history_s))
    o.transmission_error_mode_taps =
        cycles_of(config, "model.transmission_error_gear_mode_history_s",
                  d.transmission_error_gear_mode_history_s, cycle_s, 1, 64, warnings);
  if (given(d.min_estimation_s))
    o.min_rows_per_cell = std::size_t(cycles_of(config, "cells.min_estimation_s",
                                                d.min_estimation_s, cycle_s, 1, 1 << 30, warnings));
  // Counts alone were checked on loading; durations give other counts at every cycle.
  if (given(d.input_history_s) || given(d.torque_sign_history_s) ||
      given(d.transmission_error_history_s) || given(d.transmission_error_gear_mode_history_s))
    check_precontrol_capacity(config, cycle_s);
  config.resolved_cycle_s = cycle_s;
}

IdentificationConfig resolve_for_record(IdentificationConfig config,
                                        const std::string& record_robot, double record_cycle_s,
                                        const std::string& record_file,
                                        std::vector<std::string>* warnings) {
  if (!config.robot.empty() && !record_robot.empty() && config.robot != record_robot)
    refuse(config, "robot",
           fmt::format("the config is for robot '{}' (its maximum speeds, gear data and payload "
                       "rating); {} is of robot '{}'",
                       config.robot, record_file, record_robot));
  const double counts_cycle_s =
      given(config.counts_cycle_s) ? config.counts_cycle_s : record_cycle_s;
  if (std::abs(counts_cycle_s - record_cycle_s) > 1e-9 * record_cycle_s)
    refuse(config, "cycle_s",
           fmt::format("the config's counts are in cycles of {} s; {} is sampled every {} s: "
                       "state durations in seconds (model.preview_s, model.input_history_s, "
                       "model.transmission_error_history_s, cells.min_estimation_s) or give a "
                       "config for this cycle",
                       config.counts_cycle_s, record_file, record_cycle_s));
  if (warnings && !given(config.counts_cycle_s) &&
      std::abs(record_cycle_s - kDefaultCycle_s) > 1e-9 * kDefaultCycle_s)
    warnings->push_back(fmt::format(
        "{}: no cycle_s: its counts (order grid, validation.max_lag and any *_cycles, *_taps, "
        "min_rows key) are taken in cycles of {} s, the record's",
        config.file, record_cycle_s));
  apply_durations(config, record_cycle_s, warnings);
  return config;
}

}  // namespace imscal::ident
