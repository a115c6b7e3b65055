#include "robot/robot_log.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <exception>
#include <span>

#include "core/csv_text.hpp"
#include "core/input_error.hpp"
#include "core/numeric_table.hpp"
#include "core/units.hpp"

namespace imscal::calib {
namespace {

// Finds `<prefix>_<joint>_rad` or `<prefix>_<joint>_deg`; returns the column and the factor to rad.
std::pair<std::size_t, double> angle_column(const NumericTable& table, const std::string& prefix,
                                            const std::string& joint, bool& used_degrees) {
  const std::string base = prefix + "_" + joint;
  for (std::size_t c = 0; c < table.columns.size(); ++c) {
    if (table.columns[c] == base + "_rad") return {c, 1.0};
    if (table.columns[c] == base + "_deg") {
      used_degrees = true;
      return {c, kRadPerDeg};
    }
  }
  throw InputError(table.file, table.header_line, base + "_rad",
                   "missing column '" + base + "_rad' (or '" + base + "_deg')");
}

}  // namespace

std::string format_robot_log_csv(const RobotLog& log) {
  std::string text =
      fmt::format("# imscal-robot-log: 1\n# robot: {}\n# cycle_s: {}\nt_s,payload_kg",
                  log.robot_name, csv::format_shortest(log.cycle_s));
  for (const char* prefix : {"q_desired", "q_internal"}) {
    for (const std::string& joint : log.joint_names)
      text += fmt::format(",{}_{}_rad", prefix, joint);
  }
  text += '\n';
  for (const RobotLogSample& s : log.samples) {
    csv::append_shortest(text, s.t_s);
    text += ',';
    csv::append_shortest(text, s.payload_kg);
    for (const JointVector* q : {&s.q_desired_rad, &s.q_internal_rad}) {
      for (int j = 0; j < kJointCount; ++j) {
        text += ',';
        csv::append_shortest(text, (*q)[j]);
      }
    }
    text += '\n';
  }
  return text;
}

void write_robot_log_csv(const std::filesystem::path& file, const RobotLog& log,
                         Overwrite overwrite) {
  write_file_atomically(file, format_robot_log_csv(log), overwrite);
}

namespace {

// Where the log's values are in a row: column and factor to rad of each angle.
struct LogColumns {
  std::size_t time = 0, payload = 0;
  std::array<std::pair<std::size_t, double>, kJointCount> desired{}, internal{};
  bool used_degrees = false;
};

// The header's checks (version, robot, cycle, columns); the log's name, cycle and joints.
LogColumns read_log_header(const NumericTable& table, const std::string& expected_robot,
                           const std::string& expected_by, RobotLog& log) {
  if (table.meta("imscal-robot-log") != "1") {
    throw InputError(table.file, table.meta_line("imscal-robot-log"), "imscal-robot-log",
                     "unknown version '" + table.meta("imscal-robot-log") + "' (this reader: 1)");
  }
  log.robot_name = table.meta("robot");
  if (!expected_robot.empty() && log.robot_name != expected_robot) {
    throw InputError(table.file, table.meta_line("robot"), "robot",
                     fmt::format("the log is of robot '{}', {} is for robot '{}'", log.robot_name,
                                 expected_by, expected_robot));
  }
  if (!csv::parse_number(table.meta("cycle_s"), log.cycle_s) || !(log.cycle_s > 0.0) ||
      log.cycle_s > 1.0) {
    throw InputError(table.file, table.meta_line("cycle_s"), "cycle_s",
                     "'" + table.meta("cycle_s") + "' is not a cycle time in s (0 < cycle <= 1)");
  }
  // Joint names: from the q_desired_<name>_rad|deg columns, in file order.
  int found = 0;
  for (const std::string& name : table.columns) {
    if (!name.starts_with("q_desired_")) continue;
    const std::size_t unit_at = name.rfind('_');
    const std::string unit = name.substr(unit_at + 1);
    if (unit_at <= 10 || (unit != "rad" && unit != "deg")) {
      throw InputError(table.file, table.header_line, name,
                       "unknown unit '" + unit + "' of a joint angle; accepted: _rad, _deg");
    }
    const std::string joint = name.substr(10, unit_at - 10);
    if (found < kJointCount) log.joint_names[found] = joint;
    ++found;
  }
  if (found != kJointCount) {
    throw InputError(table.file, table.header_line, "q_desired_*",
                     fmt::format("{} q_desired columns, expected {}", found, kJointCount));
  }
  LogColumns columns;
  columns.time = table.column("t_s");
  columns.payload = table.column("payload_kg");
  for (int j = 0; j < kJointCount; ++j) {
    columns.desired[j] = angle_column(table, "q_desired", log.joint_names[j], columns.used_degrees);
    columns.internal[j] =
        angle_column(table, "q_internal", log.joint_names[j], columns.used_degrees);
  }
  const std::size_t expected_columns = 2 + 2 * kJointCount;
  if (table.columns.size() != expected_columns) {
    throw InputError(table.file, table.header_line, "",
                     fmt::format("{} columns, expected {} (t_s, payload_kg, 6 desired and 6 "
                                 "internal joint angles)",
                                 table.columns.size(), expected_columns));
  }
  return columns;
}

// One data row into the log, with its checks (payload, time step against the cycle).
void add_log_row(std::span<const double> values, std::size_t line, const LogColumns& columns,
                 const std::string& file, RobotLog& log) {
  RobotLogSample& s = log.samples.emplace_back();
  log.sample_lines.push_back(line);
  s.t_s = values[columns.time];
  s.payload_kg = values[columns.payload];
  if (s.payload_kg < 0.0) throw InputError(file, line, "payload_kg", "negative payload");
  for (int j = 0; j < kJointCount; ++j) {
    s.q_desired_rad[j] = values[columns.desired[j].first] * columns.desired[j].second;
    s.q_internal_rad[j] = values[columns.internal[j].first] * columns.internal[j].second;
  }
  if (log.samples.size() == 1) return;
  const double previous = log.samples[log.samples.size() - 2].t_s;
  const double step = s.t_s - previous;
  if (!(step > 0.0)) {
    throw InputError(
        file, line, "t_s",
        fmt::format("time {} s does not increase (previous line: {} s)", s.t_s, previous));
  }
  if (step > 1.5 * log.cycle_s) {
    throw InputError(file, line, "t_s",
                     fmt::format("gap of {:.6g} s before this line ({:.1f} cycles of {} s)", step,
                                 step / log.cycle_s, log.cycle_s));
  }
  if (step < 0.5 * log.cycle_s) {
    throw InputError(file, line, "t_s",
                     fmt::format("step of {:.6g} s is less than half the cycle of {} s "
                                 "(time stamps jitter or the cycle_s header is wrong)",
                                 step, log.cycle_s));
  }
}

}  // namespace

RobotLog read_robot_log_csv(const std::filesystem::path& file, const std::string& expected_robot,
                            const std::string& expected_by, bool samples_to_file) {
  // The rows go into the log as they are read, not through a whole table first. The file's
  // structure (fields, numbers) is checked to its end before any of the log's own checks
  // speaks, as when the table came first: the first of those waits in `refused`.
  RobotLog log;
  LogColumns columns;
  std::exception_ptr refused;
  const auto checked = [&](const auto& step) {
    if (refused) return;
    try {
      step();
    } catch (const InputError&) {
      refused = std::current_exception();
    }
  };
  const std::string name = file.string();
  read_numeric_rows(
      file,
      [&](const NumericTable& header, std::size_t lines_left) {
        checked([&] { columns = read_log_header(header, expected_robot, expected_by, log); });
        if (samples_to_file) log.samples.spill_to_file();
        log.samples.reserve(lines_left);
        log.sample_lines.reserve(lines_left);
      },
      [&](std::span<const double> values, std::size_t line) {
        checked([&] { add_log_row(values, line, columns, name, log); });
      });
  if (refused) std::rethrow_exception(refused);
  if (columns.used_degrees) {
    spdlog::warn("{}: joint angles given in degrees; converted to rad", name);
  }
  return log;
}

std::vector<JointLimit> joint_limits_of(const RobotDescription& robot) {
  std::vector<JointLimit> limits;
  for (int j = 0; j < kJointCount; ++j)
    limits.push_back({robot.joints[std::size_t(j)].name.empty() ? fmt::format("{}", j + 1)
                                                                : robot.joints[std::size_t(j)].name,
                      robot.kinematics.lower_limit_rad[j], robot.kinematics.upper_limit_rad[j]});
  return limits;
}

std::size_t check_robot_log_joint_limits(const RobotLog& log, const std::string& file,
                                         const RobotDescription& robot) {
  const JointAngleSource source{file,
                                [&log](std::size_t k) {
                                  return k < log.sample_lines.size() ? log.sample_lines[k]
                                                                     : std::size_t{0};
                                },
                                fmt::format("robot {} ({})", robot.name, robot.source)};
  const std::vector<JointLimit> limits = joint_limits_of(robot);
  // One column at a time (the order check_joint_limits takes them in), in one buffer: a copy of
  // every column would grow with the log.
  std::vector<double> values(log.samples.size());
  std::size_t beyond = 0;
  for (std::size_t j = 0; j < std::size_t(kJointCount); ++j) {
    for (const bool desired : {true, false}) {
      for (std::size_t k = 0; k < log.samples.size(); ++k) {
        const RobotLogSample& s = log.samples[k];
        values[k] = desired ? s.q_desired_rad[int(j)] : s.q_internal_rad[int(j)];
      }
      const JointAngleColumn column{
          fmt::format("{}_{}_rad", desired ? "q_desired" : "q_internal", log.joint_names[j]), j,
          values};
      beyond += check_joint_limits(std::span(&column, 1), limits, source);
    }
  }
  return beyond;
}

}  // namespace imscal::calib
