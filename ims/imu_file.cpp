#include "ims/imu_file.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <fstream>
#include <stdexcept>
#include <string>

#include "core/input_error.hpp"
#include "core/input_file.hpp"
#include "ims/imu_binary.hpp"
#include "ims/imu_csv.hpp"
#include "ims/psins_reader.hpp"

namespace imscal::ims {
namespace fs = std::filesystem;

namespace {
std::string lower_extension(const fs::path& file) {
  std::string extension = file.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension;
}
}  // namespace

ImuFileKind imu_file_kind(const fs::path& file) {
  const std::string extension = lower_extension(file);
  if (extension == ".csv") return ImuFileKind::kCsv;
  if (extension == kImuBinaryExtension) return ImuFileKind::kBinary;
  if (extension == ".imu") return ImuFileKind::kPsins;
  std::ifstream in = open_input_stream(file);
  std::string start(16, '\0');
  in.read(start.data(), static_cast<std::streamsize>(start.size()));
  start.resize(static_cast<std::size_t>(in.gcount()));
  if (start.starts_with(kImuBinaryMagic)) return ImuFileKind::kBinary;
  if (start.starts_with("# imscal-imu:")) return ImuFileKind::kCsv;
  throw InputError(file.string(), 1, "",
                   fmt::format("unknown IMU file kind: the extension '{}' is none of .csv, {}, "
                               ".imu and the content is neither imscal CSV nor binary",
                               extension, kImuBinaryExtension));
}

ImuSeries read_imu_file(const fs::path& file, const ImuReadOptions& options,
                        ImuReadReport* report) {
  switch (imu_file_kind(file)) {
    case ImuFileKind::kCsv:
      return read_imu_csv(file, options, report);
    case ImuFileKind::kBinary:
      return read_imu_binary(file, options, report);
    case ImuFileKind::kPsins: {
      if (report != nullptr) *report = ImuReadReport{};
      ImuSeries series = read_psins(file);
      validate_imu_series(series, options, report);
      return series;
    }
  }
  throw std::logic_error("read_imu_file: unhandled file kind");
}

void write_imu_file(const fs::path& file, const ImuSeries& series, Overwrite overwrite) {
  const std::string extension = lower_extension(file);
  if (extension == ".csv") {
    write_imu_csv(file, series, overwrite);
  } else if (extension == kImuBinaryExtension) {
    write_imu_binary(file, series, overwrite);
  } else {
    throw std::invalid_argument(
        fmt::format("{}: cannot write IMU files with extension '{}'; use .csv or {}", file.string(),
                    extension, kImuBinaryExtension));
  }
}

}  // namespace imscal::ims
