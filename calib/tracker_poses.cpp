#include "calib/tracker_poses.hpp"

#include <fmt/format.h>

#include <cmath>

#include "core/input_error.hpp"
#include "core/numeric_table.hpp"

namespace imscal::calib {
namespace {

bool starts_with(const std::string& text, const std::string& prefix) {
  return text.rfind(prefix, 0) == 0;
}
bool ends_with(const std::string& text, const std::string& suffix) {
  return text.size() >= suffix.size() &&
         text.compare(text.size() - suffix.size(), suffix.size(), suffix) == 0;
}

std::size_t joint_column(const NumericTable& table, int joint) {
  const std::string prefix = fmt::format("q{}_", joint + 1);
  std::optional<std::size_t> found;
  for (std::size_t c = 0; c < table.columns.size(); ++c) {
    if (!starts_with(table.columns[c], prefix) || !ends_with(table.columns[c], "_rad")) continue;
    if (found) {
      throw InputError(table.file, table.header_line, table.columns[c],
                       fmt::format("a second column for joint {} (first: {})", joint + 1,
                                   table.columns[*found]));
    }
    found = c;
  }
  if (!found) {
    throw InputError(table.file, table.header_line, prefix + "*_rad",
                     fmt::format("no column for joint {} (a name `{}..._rad`)", joint + 1, prefix));
  }
  return *found;
}

bool has_column(const NumericTable& table, const std::string& name) {
  for (const std::string& c : table.columns) {
    if (c == name) return true;
  }
  return false;
}

Eigen::Matrix3d rotation_xyz_moving_deg(const Eigen::Vector3d& angles_deg) {
  const Eigen::Vector3d r = angles_deg * M_PI / 180.0;
  return (Eigen::AngleAxisd(r.x(), Eigen::Vector3d::UnitX()) *
          Eigen::AngleAxisd(r.y(), Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(r.z(), Eigen::Vector3d::UnitZ()))
      .toRotationMatrix();
}

// The value of column `c` in `row`, checked against a plausible magnitude.
double checked(const NumericTable& table, std::size_t row, std::size_t c, double limit,
               const char* why) {
  const double v = table.at(row, c);
  if (std::abs(v) > limit) {
    throw InputError(table.file, table.lines[row], table.columns[c],
                     fmt::format("{} is beyond {} ({})", v, limit, why));
  }
  return v;
}

}  // namespace

TrackerPoses read_tracker_poses(const std::filesystem::path& file) {
  const NumericTable table = read_numeric_table(file);
  std::array<std::size_t, kJointCount> q_column{};
  for (int i = 0; i < kJointCount; ++i) q_column[i] = joint_column(table, i);
  const std::array<std::size_t, 3> p_column{table.column("meas_x_mm"), table.column("meas_y_mm"),
                                            table.column("meas_z_mm")};
  const bool attitude = has_column(table, "meas_rx_deg");
  const bool goal = has_column(table, "goal_x_m");
  TrackerPoses out{table.file, {}};
  for (std::size_t row = 0; row < table.rows(); ++row) {
    TrackerPose pose;
    pose.line = table.lines[row];
    for (int i = 0; i < kJointCount; ++i) {
      pose.q_rad(i) = checked(table, row, q_column[i], 4.0 * M_PI, "joint angles are in rad");
    }
    for (int k = 0; k < 3; ++k) {
      pose.p_tracker_m(k) = checked(table, row, p_column[k], 1e5, "positions are in mm") / 1000.0;
    }
    if (attitude) {
      pose.R_tracker = rotation_xyz_moving_deg({table.at(row, table.column("meas_rx_deg")),
                                                table.at(row, table.column("meas_ry_deg")),
                                                table.at(row, table.column("meas_rz_deg"))});
    }
    if (goal) {
      auto at = [&](const char* name) { return table.at(row, table.column(name)); };
      pose.goal =
          pose_from_xyz_rpy({at("goal_x_m"), at("goal_y_m"), at("goal_z_m")},
                            {at("goal_roll_rad"), at("goal_pitch_rad"), at("goal_yaw_rad")});
    }
    out.poses.push_back(pose);
  }
  if (out.poses.empty()) throw InputError(table.file, 0, "", "no pose rows");
  return out;
}

}  // namespace imscal::calib
