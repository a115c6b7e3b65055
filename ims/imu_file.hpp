#pragma once
// One entry point for raw IMS files of every kind imscal reads, chosen by the extension
// (case-insensitive) and, for other extensions, by the first bytes:
//   .csv   the project's CSV form            (ims/imu_csv.hpp)
//   .imsb  the project's binary form         (ims/imu_binary.hpp)
//   .imu   a PSINS toolbox log (read only)   (ims/psins_reader.hpp)
// Every kind is validated with the same checks (ims/imu_validation.hpp).
#include <filesystem>

#include "core/atomic_file.hpp"
#include "ims/imu_data.hpp"
#include "ims/imu_validation.hpp"

namespace imscal::ims {

enum class ImuFileKind { kCsv, kBinary, kPsins };

// By extension; otherwise by content (binary magic, or a first line "# imscal-imu:"). Throws
// InputError if neither tells.
ImuFileKind imu_file_kind(const std::filesystem::path& file);

ImuSeries read_imu_file(const std::filesystem::path& file, const ImuReadOptions& options = {},
                        ImuReadReport* report = nullptr);

// .csv or .imsb by extension; anything else (PSINS included) is refused with
// std::invalid_argument, before any file is touched.
void write_imu_file(const std::filesystem::path& file, const ImuSeries& series,
                    Overwrite overwrite);

}  // namespace imscal::ims
