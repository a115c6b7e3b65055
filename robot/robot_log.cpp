#include "robot/robot_log.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <cmath>

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

RobotLog read_robot_log_csv(const std::filesystem::path& file, const std::string& expected_robot,
                            const std::string& expected_by) {
  const NumericTable table = read_numeric_table(file);
  if (table.meta("imscal-robot-log") != "1") {
    throw InputError(table.file, table.meta_line("imscal-robot-log"), "imscal-robot-log",
                     "unknown version '" + table.meta("imscal-robot-log") + "' (this reader: 1)");
  }
  RobotLog log;
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
  const std::size_t time_column = table.column("t_s");
  const std::size_t payload_column = table.column("payload_kg");
  bool used_degrees = false;
  std::array<std::pair<std::size_t, double>, kJointCount> desired{}, internal{};
  for (int j = 0; j < kJointCount; ++j) {
    desired[j] = angle_column(table, "q_desired", log.joint_names[j], used_degrees);
    internal[j] = angle_column(table, "q_internal", log.joint_names[j], used_degrees);
  }
  const std::size_t expected_columns = 2 + 2 * kJointCount;
  if (table.columns.size() != expected_columns) {
    throw InputError(table.file, table.header_line, "",
                     fmt::format("{} columns, expected {} (t_s, payload_kg, 6 desired and 6 "
                                 "internal joint angles)",
                                 table.columns.size(), expected_columns));
  }
  log.samples.resize(table.rows());
  log.sample_lines.assign(table.lines.begin(), table.lines.end());
  for (std::size_t r = 0; r < table.rows(); ++r) {
    RobotLogSample& s = log.samples[r];
    s.t_s = table.at(r, time_column);
    s.payload_kg = table.at(r, payload_column);
    if (s.payload_kg < 0.0) {
      throw InputError(table.file, table.lines[r], "payload_kg", "negative payload");
    }
    for (int j = 0; j < kJointCount; ++j) {
      s.q_desired_rad[j] = table.at(r, desired[j].first) * desired[j].second;
      s.q_internal_rad[j] = table.at(r, internal[j].first) * internal[j].second;
    }
    if (r == 0) continue;
    const double step = s.t_s - log.samples[r - 1].t_s;
    if (!(step > 0.0)) {
      throw InputError(table.file, table.lines[r], "t_s",
                       fmt::format("time {} s does not increase (previous line: {} s)", s.t_s,
                                   log.samples[r - 1].t_s));
    }
    if (step > 1.5 * log.cycle_s) {
      throw InputError(table.file, table.lines[r], "t_s",
                       fmt::format("gap of {:.6g} s before this line ({:.1f} cycles of {} s)", step,
                                   step / log.cycle_s, log.cycle_s));
    }
    if (step < 0.5 * log.cycle_s) {
      throw InputError(table.file, table.lines[r], "t_s",
                       fmt::format("step of {:.6g} s is less than half the cycle of {} s "
                                   "(time stamps jitter or the cycle_s header is wrong)",
                                   step, log.cycle_s));
    }
  }
  if (used_degrees) {
    spdlog::warn("{}: joint angles given in degrees; converted to rad", table.file);
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
  std::vector<std::vector<double>> values(2 * kJointCount);
  for (const RobotLogSample& s : log.samples)
    for (int j = 0; j < kJointCount; ++j) {
      values[std::size_t(j)].push_back(s.q_desired_rad[j]);
      values[std::size_t(kJointCount + j)].push_back(s.q_internal_rad[j]);
    }
  std::vector<JointAngleColumn> columns;
  for (std::size_t j = 0; j < std::size_t(kJointCount); ++j) {
    columns.push_back({fmt::format("q_desired_{}_rad", log.joint_names[j]), j, values[j]});
    columns.push_back(
        {fmt::format("q_internal_{}_rad", log.joint_names[j]), j, values[kJointCount + j]});
  }
  return check_joint_limits(columns, joint_limits_of(robot),
                            {file,
                             [&log](std::size_t k) {
                               return k < log.sample_lines.size() ? log.sample_lines[k]
                                                                  : std::size_t{0};
                             },
                             fmt::format("robot {} ({})", robot.name, robot.source)});
}

}  // namespace imscal::calib
