#include "calib/tool_imu_record.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <numeric>
#include <optional>

#include "calib/time_offset.hpp"
#include "core/csv_text.hpp"
#include "core/input_error.hpp"
#include "core/input_file.hpp"
#include "core/units.hpp"
#include "ims/so3.hpp"

namespace imscal::calib {
namespace {

constexpr double kMmToM = 1e-3;

const std::vector<std::string> kRobotColumns = {
    "robot_x_mm", "robot_y_mm", "robot_z_mm", "robot_qw", "robot_qx", "robot_qy", "robot_qz"};
const std::vector<std::string> kRawColumns = {"gyro_x_dps", "gyro_y_dps", "gyro_z_dps",
                                              "acc_x_g",    "acc_y_g",    "acc_z_g"};
const std::vector<std::string> kAhrsColumns = {"sens_q0", "sens_q1", "sens_q2", "sens_q3"};

// Lines as a compact text: "368, 370-372".
std::string line_list(const std::vector<std::size_t>& lines, std::size_t max_items = 12) {
  std::string out;
  std::size_t items = 0;
  for (std::size_t i = 0; i < lines.size();) {
    std::size_t j = i;
    while (j + 1 < lines.size() && lines[j + 1] == lines[j] + 1) ++j;
    if (items == max_items) {
      out += fmt::format(", ... ({} more)", lines.size() - i);
      break;
    }
    if (!out.empty()) out += ", ";
    out += j == i ? fmt::format("{}", lines[i]) : fmt::format("{}-{}", lines[i], lines[j]);
    ++items;
    i = j + 1;
  }
  return out;
}

double median_of(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const auto mid = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), mid, values.end());
  return *mid;
}

void add_time_step_finding(ToolImuRecord& record, const ToolImuReadOptions& options) {
  if (record.t_s.size() < 3) return;
  std::vector<double> steps(record.t_s.size() - 1);
  for (std::size_t k = 0; k + 1 < record.t_s.size(); ++k) {
    steps[k] = record.t_s[k + 1] - record.t_s[k];
  }
  const double median = median_of(steps);
  const double mean = std::accumulate(steps.begin(), steps.end(), 0.0) / steps.size();
  double variance = 0.0;
  std::size_t irregular = 0;
  std::vector<std::size_t> gap_lines;
  double largest_gap = 0.0;
  std::size_t largest_gap_line = 0;
  for (std::size_t k = 0; k < steps.size(); ++k) {
    variance += (steps[k] - mean) * (steps[k] - mean);
    if (std::abs(steps[k] - median) > options.irregular_step_fraction * median) ++irregular;
    if (steps[k] > options.gap_factor * median) gap_lines.push_back(record.lines[k + 1]);
    if (steps[k] > largest_gap) {
      largest_gap = steps[k];
      largest_gap_line = record.lines[k + 1];
    }
  }
  const double std_dev = std::sqrt(variance / steps.size());
  const auto [min_it, max_it] = std::minmax_element(steps.begin(), steps.end());
  const double irregular_fraction = static_cast<double>(irregular) / steps.size();
  ToolImuFinding finding;
  finding.kind = ToolImuFindingKind::kIrregularTimeSteps;
  finding.where =
      record.file + (gap_lines.empty() ? "" : ", gaps before lines " + line_list(gap_lines));
  finding.size = irregular_fraction;
  finding.unit = "fraction of steps";
  finding.is_defect = irregular_fraction > 0.05 || !gap_lines.empty();
  finding.message = fmt::format(
      "time steps: median {:.2f} ms ({:.1f} Hz), mean {:.2f} ms, std {:.2f} ms, min {:.2f} ms, "
      "max {:.2f} ms (before line {}); {:.1f} % of the steps are more than {:.0f} % off the "
      "median; {} gap(s) longer than {:.0f} x the median",
      median * 1e3, 1.0 / median, mean * 1e3, std_dev * 1e3, *min_it * 1e3, *max_it * 1e3,
      largest_gap_line, 100.0 * irregular_fraction, 100.0 * options.irregular_step_fraction,
      gap_lines.size(), options.gap_factor);
  record.findings.push_back(std::move(finding));
}

}  // namespace

const char* to_string(ToolImuFindingKind kind) {
  switch (kind) {
    case ToolImuFindingKind::kNanRows:
      return "nan_rows";
    case ToolImuFindingKind::kIrregularTimeSteps:
      return "irregular_time_steps";
    case ToolImuFindingKind::kRobotQuaternionNotUnit:
      return "robot_quaternion_not_unit";
    case ToolImuFindingKind::kGyroNearRail:
      return "gyro_near_rail";
    case ToolImuFindingKind::kGyroScaleMismatch:
      return "gyro_scale_mismatch";
    case ToolImuFindingKind::kTimeOffset:
      return "time_offset";
    case ToolImuFindingKind::kAxisMisalignment:
      return "axis_misalignment";
    case ToolImuFindingKind::kRobotQuaternionConvention:
      return "robot_quaternion_convention";
    case ToolImuFindingKind::kSensorMissedMotion:
      return "sensor_missed_motion";
  }
  return "unknown";
}

ToolImuRecord read_tool_imu_record(const std::filesystem::path& path,
                                   const ToolImuReadOptions& options) {
  ToolImuRecord record;
  record.file = path.string();
  record.robot_quaternion_conjugated = options.robot_quaternion_is_base_in_tool;
  std::ifstream in = open_input_stream(path);

  std::string line;
  std::size_t line_number = 0;
  // Header: the first line.
  if (!std::getline(in, line) || csv::trim(line).empty()) {
    throw InputError(record.file, 1, "",
                     "empty file: a header line with the column names is "
                     "expected");
  }
  line_number = 1;
  if (strip_byte_order_mark(line))
    spdlog::warn("{}: a UTF-8 byte-order mark at the start was skipped", record.file);
  std::vector<std::string> columns;
  for (auto field : csv::split(csv::trim(line), ',')) columns.emplace_back(csv::trim(field));
  auto find_column = [&](const std::string& name) -> std::optional<std::size_t> {
    const auto it = std::find(columns.begin(), columns.end(), name);
    if (it == columns.end()) return std::nullopt;
    return static_cast<std::size_t>(it - columns.begin());
  };
  record.has_raw_imu = find_column("gyro_x_dps").has_value();
  record.has_sensor_orientation = find_column("sens_q0").has_value();
  if (record.has_raw_imu == record.has_sensor_orientation) {
    throw InputError(record.file, 1, record.has_raw_imu ? "sens_q0" : "gyro_x_dps",
                     "the header must hold either the raw IMU columns (gyro_*_dps, acc_*_g) or "
                     "an AHRS orientation (sens_q0..3), exactly one of the two");
  }
  std::vector<std::string> expected = {"t_s"};
  const auto& sensor_columns = record.has_raw_imu ? kRawColumns : kAhrsColumns;
  expected.insert(expected.end(), sensor_columns.begin(), sensor_columns.end());
  expected.insert(expected.end(), kRobotColumns.begin(), kRobotColumns.end());
  for (const auto& name : columns) {
    if (std::count(columns.begin(), columns.end(), name) > 1) {
      throw InputError(record.file, 1, name, "column appears twice");
    }
    if (std::find(expected.begin(), expected.end(), name) == expected.end()) {
      throw InputError(
          record.file, 1, name,
          fmt::format("unknown column; expected exactly: {}", fmt::join(expected, ",")));
    }
  }
  std::vector<std::size_t> index;  // file column of each expected column
  for (const auto& name : expected) {
    const auto at = find_column(name);
    if (!at) throw InputError(record.file, 1, name, "missing column");
    index.push_back(*at);
  }

  std::vector<std::size_t> nan_lines;
  std::vector<std::size_t> bad_quaternion_lines;
  std::vector<double> values(expected.size());
  bool blank_seen = false;
  std::size_t blank_line = 0;
  while (std::getline(in, line)) {
    ++line_number;
    const auto text = csv::trim(line);
    if (text.empty()) {
      if (!blank_seen) blank_line = line_number;
      blank_seen = true;
      continue;
    }
    if (blank_seen) {
      throw InputError(record.file, blank_line, "", "empty line among the data rows");
    }
    const auto fields = csv::split(text, ',');
    if (fields.size() != columns.size()) {
      const std::string field =
          fields.size() < columns.size() ? columns[fields.size()] : std::string("(extra field)");
      throw InputError(record.file, line_number, field,
                       fmt::format("{} fields where the header has {} (truncated or damaged row)",
                                   fields.size(), columns.size()));
    }
    bool has_nan = false;
    for (std::size_t c = 0; c < expected.size(); ++c) {
      if (!csv::parse_number(fields[index[c]], values[c])) {
        throw InputError(record.file, line_number, expected[c],
                         fmt::format("'{}' is not a number", csv::trim(fields[index[c]])));
      }
      if (std::isnan(values[c])) {
        has_nan = true;
      } else if (!std::isfinite(values[c])) {
        throw InputError(record.file, line_number, expected[c], "infinite value");
      }
    }
    if (has_nan) {
      nan_lines.push_back(line_number);
      continue;
    }
    const double t = values[0];
    if (!record.t_s.empty() && !(t > record.t_s.back())) {
      throw InputError(record.file, line_number, "t_s",
                       fmt::format("time {} s does not increase (previous row {} s, line {})", t,
                                   record.t_s.back(), record.lines.back()));
    }
    record.t_s.push_back(t);
    record.lines.push_back(line_number);
    std::size_t c = 1;
    if (record.has_raw_imu) {
      record.gyro_rad_s.emplace_back(values[1] * kRadPerDeg, values[2] * kRadPerDeg,
                                     values[3] * kRadPerDeg);
      record.acc_m_s2.emplace_back(values[4] * kStandardGravity_m_s2,
                                   values[5] * kStandardGravity_m_s2,
                                   values[6] * kStandardGravity_m_s2);
      c = 7;
    } else {
      Eigen::Quaterniond q(values[1], values[2], values[3], values[4]);
      const double norm = q.norm();
      if (!(norm > 0.5)) {  // an AHRS's own output is unit; far off means damaged
        throw InputError(record.file, line_number, "sens_q0",
                         fmt::format("sensor quaternion norm {:.4g} is far from 1", norm));
      }
      record.q_N_X.push_back(q.normalized());
      c = 5;
    }
    record.robot_position_m.emplace_back(values[c] * kMmToM, values[c + 1] * kMmToM,
                                         values[c + 2] * kMmToM);
    Eigen::Quaterniond q(values[c + 3], values[c + 4], values[c + 5], values[c + 6]);
    const double norm = q.norm();
    record.robot_quaternion_norm.push_back(norm);
    if (std::abs(norm - 1.0) > options.robot_quaternion_norm_tolerance) {
      bad_quaternion_lines.push_back(line_number);
    }
    const bool valid = std::abs(norm - 1.0) <= options.robot_quaternion_norm_tolerance;
    record.robot_pose_valid.push_back(valid);
    if (!valid) {
      record.q_B_T.push_back(Eigen::Quaterniond::Identity());
    } else {
      record.q_B_T.push_back(options.robot_quaternion_is_base_in_tool ? q.normalized().conjugate()
                                                                      : q.normalized());
    }
  }
  if (record.t_s.size() < 2) {
    throw InputError(
        record.file, line_number, "t_s",
        fmt::format("{} usable data row(s); at least 2 are needed", record.t_s.size()));
  }

  if (!nan_lines.empty()) {
    ToolImuFinding finding;
    finding.kind = ToolImuFindingKind::kNanRows;
    finding.where = fmt::format("{} lines {}", record.file, line_list(nan_lines));
    finding.size = static_cast<double>(nan_lines.size());
    finding.unit = "rows";
    finding.message = fmt::format("{} row(s) hold NaN and were dropped (lines {})",
                                  nan_lines.size(), line_list(nan_lines));
    spdlog::warn("{}: {}", record.file, finding.message);
    record.findings.push_back(std::move(finding));
  }
  add_time_step_finding(record, options);
  if (!bad_quaternion_lines.empty()) {
    double worst = 1.0;
    for (std::size_t k = 0; k < record.t_s.size(); ++k) {
      if (std::abs(record.robot_quaternion_norm[k] - 1.0) > std::abs(worst - 1.0)) {
        worst = record.robot_quaternion_norm[k];
      }
    }
    ToolImuFinding finding;
    finding.kind = ToolImuFindingKind::kRobotQuaternionNotUnit;
    finding.where = fmt::format("{} lines {}", record.file, line_list(bad_quaternion_lines));
    finding.size = static_cast<double>(bad_quaternion_lines.size());
    finding.unit = "rows";
    finding.message = fmt::format(
        "{} robot quaternion(s) are off unit length by more than {:.3g} (worst norm {:.4g}): the "
        "poses were interpolated component-wise between the robot's samples, across a sign "
        "flip (q and -q) where the norm nears 0: their direction is wrong; they are not used "
        "(the orientation is interpolated from the valid neighbours)",
        bad_quaternion_lines.size(), options.robot_quaternion_norm_tolerance, worst);
    spdlog::warn("{}: {}", record.file, finding.message);
    record.findings.push_back(std::move(finding));
  }
  return record;
}

bool robot_orientation_at(const ToolImuRecord& record, double t_s, Eigen::Quaterniond& q_B_T,
                          double max_gap_s) {
  const auto& t = record.t_s;
  if (t.empty() || t_s < t.front() || t_s > t.back()) return false;
  std::size_t hi = static_cast<std::size_t>(std::lower_bound(t.begin(), t.end(), t_s) - t.begin());
  if (hi == t.size()) hi = t.size() - 1;
  // Nearest valid poses on both sides.
  std::size_t lo = hi;
  while (lo > 0 && (!record.robot_pose_valid[lo] || t[lo] > t_s)) --lo;
  while (hi + 1 < t.size() && !record.robot_pose_valid[hi]) ++hi;
  if (!record.robot_pose_valid[lo] || !record.robot_pose_valid[hi] || t[lo] > t_s || t[hi] < t_s ||
      t[hi] - t[lo] > max_gap_s) {
    return false;
  }
  if (hi == lo) {
    q_B_T = record.q_B_T[lo];
    return true;
  }
  const double fraction = (t_s - t[lo]) / (t[hi] - t[lo]);
  q_B_T = record.q_B_T[lo].slerp(fraction, record.q_B_T[hi]);
  return true;
}

RobotRateSeries robot_tool_rate(const ToolImuRecord& record, double step_s, double half_span_s) {
  RobotRateSeries series;
  const double t0 = record.t_s.front();
  const auto count = static_cast<std::size_t>(std::floor((record.t_s.back() - t0) / step_s)) + 1;
  std::vector<Eigen::Quaterniond> grid(count);
  std::vector<bool> have(count);
  for (std::size_t k = 0; k < count; ++k) {
    have[k] = robot_orientation_at(record, t0 + k * step_s, grid[k]);
  }
  const auto half =
      std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(half_span_s / step_s)));
  for (std::size_t k = half; k + half < count; ++k) {
    if (!have[k - half] || !have[k + half]) continue;
    series.t_s.push_back(t0 + k * step_s);
    series.omega_T_rad_s.push_back(
        ims::quat_log(Eigen::Quaterniond(grid[k - half].conjugate() * grid[k + half])) /
        (2.0 * half * step_s));
  }
  return series;
}

bool robot_rate_at(const RobotRateSeries& series, double t_s, Eigen::Vector3d& omega_T_rad_s) {
  const auto& t = series.t_s;
  if (t.size() < 2 || t_s < t.front() || t_s > t.back()) return false;
  std::size_t hi = static_cast<std::size_t>(std::lower_bound(t.begin(), t.end(), t_s) - t.begin());
  if (hi == 0) hi = 1;
  const std::size_t lo = hi - 1;
  // Gaps in the grid (invalid poses): no interpolation across them.
  if (t[hi] - t[lo] > 1.5 * (t[1] - t[0]) + 1e-9) return false;
  const double fraction = (t_s - t[lo]) / (t[hi] - t[lo]);
  omega_T_rad_s = (1.0 - fraction) * series.omega_T_rad_s[lo] + fraction * series.omega_T_rad_s[hi];
  return true;
}

Eigen::Matrix3d fit_rotation(const std::vector<Eigen::Vector3d>& a,
                             const std::vector<Eigen::Vector3d>& b) {
  Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
  for (std::size_t k = 0; k < a.size(); ++k) h += b[k] * a[k].transpose();
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(h, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
  d(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0.0 ? -1.0 : 1.0;
  return svd.matrixU() * d * svd.matrixV().transpose();
}

namespace {

// "sensor x ~ -tool z, ..." for the signed permutation nearest to R_T_S.
std::string axis_words(const Eigen::Matrix3d& R_T_S) {
  const char* names = "xyz";
  std::string out;
  for (int s = 0; s < 3; ++s) {
    int best = 0;
    for (int t = 1; t < 3; ++t) {
      if (std::abs(R_T_S(t, s)) > std::abs(R_T_S(best, s))) best = t;
    }
    if (!out.empty()) out += ", ";
    out += fmt::format("sensor {} ~ {}tool {} ({:.1f} deg off)", names[s],
                       R_T_S(best, s) < 0 ? "-" : "+", names[best],
                       std::acos(std::min(1.0, std::abs(R_T_S(best, s)))) * 180.0 / M_PI);
  }
  return out;
}

// Median over the segments of gyro angle / robot angle, and the segments off it by more than
// `fraction`.
double segment_ratio(const std::vector<MotionSegment>& segments, double fraction,
                     std::vector<MotionSegment>& off) {
  std::vector<double> ratios;
  for (const auto& s : segments) ratios.push_back(s.gyro_angle_raw_rad / s.robot_angle_rad);
  const double median = median_of(ratios);
  off.clear();
  for (const auto& s : segments) {
    if (std::abs(s.gyro_angle_raw_rad / s.robot_angle_rad / median - 1.0) > fraction) {
      off.push_back(s);
    }
  }
  return median;
}

}  // namespace

std::vector<MotionSegment> motion_segments(const ToolImuRecord& record,
                                           const RobotRateSeries& robot, double offset_s,
                                           double rate_threshold, double min_angle) {
  std::vector<MotionSegment> segments;
  const double step = robot.t_s.size() > 1 ? robot.t_s[1] - robot.t_s[0] : 0.01;
  std::size_t k = 0;
  while (k < robot.t_s.size()) {
    if (robot.omega_T_rad_s[k].norm() < rate_threshold) {
      ++k;
      continue;
    }
    MotionSegment segment;
    std::size_t end = k;
    while (end < robot.t_s.size() && robot.omega_T_rad_s[end].norm() >= rate_threshold) {
      segment.robot_angle_rad += robot.omega_T_rad_s[end].norm() * step;
      ++end;
    }
    segment.begin_s = robot.t_s[k] + offset_s - 0.15;
    segment.end_s = robot.t_s[end - 1] + offset_s + 0.15;
    k = end;
    if (segment.robot_angle_rad < min_angle) continue;
    for (std::size_t i = 0; i + 1 < record.t_s.size(); ++i) {
      if (record.t_s[i] < segment.begin_s || record.t_s[i + 1] > segment.end_s) continue;
      if (segment.first_line == 0) segment.first_line = record.lines[i];
      segment.last_line = record.lines[i + 1];
      segment.gyro_angle_raw_rad +=
          0.5 * (record.gyro_rad_s[i].norm() + record.gyro_rad_s[i + 1].norm()) *
          (record.t_s[i + 1] - record.t_s[i]);
    }
    segments.push_back(segment);
  }
  return segments;
}

ToolImuAnalysis check_tool_imu_record(const ToolImuRecord& record,
                                      const ToolImuCheckOptions& options) {
  if (!record.has_raw_imu) {
    throw InputError(record.file, 0, "gyro_x_dps", "the checks need the raw gyro columns");
  }
  ToolImuAnalysis analysis;
  analysis.findings = record.findings;
  const RobotRateSeries robot = robot_tool_rate(record);
  if (robot.t_s.size() < 10) {
    throw InputError(record.file, 0, "robot_qw", "fewer than 10 usable robot orientations");
  }

  // Time offset: |omega| does not depend on the frame nor (for the correlation) on the scale.
  RateMagnitudeSeries robot_magnitude{{}, {}, record.file + " robot pose"};
  for (std::size_t k = 0; k < robot.t_s.size(); ++k) {
    robot_magnitude.t_s.push_back(robot.t_s[k]);
    robot_magnitude.rate_rad_s.push_back(robot.omega_T_rad_s[k].norm());
  }
  RateMagnitudeSeries gyro_magnitude{record.t_s, {}, record.file + " gyro"};
  for (const auto& w : record.gyro_rad_s) gyro_magnitude.rate_rad_s.push_back(w.norm());
  TimeOffsetOptions offset_options;
  offset_options.max_abs_offset_s = options.max_abs_time_offset_s;
  offset_options.coarse_step_s = 0.005;
  // The sensor's rate may be mislabelled by a large factor: the motion test must not depend on
  // the unit (the correlation does not).
  offset_options.min_rate_std_rad_s = 1e-4;
  TimeOffsetResult offset = estimate_time_offset(robot_magnitude, gyro_magnitude, offset_options);
  // Motion the sensor did not record faithfully (segments whose gyro/robot angle ratio is off
  // the median of all segments) also spoils the correlation: time again without it.
  std::vector<MotionSegment> missed;
  const double rate_threshold = options.segment_rate_rad_s;
  const double min_angle = options.min_segment_angle_rad;
  segment_ratio(motion_segments(record, robot, offset.offset_s, rate_threshold, min_angle),
                options.missed_motion_fraction, missed);
  if (!missed.empty()) {
    RateMagnitudeSeries kept{{}, {}, gyro_magnitude.source};
    for (std::size_t k = 0; k < record.t_s.size(); ++k) {
      bool inside = false;
      for (const auto& s : missed)
        inside = inside || (record.t_s[k] >= s.begin_s && record.t_s[k] <= s.end_s);
      if (inside) continue;
      kept.t_s.push_back(record.t_s[k]);
      kept.rate_rad_s.push_back(gyro_magnitude.rate_rad_s[k]);
    }
    offset = estimate_time_offset(robot_magnitude, kept, offset_options);
  }
  const double median_segment_ratio =
      segment_ratio(motion_segments(record, robot, offset.offset_s, rate_threshold, min_angle),
                    options.missed_motion_fraction, missed);
  auto in_missed = [&](double t) {
    for (const auto& s : missed) {
      if (t >= s.begin_s && t <= s.end_s) return true;
    }
    return false;
  };
  analysis.time_offset_s = offset.offset_s;
  analysis.time_offset_peak_correlation = offset.peak_correlation;
  {
    ToolImuFinding finding;
    finding.kind = ToolImuFindingKind::kTimeOffset;
    finding.where = record.file;
    finding.size = offset.offset_s;
    finding.unit = "s";
    finding.is_defect = std::abs(offset.offset_s) > 0.01;
    finding.message = fmt::format(
        "the sensor's clock runs {:+.3f} s from the robot pose's (t_sensor = t_robot + offset; "
        "cross-correlation of |omega|, peak {:.3f}, width {:.3f} s){}",
        offset.offset_s, offset.peak_correlation, offset.peak_width_s,
        finding.is_defect ? ": the streams are not synchronised" : "");
    analysis.findings.push_back(std::move(finding));
  }

  // Pairs (gyro, robot rate at t - offset) where the robot turns.
  std::vector<Eigen::Vector3d> gyro_fit, robot_fit;
  std::vector<std::size_t> fit_index;
  for (std::size_t k = 0; k < record.t_s.size(); ++k) {
    Eigen::Vector3d w_T;
    if (in_missed(record.t_s[k])) continue;
    if (!robot_rate_at(robot, record.t_s[k] - offset.offset_s, w_T)) continue;
    if (w_T.norm() < options.min_rate_for_fit_rad_s) continue;
    gyro_fit.push_back(record.gyro_rad_s[k]);
    robot_fit.push_back(w_T);
    fit_index.push_back(k);
  }
  analysis.fit_sample_count = gyro_fit.size();
  if (gyro_fit.size() < 20) {
    throw InputError(record.file, 0, "gyro_x_dps",
                     fmt::format("only {} samples with robot rotation above {:.3g} rad/s; too few "
                                 "to check the gyro scale and axes",
                                 gyro_fit.size(), options.min_rate_for_fit_rad_s));
  }

  // Near-rail flat tops (before the scale fit, so that clipped samples can be left out of it).
  std::vector<bool> clipped_sample(record.t_s.size(), false);
  for (int axis = 0; axis < 3; ++axis) {
    double largest = 0.0;
    for (const auto& w : record.gyro_rad_s) largest = std::max(largest, std::abs(w[axis]));
    const double threshold = (1.0 - options.rail_fraction) * largest;
    // Longest run of consecutive samples at the rail.
    std::size_t best_begin = 0, best_length = 0;
    for (std::size_t k = 0; k < record.t_s.size();) {
      if (std::abs(record.gyro_rad_s[k][axis]) < threshold) {
        ++k;
        continue;
      }
      std::size_t end = k;
      while (end < record.t_s.size() && std::abs(record.gyro_rad_s[end][axis]) >= threshold) {
        ++end;
      }
      if (end - k > best_length) {
        best_length = end - k;
        best_begin = k;
      }
      k = end;
    }
    if (best_length < options.min_flat_top_samples) continue;
    // The robot's rate during the flat top against the gyro's, magnitudes; the gyro's scale is
    // not known yet, so both are divided by their median over the fit samples outside the top.
    double robot_sum = 0.0, gyro_sum = 0.0;
    std::size_t used = 0;
    for (std::size_t k = best_begin; k < best_begin + best_length; ++k) {
      Eigen::Vector3d w_T;
      if (!robot_rate_at(robot, record.t_s[k] - offset.offset_s, w_T)) continue;
      robot_sum += w_T.norm();
      gyro_sum += record.gyro_rad_s[k].norm();
      ++used;
    }
    std::vector<double> ratios;
    for (std::size_t i = 0; i < gyro_fit.size(); ++i) {
      if (fit_index[i] >= best_begin && fit_index[i] < best_begin + best_length) continue;
      ratios.push_back(gyro_fit[i].norm() / robot_fit[i].norm());
    }
    const double typical_ratio = median_of(ratios);
    const double excess = used == 0 ? 0.0 : robot_sum * typical_ratio / gyro_sum - 1.0;
    const bool clipping = excess > options.clipping_excess_fraction;
    ToolImuFinding finding;
    finding.kind = ToolImuFindingKind::kGyroNearRail;
    finding.where =
        fmt::format("{} gyro_{}_dps lines {}-{}", record.file, "xyz"[axis],
                    record.lines[best_begin], record.lines[best_begin + best_length - 1]);
    finding.size = largest * 180.0 / M_PI;
    finding.unit = "deg/s";
    finding.is_defect = true;  // a flat top at the largest reading is a possible rail
    finding.message = fmt::format(
        "gyro {} stays within {:.0f} % of its largest reading |{:.1f}| deg/s (as labelled) for {} "
        "samples ({:.3f} s): a flat top, possibly the rail (saturation); the robot turns "
        "{:+.1f} % faster than the gyro reads there (gyro scaled by its typical ratio {:.4g}; "
        "the robot's rate from the jittered poses is good to ~10 %): {}",
        "xyz"[axis], 100.0 * options.rail_fraction, finding.size, best_length,
        record.t_s[best_begin + best_length - 1] - record.t_s[best_begin], 100.0 * excess,
        typical_ratio,
        clipping ? "clipping CONFIRMED by the robot; samples at the rail are not used"
                 : "clipping not confirmed by the robot (may be a constant-rate motion); the "
                   "samples are kept");
    analysis.findings.push_back(std::move(finding));
    if (clipping) {
      analysis.clipped_axes.push_back(axis);
      analysis.clipped_axis_rail_rad_s.push_back(largest);
      for (std::size_t k = 0; k < record.t_s.size(); ++k) {
        if (std::abs(record.gyro_rad_s[k][axis]) >= threshold) clipped_sample[k] = true;
      }
    }
  }

  // Scale ratio: least-squares slope through the origin of |gyro| on |robot rate|.
  double cross = 0.0, robot_sq = 0.0;
  for (std::size_t i = 0; i < gyro_fit.size(); ++i) {
    if (clipped_sample[fit_index[i]]) continue;
    cross += gyro_fit[i].norm() * robot_fit[i].norm();
    robot_sq += robot_fit[i].squaredNorm();
  }
  analysis.gyro_scale_ratio = cross / robot_sq;
  {
    const double ratio = analysis.gyro_scale_ratio;
    ToolImuFinding finding;
    finding.kind = ToolImuFindingKind::kGyroScaleMismatch;
    finding.where = record.file + " gyro_*_dps";
    finding.size = ratio;
    finding.unit = "ratio";
    finding.is_defect = std::abs(ratio - 1.0) > options.scale_tolerance;
    const double rad_ratio = kRadPerDeg;  // what rad/s labelled as deg/s would give
    std::string reading;
    if (!finding.is_defect) {
      reading = "the labelled unit deg/s agrees with the robot";
    } else if (std::abs(ratio / rad_ratio - 1.0) < options.scale_tolerance) {
      reading = "the values look like rad/s, not deg/s";
    } else {
      reading = fmt::format(
          "neither deg/s nor rad/s (which would give {:.4f}): one count of the column is {:.4g} "
          "deg/s; the gyro scale must be calibrated, not taken from the label",
          rad_ratio, 1.0 / ratio);
    }
    finding.message = fmt::format(
        "|gyro| as labelled (deg/s) is {:.4g} x the robot's angular rate from the pose "
        "(least squares over {} samples with the robot turning): {}",
        ratio, gyro_fit.size(), reading);
    analysis.findings.push_back(std::move(finding));
  }

  // Motion segments the sensor did not record faithfully.
  for (const auto& segment : missed) {
    analysis.missed_motion_spans_s.emplace_back(segment.begin_s, segment.end_s);
    const double gyro_angle = segment.gyro_angle_raw_rad / median_segment_ratio;
    ToolImuFinding finding;
    finding.kind = ToolImuFindingKind::kSensorMissedMotion;
    finding.where =
        fmt::format("{} lines {}-{}", record.file, segment.first_line, segment.last_line);
    finding.size = (segment.robot_angle_rad - gyro_angle) * 180.0 / M_PI;
    finding.unit = "deg";
    finding.message = fmt::format(
        "the robot turned {:.1f} deg between sensor times {:.2f} and {:.2f} s, the gyro "
        "integrates {:.1f} deg (scaled by the median segment ratio {:.4g}): the sensor stream "
        "lost or garbled this motion (dropped or mis-stamped samples); no orientation can be "
        "carried across it",
        segment.robot_angle_rad * 180.0 / M_PI, segment.begin_s, segment.end_s,
        gyro_angle * 180.0 / M_PI, median_segment_ratio);
    analysis.findings.push_back(std::move(finding));
  }

  // Axes: rotation taking the (scaled) gyro vectors onto the robot's; the same fit with the
  // robot quaternion conjugated tells which quaternion convention the file uses.
  auto fit_axes = [&](const RobotRateSeries& rates, Eigen::Matrix3d& R_T_S) {
    std::vector<Eigen::Vector3d> a, b;
    for (std::size_t k = 0; k < record.t_s.size(); ++k) {
      Eigen::Vector3d w_T;
      if (clipped_sample[k] || in_missed(record.t_s[k]) ||
          !robot_rate_at(rates, record.t_s[k] - offset.offset_s, w_T) ||
          w_T.norm() < options.min_rate_for_fit_rad_s) {
        continue;
      }
      a.push_back(record.gyro_rad_s[k] / analysis.gyro_scale_ratio);
      b.push_back(w_T);
    }
    R_T_S = fit_rotation(a, b);
    double residual_sq = 0.0, robot_total = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i) {
      residual_sq += (R_T_S * a[i] - b[i]).squaredNorm();
      robot_total += b[i].squaredNorm();
    }
    return std::sqrt(residual_sq / robot_total);
  };
  analysis.rate_fit_residual = fit_axes(robot, analysis.R_T_S);
  {
    ToolImuRecord conjugated = record;
    for (auto& q : conjugated.q_B_T) q = q.conjugate();
    Eigen::Matrix3d unused;
    analysis.conjugate_rate_fit_residual = fit_axes(robot_tool_rate(conjugated), unused);
  }
  analysis.misalignment_rad = Eigen::AngleAxisd(analysis.R_T_S).angle();
  {
    ToolImuFinding finding;
    finding.kind = ToolImuFindingKind::kRobotQuaternionConvention;
    finding.where = record.file + " robot_qw..robot_qz";
    finding.size = analysis.conjugate_rate_fit_residual / analysis.rate_fit_residual;
    finding.unit = "ratio";
    // Conjugating the quaternion fits better: the convention used to read it is wrong.
    finding.is_defect = analysis.conjugate_rate_fit_residual < analysis.rate_fit_residual;
    finding.message = fmt::format(
        "rate-vector fit leaves {:.1f} % of the robot's rate unexplained with the quaternion read "
        "as {}, {:.1f} % with it conjugated: {}",
        100.0 * analysis.rate_fit_residual,
        record.robot_quaternion_conjugated ? "base in tool (conjugated)" : "tool in base",
        100.0 * analysis.conjugate_rate_fit_residual,
        finding.is_defect ? "the quaternion convention is the other one; read the file with the "
                            "other robot_quaternion_is_base_in_tool"
                          : "the convention used fits (the other does not)");
    analysis.findings.push_back(std::move(finding));
  }
  {
    ToolImuFinding finding;
    finding.kind = ToolImuFindingKind::kAxisMisalignment;
    finding.where = record.file;
    finding.size = analysis.misalignment_rad * 180.0 / M_PI;
    finding.unit = "deg";
    finding.is_defect = analysis.misalignment_rad > options.misalignment_threshold_rad;
    finding.message = fmt::format(
        "the sensor axes are turned {:.1f} deg from the tool axes ({}); the fit of the rate "
        "vectors leaves {:.1f} % of the robot's rate unexplained{}",
        finding.size, axis_words(analysis.R_T_S), 100.0 * analysis.rate_fit_residual,
        finding.is_defect ? ": the sensor-to-tool rotation must be calibrated" : "");
    analysis.findings.push_back(std::move(finding));
  }
  return analysis;
}

}  // namespace imscal::calib
