#include "ims/imu_csv.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <map>
#include <numbers>
#include <stdexcept>
#include <string_view>
#include <vector>

#include "core/csv_text.hpp"
#include "core/input_error.hpp"
#include "core/input_file.hpp"
#include "core/spill_mapping.hpp"
#include "core/units.hpp"
#include "ims/huge_pages.hpp"

namespace imscal::ims {
namespace fs = std::filesystem;

namespace {

constexpr std::size_t kColumns = 7;
constexpr std::size_t kValidationBatch = 4096;  // samples; a power of two

// ---------------------------------------------------------------------------------------------
// Column names and their units.

struct Unit {
  std::string_view suffix;  // as in the column name: "deg_s"
  double to_si;             // factor to the SI unit
  std::string_view label;   // for messages: "deg/s"
};

const std::vector<Unit>& units_of(std::size_t column, ImuQuantity quantity) {
  static const std::vector<Unit> time = {{"s", 1.0, "s"}, {"ms", 1e-3, "ms"}, {"us", 1e-6, "us"}};
  static const std::vector<Unit> rate = {{"rad_s", 1.0, "rad/s"},
                                         {"deg_s", kRadPerDeg, "deg/s"},
                                         {"deg_h", kRadPerDeg / 3600.0, "deg/h"}};
  static const std::vector<Unit> force = {{"m_s2", 1.0, "m/s^2"},
                                          {"g", kStandardGravity_m_s2, "g"},
                                          {"mg", kStandardGravity_m_s2 * 1e-3, "mg"}};
  static const std::vector<Unit> angle = {{"rad", 1.0, "rad"},
                                          {"deg", kRadPerDeg, "deg"},
                                          {"mrad", 1e-3, "mrad"},
                                          {"urad", 1e-6, "urad"},
                                          {"arcsec", kRadPerDeg / 3600.0, "arcsec"}};
  static const std::vector<Unit> velocity = {
      {"m_s", 1.0, "m/s"}, {"mm_s", 1e-3, "mm/s"}, {"g_s", kStandardGravity_m_s2, "g*s"}};
  if (column == 0) return time;
  const bool rates = quantity == ImuQuantity::kRates;
  if (column <= 3) return rates ? rate : angle;
  return rates ? force : velocity;
}

// "t", "gyro_x", "dv_z", ...: the column name without its unit.
std::string base_name(std::size_t column, ImuQuantity quantity) {
  if (column == 0) return "t";
  const bool rates = quantity == ImuQuantity::kRates;
  const char axis = "xyz"[(column - 1) % 3];
  const char* family = column <= 3 ? (rates ? "gyro" : "dtheta") : (rates ? "acc" : "dv");
  return fmt::format("{}_{}", family, axis);
}

std::string_view quantity_name(ImuQuantity quantity) {
  return quantity == ImuQuantity::kRates ? "rates" : "increments";
}

std::string joined(const ImuColumnNames& names) {
  std::string text;
  for (const auto& n : names) text += (text.empty() ? "" : ",") + n;
  return text;
}

using csv::parse_number;
using csv::trim;

// Matches a column name against the expected one; returns the factor to SI.
double column_factor(const std::string& file, std::size_t line, std::size_t column,
                     const std::string& name, ImuQuantity quantity) {
  const std::string base = base_name(column, quantity);
  const std::string si = si_column_names(quantity)[column];
  std::string alternatives;
  for (const auto& u : units_of(column, quantity)) {
    alternatives += fmt::format("{}{}_{}", alternatives.empty() ? "" : ", ", base, u.suffix);
  }
  if (name.starts_with(base + "_")) {
    const std::string_view suffix = std::string_view(name).substr(base.size() + 1);
    for (const auto& u : units_of(column, quantity)) {
      if (u.suffix == suffix) return u.to_si;
    }
    throw InputError(file, line, name,
                     fmt::format("unknown unit '{}' for column {}; accepted: {}", suffix,
                                 column + 1, alternatives));
  }
  const ImuQuantity other =
      quantity == ImuQuantity::kRates ? ImuQuantity::kIncrements : ImuQuantity::kRates;
  const std::string other_base = base_name(column, other);
  const std::string other_family = other_base.substr(0, other_base.find('_') + 1);  // "dv_"
  if (column > 0 && name.starts_with(other_family)) {
    throw InputError(
        file, line, name,
        fmt::format("column '{}' holds {}, but the header declares '# quantity: {}'; expected "
                    "'{}' in column {}",
                    name, quantity_name(other), quantity_name(quantity), si, column + 1));
  }
  throw InputError(file, line, name,
                   fmt::format("unexpected column '{}' in column {}; expected '{}' (or one of: {})",
                               name, column + 1, si, alternatives));
}

// ---------------------------------------------------------------------------------------------
// The file, mapped read-only (the input is never modified).

// Before the file is mapped (and paged in): a file whose first byte, after a byte-order mark,
// is not the '#' of '# imscal-imu: 1' is refused without reading further.
void check_first_byte(int fd, const fs::path& path) {
  char start[4] = {};
  const ssize_t got = ::pread(fd, start, sizeof start, 0);
  if (got <= 0) return;  // empty (refused later with its own message) or unreadable
  const std::string_view head(start, static_cast<std::size_t>(got));
  const std::size_t skip = head.starts_with(kUtf8ByteOrderMark) ? kUtf8ByteOrderMark.size() : 0;
  if (head.size() > skip && head[skip] != '#') {
    throw InputError(path.string(), 1, "imscal-imu",
                     "not an imscal IMU CSV file: the first line must be '# imscal-imu: 1'");
  }
}

class MappedFile {
 public:
  // `released`: the pages leave resident memory behind a reader of one pass
  // (core/spill_mapping.hpp) instead of being mapped all at once.
  MappedFile(const fs::path& path, bool released) : fd_(open_regular_file(path)) {
    struct stat status {};
    if (::fstat(fd_, &status) != 0) {
      const int error = errno;
      ::close(fd_);
      throw InputError(path.string(), 0, "",
                       fmt::format("cannot read the file's status: {}", std::strerror(error)));
    }
    size_ = static_cast<std::size_t>(status.st_size);
    if (size_ == 0) return;
    try {
      check_first_byte(fd_, path);
    } catch (...) {
      ::close(fd_);
      throw;
    }
    void* mapped =
        ::mmap(nullptr, size_, PROT_READ, MAP_PRIVATE | (released ? 0 : MAP_POPULATE), fd_, 0);
    if (mapped == MAP_FAILED) {
      const int error = errno;
      ::close(fd_);
      throw InputError(path.string(), 0, "",
                       fmt::format("cannot map the file: {}", std::strerror(error)));
    }
    data_ = static_cast<const char*>(mapped);
    ::madvise(mapped, size_, MADV_SEQUENTIAL);
    if (released) watch_resident_pages(data_, size_);
    released_ = released;
  }
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;
  ~MappedFile() {
    if (data_ != nullptr && released_) unwatch_resident_pages(data_);
    if (data_ != nullptr) ::munmap(const_cast<char*>(data_), size_);
    ::close(fd_);
  }
  const char* data() const { return data_; }
  std::size_t size() const { return size_; }

 private:
  int fd_ = -1;
  const char* data_ = nullptr;
  std::size_t size_ = 0;
  bool released_ = false;
};

// ---------------------------------------------------------------------------------------------
// Header.

struct Header {
  std::optional<ImuQuantity> quantity;
  std::optional<double> nominal_dt_s;
  std::size_t nominal_dt_line = 0;
  std::optional<double> latitude_deg, longitude_deg, height_m;
  std::size_t site_line = 0;
  std::vector<std::pair<std::string, std::string>> metadata;
  std::map<std::string, std::size_t, std::less<>> seen;  // key -> line
};

bool is_reserved_key(std::string_view key) {
  return key == "imscal-imu" || key == "quantity" || key == "nominal_dt_s" ||
         key == "site_latitude_deg" || key == "site_longitude_deg" || key == "site_height_m";
}

void parse_header_line(const std::string& file, std::size_t line, std::string_view text,
                       Header& header) {
  // text starts with '#'
  const std::string_view body = text.substr(1);
  const auto colon = body.find(':');
  if (colon == std::string_view::npos) {
    throw InputError(file, line, "header",
                     fmt::format("a header line must read '# key: value'; found '{}'", text));
  }
  const std::string key(trim(body.substr(0, colon)));
  const std::string value(trim(body.substr(colon + 1)));
  if (key.empty()) {
    throw InputError(file, line, "header", fmt::format("empty key in header line '{}'", text));
  }
  if (line == 1 && key != "imscal-imu") {
    throw InputError(file, line, "imscal-imu",
                     fmt::format("not an imscal IMU CSV file: the first line must be "
                                 "'# imscal-imu: 1', found '{}'",
                                 text));
  }
  if (auto [it, inserted] = header.seen.emplace(key, line); !inserted) {
    throw InputError(file, line, key,
                     fmt::format("header key '{}' repeats line {}", key, it->second));
  }
  auto number = [&](double low, double high, const char* what) {
    double v = 0.0;
    if (!parse_number(value, v) || !std::isfinite(v) || v < low || v > high) {
      throw InputError(file, line, key,
                       fmt::format("'{}' is not {} in [{}, {}]", value, what, low, high));
    }
    return v;
  };
  if (key == "imscal-imu") {
    if (value != "1") {
      throw InputError(file, line, key,
                       fmt::format("unsupported format version '{}'; this reader knows 1", value));
    }
  } else if (key == "quantity") {
    if (value == "increments") {
      header.quantity = ImuQuantity::kIncrements;
    } else if (value == "rates") {
      header.quantity = ImuQuantity::kRates;
    } else {
      throw InputError(
          file, line, key,
          fmt::format("'{}' is not a quantity; expected 'increments' or 'rates'", value));
    }
  } else if (key == "nominal_dt_s") {
    header.nominal_dt_s = number(1e-9, 1e3, "a sample interval [s]");
    header.nominal_dt_line = line;
  } else if (key == "site_latitude_deg") {
    header.latitude_deg = number(-90.0, 90.0, "a latitude [deg]");
    header.site_line = line;
  } else if (key == "site_longitude_deg") {
    header.longitude_deg = number(-180.0, 360.0, "a longitude [deg]");
    header.site_line = line;
  } else if (key == "site_height_m") {
    header.height_m = number(-1e4, 1e5, "a height above the ellipsoid [m]");
    header.site_line = line;
  } else {
    header.metadata.emplace_back(key, value);
  }
}

// ---------------------------------------------------------------------------------------------
// Errors inside a data line: what is wrong with field `column` of the line at line_begin.

const char* end_of_line(const char* p, const char* end) {
  const void* eol = std::memchr(p, '\n', static_cast<std::size_t>(end - p));
  return eol != nullptr ? static_cast<const char*>(eol) : end;
}

std::size_t count_fields(std::string_view line) {
  return static_cast<std::size_t>(std::count(line.begin(), line.end(), ',')) + 1;
}

[[noreturn]] void fail_data_line(const std::string& file, std::size_t line,
                                 const ImuColumnNames& columns, const char* line_begin,
                                 const char* at, const char* end, std::size_t column) {
  const char* eol = end_of_line(line_begin, end);
  const std::string_view text = trim(std::string_view(line_begin, eol - line_begin));
  if (text.empty()) {
    throw InputError(file, line, columns[0],
                     fmt::format("empty line; expected {} comma-separated numbers", kColumns));
  }
  const std::size_t fields = count_fields(text);
  if (fields != kColumns) {
    const std::size_t named = std::min(fields, kColumns - 1);
    throw InputError(
        file, line, columns[fields < kColumns ? fields : named],
        fmt::format("the line has {} fields; expected {} ({})", fields, kColumns, joined(columns)));
  }
  const char* field_end = at;
  while (field_end < eol && *field_end != ',') ++field_end;
  const char* field_begin = at;
  while (field_begin > line_begin && field_begin[-1] != ',') --field_begin;
  const std::string_view field = trim(std::string_view(field_begin, field_end - field_begin));
  if (field.empty()) {
    throw InputError(file, line, columns[column], "empty field; expected a number");
  }
  double ignored = 0.0;
  const auto [ptr, ec] = std::from_chars(field.data(), field.data() + field.size(), ignored);
  if (ec == std::errc::result_out_of_range) {
    throw InputError(file, line, columns[column],
                     fmt::format("'{}' is out of the range of a double", field));
  }
  throw InputError(file, line, columns[column], fmt::format("'{}' is not a number", field));
}

// ---------------------------------------------------------------------------------------------
// Writing.

void check_header_text(std::string_view text, const char* what) {
  if (text.find_first_of("\r\n") != std::string_view::npos || trim(text) != text) {
    throw std::invalid_argument(
        fmt::format("IMU CSV metadata {} '{}' has a line break or surrounding blanks", what, text));
  }
}

template <typename Flush>
void format_csv(const ImuSeries& series, std::string& out, Flush flush) {
  out += "# imscal-imu: 1\n# quantity: ";
  out += quantity_name(series.quantity);
  out += "\n# nominal_dt_s: ";
  csv::append_shortest(out, series.nominal_dt_s);
  out += '\n';
  if (series.site) {
    out += "# site_latitude_deg: ";
    csv::append_shortest(out, series.site->latitude_deg);
    out += "\n# site_longitude_deg: ";
    csv::append_shortest(out, series.site->longitude_deg);
    out += "\n# site_height_m: ";
    csv::append_shortest(out, series.site->height_m);
    out += '\n';
  }
  for (const auto& [key, value] : series.metadata) {
    check_header_text(key, "key");
    check_header_text(value, "value");
    if (key.empty() || key.find(':') != std::string::npos || is_reserved_key(key)) {
      throw std::invalid_argument(
          fmt::format("IMU CSV metadata key '{}' is empty, has a ':' or is reserved", key));
    }
    out += "# " + key + ": " + value + '\n';
  }
  out += joined(si_column_names(series.quantity)) + '\n';
  for (std::size_t i = 0; i < series.samples.size(); ++i) {
    const std::array<double, kColumns> values = finite_sample_values(series, i);
    for (std::size_t c = 0; c < kColumns; ++c) {
      csv::append_shortest(out, values[c]);
      out += c + 1 < kColumns ? ',' : '\n';
    }
    flush(out);
  }
}

}  // namespace

ImuSeries read_imu_csv(const fs::path& path, const ImuReadOptions& options, ImuReadReport* report) {
  if (report != nullptr) *report = ImuReadReport{};
  const std::string file = path.string();
  const MappedFile mapped(path, options.samples_to_file);
  const std::string_view whole(mapped.data(), mapped.size());
  const std::size_t mark = whole.starts_with(kUtf8ByteOrderMark) ? kUtf8ByteOrderMark.size() : 0;
  if (mark > 0) {
    add_imu_warning(report,
                    fmt::format("{}: a UTF-8 byte-order mark at the start was skipped", file));
  }
  const char* const begin = mapped.data() + mark;
  const char* const end = mapped.data() + mapped.size();
  if (begin == end) {
    throw InputError(file, 1, "imscal-imu",
                     "the file is empty; expected the header line '# imscal-imu: 1'");
  }

  // Header lines.
  Header header;
  const char* p = begin;
  std::size_t line = 0;
  while (p < end && *p == '#') {
    ++line;
    const char* eol = end_of_line(p, end);
    parse_header_line(file, line, trim(std::string_view(p, eol - p)), header);
    p = eol < end ? eol + 1 : end;
  }
  if (line == 0) {
    throw InputError(file, 1, "imscal-imu",
                     "not an imscal IMU CSV file: the first line must be '# imscal-imu: 1'");
  }
  const std::size_t column_line = line + 1;
  if (!header.quantity) {
    throw InputError(file, column_line, "quantity",
                     fmt::format("the header (lines 1-{}) lacks '# quantity: increments' or "
                                 "'# quantity: rates'",
                                 line));
  }
  if (!header.nominal_dt_s) {
    throw InputError(
        file, column_line, "nominal_dt_s",
        fmt::format("the header (lines 1-{}) lacks '# nominal_dt_s: <seconds>'", line));
  }
  if (header.latitude_deg.has_value() != header.longitude_deg.has_value() ||
      (header.height_m && !header.latitude_deg)) {
    throw InputError(file, header.site_line,
                     header.latitude_deg ? "site_longitude_deg" : "site_latitude_deg",
                     "a site needs both site_latitude_deg and site_longitude_deg");
  }

  ImuSeries series;
  series.source = file;
  series.quantity = *header.quantity;
  series.nominal_dt_s = *header.nominal_dt_s;
  series.metadata = std::move(header.metadata);
  if (header.latitude_deg) {
    series.site = Site{*header.latitude_deg, *header.longitude_deg, header.height_m.value_or(0.0)};
  }

  // Column names.
  const ImuColumnNames si_names = si_column_names(series.quantity);
  if (p >= end) {
    throw InputError(
        file, column_line, si_names[0],
        fmt::format("no column-name line after the header; expected '{}'", joined(si_names)));
  }
  ImuColumnNames names;
  std::array<double, kColumns> factor{};
  {
    const char* eol = end_of_line(p, end);
    const std::string_view text = trim(std::string_view(p, eol - p));
    std::size_t count = 0;
    std::size_t start = 0;
    while (true) {
      const auto comma = text.find(',', start);
      const std::string name(trim(text.substr(start, comma - start)));
      if (count < kColumns) names[count] = name;
      ++count;
      if (comma == std::string_view::npos) break;
      start = comma + 1;
    }
    if (count != kColumns) {
      throw InputError(file, column_line, count < kColumns ? si_names[count] : names[kColumns - 1],
                       fmt::format("the column line has {} names; expected {}: '{}'", count,
                                   kColumns, joined(si_names)));
    }
    for (std::size_t c = 0; c < kColumns; ++c) {
      factor[c] = column_factor(file, column_line, c, names[c], series.quantity);
    }
    p = eol < end ? eol + 1 : end;
  }

  // A complete file ends with a newline; a last line without one was cut off.
  if (end[-1] != '\n' && !options.allow_missing_final_newline) {
    const char* last = end;
    while (last > begin && last[-1] != '\n') --last;
    const std::size_t last_line = static_cast<std::size_t>(std::count(begin, end, '\n')) + 1;
    const std::size_t fields = count_fields(std::string_view(last, end - last));
    throw InputError(file, last_line, names[std::min(fields, kColumns) - 1],
                     fmt::format("truncated last line: {} field(s) and no end-of-line; a complete "
                                 "file ends with a newline (ImuReadOptions::"
                                 "allow_missing_final_newline accepts it)",
                                 fields));
  }

  series.first_data_line = column_line + 1;
  {
    std::string_view rest(p, end - p);
    if (rest.find_first_not_of(" \t\r\n") == std::string_view::npos) {
      throw InputError(file, series.first_data_line, names[0],
                       "no data lines after the column names");
    }
  }

  // Non-SI columns: one warning per unit, naming the conversion.
  struct Conversion {
    double factor = 1.0;
    std::string columns;
  };
  std::map<std::string, Conversion> conversions;  // "deg/s converted to rad/s" -> columns
  for (std::size_t c = 0; c < kColumns; ++c) {
    if (factor[c] == 1.0) continue;
    const std::string suffix = names[c].substr(base_name(c, series.quantity).size() + 1);
    std::string_view label, si_label;
    for (const auto& u : units_of(c, series.quantity)) {
      if (u.suffix == suffix) label = u.label;
      if (u.to_si == 1.0) si_label = u.label;
    }
    Conversion& conversion = conversions[fmt::format("{} converted to {}", label, si_label)];
    conversion.factor = factor[c];
    conversion.columns += (conversion.columns.empty() ? "" : ", ") + names[c];
  }
  for (const auto& [what, conversion] : conversions) {
    add_imu_warning(report, fmt::format("{}: column(s) {} in {} (x {})", file, conversion.columns,
                                        what, conversion.factor));
  }

  ImuSourceInfo info;
  info.columns = names;
  info.nominal_dt_line = header.nominal_dt_line;
  ImuValidator validator(series, options, report, info);

  // Room for the samples, from the mean line length of the first megabyte.
  {
    if (options.samples_to_file) series.samples.spill_to_file();
    const std::size_t probe = std::min<std::size_t>(static_cast<std::size_t>(end - p), 1u << 20);
    const auto lines = static_cast<std::size_t>(std::count(p, p + probe, '\n')) + 1;
    const double per_line = static_cast<double>(probe) / static_cast<double>(lines);
    series.samples.reserve(
        static_cast<std::size_t>(static_cast<double>(end - p) / per_line * 1.05) + 16);
    advise_huge_pages(series.samples.data(), series.samples.capacity() * sizeof(ImuSample));
  }

  // Data lines: fields are parsed straight from the mapped text.
  std::size_t data_line = series.first_data_line;
  std::array<double, kColumns> v{};
  while (p < end) {
    const char* q = p;
    for (std::size_t c = 0; c < kColumns; ++c) {
      while (q < end && (*q == ' ' || *q == '\t')) ++q;
      if (q < end && *q == '+') ++q;
      const auto [ptr, ec] = std::from_chars(q, end, v[c]);
      if (ec != std::errc()) fail_data_line(file, data_line, names, p, q, end, c);
      q = ptr;
      while (q < end && (*q == ' ' || *q == '\t')) ++q;
      if (c + 1 < kColumns) {
        if (q < end && *q == ',') {
          ++q;
        } else {
          fail_data_line(file, data_line, names, p, q, end, c);
        }
      }
    }
    if (q < end && *q == '\r') ++q;
    if (q < end) {
      if (*q != '\n') fail_data_line(file, data_line, names, p, q, end, kColumns - 1);
      ++q;
    }
    series.samples.push_back(ImuSample{
        v[0] * factor[0], Eigen::Vector3d(v[1] * factor[1], v[2] * factor[2], v[3] * factor[3]),
        Eigen::Vector3d(v[4] * factor[4], v[5] * factor[5], v[6] * factor[6])});
    p = q;
    ++data_line;
    // Validate what was just parsed while it is in cache.
    if ((series.samples.size() & (kValidationBatch - 1)) == 0) {
      validator.check_up_to(series.samples.size());
    }
    // Blank lines are allowed only at the very end of the file.
    if (p < end && (*p == '\n' || *p == '\r') &&
        std::string_view(p, end - p).find_first_not_of(" \t\r\n") == std::string_view::npos) {
      break;
    }
  }

  validator.finish();
  return series;
}

std::string format_imu_csv(const ImuSeries& series) {
  std::string out;
  format_csv(series, out, [](std::string&) {});
  return out;
}

void write_imu_csv(const fs::path& path, const ImuSeries& series, Overwrite overwrite) {
  AtomicFile file(path, overwrite);
  std::string buffer;
  constexpr std::size_t kChunk = 1u << 20;
  buffer.reserve(kChunk + 4096);
  format_csv(series, buffer, [&](std::string& out) {
    if (out.size() < kChunk) return;
    file.stream().write(out.data(), static_cast<std::streamsize>(out.size()));
    out.clear();
  });
  file.stream().write(buffer.data(), static_cast<std::streamsize>(buffer.size()));
  file.commit();
}

}  // namespace imscal::ims
