#pragma once
// The compact binary form of a raw IMS record, extension ".imsb" (specified in
// datasets/FORMAT.md). It holds exactly what the CSV form holds, in SI units, as little-endian
// IEEE-754 doubles, so that it reads several times faster than text and round-trips bit-exactly:
//
//   offset  bytes  field
//   0       8      magic "IMSB\r\n\x1a\n" (the line-ending bytes catch text-mode corruption)
//   8       4      uint32 version = 1
//   12      4      uint32 quantity: 0 = increments, 1 = rates
//   16      8      float64 nominal_dt_s
//   24      4      uint32 has_site: 0 or 1
//   28      24     float64 site_latitude_deg, site_longitude_deg, site_height_m (0 if no site)
//   52      4      uint32 metadata entry count N
//   56      ...    N x (uint32 key length, key bytes, uint32 value length, value bytes), UTF-8
//   ...     8      uint64 record count M
//   ...     56*M   M records of 7 float64: t_s, gyro x y z, acc x y z (as in the CSV columns)
//
// The file size must be exactly the header plus 56*M bytes: a shorter file is truncated, and the
// error names the first incomplete record and field.
#include <filesystem>
#include <string_view>

#include "core/atomic_file.hpp"
#include "ims/imu_data.hpp"
#include "ims/imu_validation.hpp"

namespace imscal::ims {

inline constexpr std::string_view kImuBinaryMagic{"IMSB\r\n\x1a\n", 8};
inline constexpr std::string_view kImuBinaryExtension = ".imsb";

// Reads and validates (ims/imu_validation.hpp). Errors are InputError with line 0; the record
// number (1-based) is in the message, the field is the column name ("acc_x_m_s2") or the header
// field ("nominal_dt_s", "metadata"). The file is only read.
ImuSeries read_imu_binary(const std::filesystem::path& file, const ImuReadOptions& options = {},
                          ImuReadReport* report = nullptr);

// Writes atomically. Throws std::invalid_argument for non-finite values, std::runtime_error if
// the target exists under Overwrite::kRefuse or on I/O errors.
void write_imu_binary(const std::filesystem::path& file, const ImuSeries& series,
                      Overwrite overwrite);

}  // namespace imscal::ims
