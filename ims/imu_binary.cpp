#include "ims/imu_binary.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <vector>

#include "core/input_error.hpp"
#include "core/input_file.hpp"
#include "ims/huge_pages.hpp"

namespace imscal::ims {
namespace fs = std::filesystem;

namespace {

constexpr std::size_t kValuesPerRecord = 7;
constexpr std::size_t kRecordBytes = kValuesPerRecord * sizeof(double);
constexpr std::uint32_t kVersion = 1;

template <typename T>
T from_little_endian(const char* bytes) {
  T value;
  std::memcpy(&value, bytes, sizeof(T));
  if constexpr (std::endian::native == std::endian::big) {
    auto raw = std::bit_cast<std::array<char, sizeof(T)>>(value);
    std::reverse(raw.begin(), raw.end());
    value = std::bit_cast<T>(raw);
  }
  return value;
}

template <typename T>
void append_little_endian(std::string& out, T value) {
  auto raw = std::bit_cast<std::array<char, sizeof(T)>>(value);
  if constexpr (std::endian::native == std::endian::big) std::reverse(raw.begin(), raw.end());
  out.append(raw.data(), raw.size());
}

// Sequential reader of the header that turns a short read into an error naming the field.
class HeaderReader {
 public:
  HeaderReader(std::ifstream& in, std::string file, std::uint64_t file_size)
      : in_(in), file_(std::move(file)), file_size_(file_size) {}

  template <typename T>
  T read(const char* field) {
    char bytes[sizeof(T)];
    bytes_(bytes, sizeof(T), field);
    return from_little_endian<T>(bytes);
  }
  std::string read_text(const char* field) {
    const auto length = read<std::uint32_t>(field);
    if (length > file_size_ - offset_) {
      throw InputError(file_, 0, field,
                       fmt::format("text length {} at byte {} runs past the end of the file ({} "
                                   "bytes): the file is truncated or corrupt",
                                   length, offset_ - 4, file_size_));
    }
    std::string text(length, '\0');
    bytes_(text.data(), length, field);
    return text;
  }
  std::uint64_t offset() const { return offset_; }
  std::uint64_t file_size() const { return file_size_; }

 private:
  void bytes_(char* out, std::size_t count, const char* field) {
    if (file_size_ - offset_ < count || !in_.read(out, static_cast<std::streamsize>(count))) {
      throw InputError(file_, 0, field,
                       fmt::format("truncated header: the file ends at byte {} inside field '{}' "
                                   "(at byte {})",
                                   file_size_, field, offset_));
    }
    offset_ += count;
  }
  std::ifstream& in_;
  std::string file_;
  std::uint64_t file_size_;
  std::uint64_t offset_ = 0;
};

}  // namespace

ImuSeries read_imu_binary(const fs::path& path, const ImuReadOptions& options,
                          ImuReadReport* report) {
  if (report != nullptr) *report = ImuReadReport{};
  const std::string file = path.string();
  std::error_code error;
  const std::uint64_t file_size = fs::file_size(path, error);
  std::ifstream in = open_input_stream(path);
  if (error) throw InputError(file, 0, "", "cannot open the file: " + error.message());
  if (file_size == 0) {
    throw InputError(file, 0, "magic", "the file is empty; expected an imscal IMU binary file");
  }
  HeaderReader header(in, file, file_size);

  std::array<char, 8> magic{};
  for (char& c : magic) c = header.read<char>("magic");
  if (std::string_view(magic.data(), magic.size()) != kImuBinaryMagic) {
    throw InputError(
        file, 0, "magic",
        "not an imscal IMU binary file: the first 8 bytes are not \"IMSB\\r\\n\\x1a\\n\"");
  }
  const auto version = header.read<std::uint32_t>("version");
  if (version != kVersion) {
    throw InputError(
        file, 0, "version",
        fmt::format("unsupported version {}; this reader knows {}", version, kVersion));
  }
  ImuSeries series;
  series.source = file;
  const auto quantity = header.read<std::uint32_t>("quantity");
  if (quantity > 1) {
    throw InputError(
        file, 0, "quantity",
        fmt::format("{} is not a quantity; expected 0 (increments) or 1 (rates)", quantity));
  }
  series.quantity = quantity == 0 ? ImuQuantity::kIncrements : ImuQuantity::kRates;
  series.nominal_dt_s = header.read<double>("nominal_dt_s");
  const auto has_site = header.read<std::uint32_t>("has_site");
  Site site;
  site.latitude_deg = header.read<double>("site_latitude_deg");
  site.longitude_deg = header.read<double>("site_longitude_deg");
  site.height_m = header.read<double>("site_height_m");
  if (has_site > 1) {
    throw InputError(file, 0, "has_site", fmt::format("{} is not 0 or 1", has_site));
  }
  if (has_site == 1) {
    if (!(std::abs(site.latitude_deg) <= 90.0) || !(std::abs(site.longitude_deg) <= 360.0) ||
        !std::isfinite(site.height_m)) {
      throw InputError(file, 0, "site_latitude_deg",
                       fmt::format("the site ({}, {}, {}) is not a geodetic position",
                                   site.latitude_deg, site.longitude_deg, site.height_m));
    }
    series.site = site;
  }
  const auto n_metadata = header.read<std::uint32_t>("metadata");
  for (std::uint32_t k = 0; k < n_metadata; ++k) {
    std::string key = header.read_text("metadata");
    std::string value = header.read_text("metadata");
    series.metadata.emplace_back(std::move(key), std::move(value));
  }
  const auto n_records = header.read<std::uint64_t>("sample_count");

  // Size check before reading any record: a truncated file names its first incomplete record.
  const std::uint64_t data_bytes = file_size - header.offset();
  const ImuColumnNames names = si_column_names(series.quantity);
  if (data_bytes / kRecordBytes < n_records) {
    const std::uint64_t complete = data_bytes / kRecordBytes;
    const std::uint64_t partial_values = (data_bytes % kRecordBytes) / sizeof(double);
    throw InputError(file, 0, names[partial_values],
                     fmt::format("record {} of {}: the file is truncated: it holds {} bytes of "
                                 "records, {} complete record(s) of {} bytes, and record {} ends "
                                 "before field '{}'",
                                 complete + 1, n_records, data_bytes, complete, kRecordBytes,
                                 complete + 1, names[partial_values]));
  }
  if (data_bytes != n_records * kRecordBytes) {
    throw InputError(file, 0, "sample_count",
                     fmt::format("{} bytes follow the {} records the header announces; the file "
                                 "is corrupt or the record count is wrong",
                                 data_bytes - n_records * kRecordBytes, n_records));
  }

  // Records, decoded chunk by chunk so that the buffer stays in cache, and validated while the
  // decoded samples are still in cache.
  ImuSourceInfo info;
  info.record_count = static_cast<std::size_t>(n_records);
  ImuValidator validator(series, options, report, info);
  if (options.samples_to_file) series.samples.spill_to_file();
  series.samples.reserve(n_records);
  advise_huge_pages(series.samples.data(), n_records * sizeof(ImuSample));
  constexpr std::size_t kChunkRecords = 4096;
  std::vector<char> buffer(kChunkRecords * kRecordBytes);
  for (std::uint64_t done = 0; done < n_records;) {
    const std::size_t count =
        static_cast<std::size_t>(std::min<std::uint64_t>(kChunkRecords, n_records - done));
    if (!in.read(buffer.data(), static_cast<std::streamsize>(count * kRecordBytes))) {
      throw InputError(file, 0, names[0],
                       fmt::format("record {} of {}: read error (was the file changed while "
                                   "being read?)",
                                   done + 1, n_records));
    }
    for (std::size_t r = 0; r < count; ++r) {
      const char* record = buffer.data() + r * kRecordBytes;
      double v[kValuesPerRecord];
      for (std::size_t c = 0; c < kValuesPerRecord; ++c) {
        v[c] = from_little_endian<double>(record + c * sizeof(double));
      }
      series.samples.push_back(
          ImuSample{v[0], Eigen::Vector3d(v[1], v[2], v[3]), Eigen::Vector3d(v[4], v[5], v[6])});
    }
    done += count;
    validator.check_up_to(series.samples.size());
  }
  validator.finish();
  return series;
}

void write_imu_binary(const fs::path& path, const ImuSeries& series, Overwrite overwrite) {
  std::string out;
  out.append(kImuBinaryMagic);
  append_little_endian<std::uint32_t>(out, kVersion);
  append_little_endian<std::uint32_t>(out, series.quantity == ImuQuantity::kRates ? 1 : 0);
  append_little_endian<double>(out, series.nominal_dt_s);
  append_little_endian<std::uint32_t>(out, series.site ? 1 : 0);
  const Site site = series.site.value_or(Site{});
  append_little_endian<double>(out, site.latitude_deg);
  append_little_endian<double>(out, site.longitude_deg);
  append_little_endian<double>(out, site.height_m);
  append_little_endian<std::uint32_t>(out, static_cast<std::uint32_t>(series.metadata.size()));
  for (const auto& [key, value] : series.metadata) {
    append_little_endian<std::uint32_t>(out, static_cast<std::uint32_t>(key.size()));
    out += key;
    append_little_endian<std::uint32_t>(out, static_cast<std::uint32_t>(value.size()));
    out += value;
  }
  append_little_endian<std::uint64_t>(out, series.samples.size());

  AtomicFile file(path, overwrite, /*binary=*/true);
  constexpr std::size_t kChunk = 1u << 20;
  for (std::size_t i = 0; i < series.samples.size(); ++i) {
    for (const double value : finite_sample_values(series, i)) {
      append_little_endian<double>(out, value);
    }
    if (out.size() >= kChunk) {
      file.stream().write(out.data(), static_cast<std::streamsize>(out.size()));
      out.clear();
    }
  }
  file.stream().write(out.data(), static_cast<std::streamsize>(out.size()));
  file.commit();
}

}  // namespace imscal::ims
