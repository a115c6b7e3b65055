#pragma once
// The project's own CSV form of a raw IMS record (specified in datasets/FORMAT.md):
//
//   # imscal-imu: 1
//   # quantity: increments            (or: rates)
//   # nominal_dt_s: 0.001
//   # site_latitude_deg: 48.7         (optional; the three site keys go together)
//   # site_longitude_deg: 9.1
//   # site_height_m: 380
//   # any_other_key: any value         (kept in ImuSeries::metadata, in order)
//   t_s,dtheta_x_rad,dtheta_y_rad,dtheta_z_rad,dv_x_m_s,dv_y_m_s,dv_z_m_s
//   0.001,1.2e-06,...
//
// Rates use t_s,gyro_x_rad_s,gyro_y_rad_s,gyro_z_rad_s,acc_x_m_s2,acc_y_m_s2,acc_z_m_s2.
// Columns in other named units (gyro_x_deg_s, acc_x_g, dtheta_x_deg, dv_x_mm_s, t_ms, ...) are
// converted to SI on reading, with a warning naming the conversion. Increments are stamped at
// the END of their interval (ims/imu_data.hpp).
//
// Reading maps the file once and parses it with std::from_chars; the writer prints the
// shortest representation that reads back to the same double (std::to_chars), so a
// write/read round trip is bit-exact.
#include <filesystem>

#include "core/atomic_file.hpp"
#include "ims/imu_data.hpp"
#include "ims/imu_validation.hpp"

namespace imscal::ims {

// Reads and validates (ims/imu_validation.hpp); throws InputError naming file, line and field.
// Sample i of the result is on line first_data_line + i. The file is only read.
ImuSeries read_imu_csv(const std::filesystem::path& file, const ImuReadOptions& options = {},
                       ImuReadReport* report = nullptr);

// Writes atomically (nothing is left behind on failure). Throws std::invalid_argument for data
// the format cannot hold (non-finite values, metadata with line breaks, ...), and
// std::runtime_error if the target exists under Overwrite::kRefuse or on I/O errors.
void write_imu_csv(const std::filesystem::path& file, const ImuSeries& series, Overwrite overwrite);

// The CSV text itself (what write_imu_csv writes), for small series and tests.
std::string format_imu_csv(const ImuSeries& series);

}  // namespace imscal::ims
