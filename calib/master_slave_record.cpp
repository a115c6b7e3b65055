#include "calib/master_slave_record.hpp"

#include <fmt/format.h>

#include <algorithm>

#include "core/input_error.hpp"
#include "core/numeric_table.hpp"

namespace imscal::calib {
namespace {

// The time column, strictly increasing.
std::vector<double> times(const NumericTable& table) {
  const std::size_t c = table.column("t_s");
  std::vector<double> t;
  for (std::size_t row = 0; row < table.rows(); ++row) {
    t.push_back(table.at(row, c));
    if (row > 0 && !(t[row] > t[row - 1])) {
      throw InputError(table.file, table.lines[row], "t_s",
                       fmt::format("time {} does not increase (previous {})", t[row], t[row - 1]));
    }
  }
  if (t.size() < 2) throw InputError(table.file, 0, "", "fewer than 2 rows");
  return t;
}

Eigen::Vector3d triple(const NumericTable& table, std::size_t row, const char* prefix,
                       const char* suffix) {
  Eigen::Vector3d v;
  const char* axes[] = {"x", "y", "z"};
  for (int k = 0; k < 3; ++k) {
    v(k) = table.at(row, table.column(fmt::format("{}{}{}", prefix, axes[k], suffix)));
  }
  return v;
}

}  // namespace

Eigen::Quaterniond psins_attitude(double pitch_rad, double roll_rad, double yaw_rad) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()) *
                            Eigen::AngleAxisd(pitch_rad, Eigen::Vector3d::UnitX()) *
                            Eigen::AngleAxisd(roll_rad, Eigen::Vector3d::UnitY()));
}

IncrementImu read_increment_imu_csv(const std::filesystem::path& file) {
  const NumericTable table = read_numeric_table(file);
  IncrementImu out{table.file, table.lines, times(table), {}, {}};
  for (std::size_t row = 0; row < table.rows(); ++row) {
    out.dtheta_rad.push_back(triple(table, row, "dtheta_", "_rad"));
    out.dv_m_s.push_back(triple(table, row, "dv_", "_mps"));
    if (out.dtheta_rad.back().norm() > 1.0) {
      throw InputError(table.file, table.lines[row], "dtheta_x_rad",
                       "an angle increment above 1 rad per sample: not rad, or not increments");
    }
  }
  return out;
}

InsAttitude read_psins_attitude_csv(const std::filesystem::path& file) {
  const NumericTable table = read_numeric_table(file);
  InsAttitude out{table.file, times(table), {}};
  const std::size_t pitch = table.column("pitch_rad");
  const std::size_t roll = table.column("roll_rad");
  const std::size_t yaw = table.column("yaw_rad");
  for (std::size_t row = 0; row < table.rows(); ++row) {
    for (std::size_t c : {pitch, roll, yaw}) {
      if (std::abs(table.at(row, c)) > 2.0 * M_PI) {
        throw InputError(table.file, table.lines[row], table.columns[c],
                         fmt::format("{} is beyond 2 pi: not rad", table.at(row, c)));
      }
    }
    out.q_N_B.push_back(
        psins_attitude(table.at(row, pitch), table.at(row, roll), table.at(row, yaw)));
  }
  return out;
}

ToolImuRecord master_slave_record(const IncrementImu& slave, const InsAttitude& master) {
  ToolImuRecord record;
  record.file = slave.file;
  record.has_raw_imu = true;
  std::size_t j = 0;  // master sample at or before t
  for (std::size_t k = 1; k < slave.t_end_s.size(); ++k) {
    const double dt = slave.t_end_s[k] - slave.t_end_s[k - 1];
    const double t = slave.t_end_s[k] - 0.5 * dt;
    record.lines.push_back(slave.lines[k]);
    record.t_s.push_back(t);
    record.gyro_rad_s.push_back(slave.dtheta_rad[k] / dt);
    record.acc_m_s2.push_back(slave.dv_m_s[k] / dt);
    record.robot_position_m.push_back(Eigen::Vector3d::Zero());
    record.robot_quaternion_norm.push_back(1.0);
    while (j + 1 < master.t_s.size() && master.t_s[j + 1] <= t) ++j;
    const bool inside = t >= master.t_s.front() && t <= master.t_s.back();
    Eigen::Quaterniond q = master.q_N_B[j];
    if (inside && j + 1 < master.t_s.size()) {
      const double fraction = (t - master.t_s[j]) / (master.t_s[j + 1] - master.t_s[j]);
      q = master.q_N_B[j].slerp(fraction, master.q_N_B[j + 1]);
    }
    record.q_B_T.push_back(q.normalized());
    record.robot_pose_valid.push_back(inside);
  }
  return record;
}

}  // namespace imscal::calib
