#include "ims/psins_reader.hpp"

#include <fmt/format.h>
#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "core/input_error.hpp"
#include "core/input_file.hpp"
#include "core/units.hpp"

namespace imscal::ims {
namespace {

const char* const kHeaderFields[3][6] = {
    {"pitch0_deg", "roll0_deg", "yaw0_deg", "ve0_m_s", "vn0_m_s", "vu0_m_s"},
    {"latitude0_deg", "longitude0_deg", "height0_m", "t0_s", "interval_ms", "g_m_s2"},
    {"gyro_scale_x_arcsec_per_count", "gyro_scale_y_arcsec_per_count",
     "gyro_scale_z_arcsec_per_count", "acc_scale_x_ug_s_per_count", "acc_scale_y_ug_s_per_count",
     "acc_scale_z_ug_s_per_count"}};
const char* const kDataFields[6] = {"gyro_x_count", "gyro_y_count", "gyro_z_count",
                                    "acc_x_count",  "acc_y_count",  "acc_z_count"};

bool is_space(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

// Splits a line at white space into at most `capacity` tokens; returns the total token count
// (which may exceed capacity, so that a wrong column count is reported exactly).
int split(std::string_view line, std::string_view* tokens, int capacity) {
  int count = 0;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && is_space(line[i])) ++i;
    if (i >= line.size()) break;
    const std::size_t begin = i;
    while (i < line.size() && !is_space(line[i])) ++i;
    if (count < capacity) tokens[count] = line.substr(begin, i - begin);
    ++count;
  }
  return count;
}

class LineError {
 public:
  LineError(const std::string& file, std::size_t line) : file_(file), line_(line) {}
  [[noreturn]] void raise(const std::string& field, const std::string& problem) const {
    throw InputError(file_, line_, field, problem);
  }

 private:
  const std::string& file_;
  std::size_t line_;
};

double parse_real(std::string_view token, const LineError& error, const char* field) {
  double value = 0.0;
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  if (ec != std::errc() || end != token.data() + token.size()) {
    error.raise(field, fmt::format("'{}' is not a number", token));
  }
  if (!std::isfinite(value)) error.raise(field, fmt::format("'{}' is not a finite number", token));
  return value;
}

long long parse_count(std::string_view token, const LineError& error, const char* field) {
  long long value = 0;
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  if (ec == std::errc() && end == token.data() + token.size()) return value;
  double real = 0.0;
  const auto [real_end, real_ec] = std::from_chars(token.data(), token.data() + token.size(), real);
  if (real_ec == std::errc() && real_end == token.data() + token.size()) {
    error.raise(field,
                fmt::format("'{}' is not an integer count (counts are whole numbers)", token));
  }
  error.raise(field, fmt::format("'{}' is not an integer count", token));
}

void require_range(double value, double low, double high, const LineError& error, const char* field,
                   const char* what) {
  if (!(value >= low && value <= high)) {
    error.raise(field, fmt::format("{} is not {} (expected {} .. {})", value, what, low, high));
  }
}

std::string read_all(const std::filesystem::path& path) {
  return read_input_file(path);
}

}  // namespace

ImuSeries read_psins(const std::filesystem::path& path, PsinsHeader* header_out) {
  const std::string file = path.string();
  const std::string content = read_all(path);

  PsinsHeader header;
  double header_values[3][6] = {};
  int headers_read = 0;
  ImuSeries series;
  series.quantity = ImuQuantity::kIncrements;
  series.source = file;
  Eigen::Vector3d gyro_rad_per_count, acc_m_s_per_count;

  std::size_t line_number = 0;
  std::size_t position = 0;
  std::string_view tokens[6];
  while (position < content.size()) {
    std::size_t end = content.find('\n', position);
    if (end == std::string::npos) end = content.size();
    const std::string_view line(content.data() + position, end - position);
    position = end + 1;
    ++line_number;
    const LineError error(file, line_number);

    std::size_t first = 0;
    while (first < line.size() && is_space(line[first])) ++first;
    if (first == line.size() || line[first] == '%') continue;  // blank or comment

    const int count = split(line, tokens, 6);
    if (headers_read < 3) {
      if (count != 6) {
        error.raise(count < 6 ? kHeaderFields[headers_read][count] : "",
                    fmt::format("PSINS header line {} has {} values, expected 6 ({} .. {})",
                                headers_read + 1, count, kHeaderFields[headers_read][0],
                                kHeaderFields[headers_read][5]));
      }
      for (int c = 0; c < 6; ++c) {
        header_values[headers_read][c] =
            parse_real(tokens[c], error, kHeaderFields[headers_read][c]);
      }
      header.header_lines[headers_read] = line_number;
      const double* v = header_values[headers_read];
      const auto& f = kHeaderFields[headers_read];
      if (headers_read == 0) {
        require_range(v[0], -90.0, 90.0, error, f[0], "a pitch angle");
        require_range(v[1], -180.0, 180.0, error, f[1], "a roll angle");
        require_range(v[2], -360.0, 360.0, error, f[2], "a yaw angle");
        header.initial_pitch_deg = v[0];
        header.initial_roll_deg = v[1];
        header.initial_yaw_deg = v[2];
        header.initial_velocity_enu_m_s = Eigen::Vector3d(v[3], v[4], v[5]);
      } else if (headers_read == 1) {
        require_range(v[0], -90.0, 90.0, error, f[0], "a latitude");
        require_range(v[1], -360.0, 360.0, error, f[1], "a longitude");
        require_range(v[2], -1e4, 1e5, error, f[2], "a plausible height");
        // A sampling interval from 1 us to 10 s covers every IMU rate in use.
        require_range(v[4], 1e-3, 1e4, error, f[4], "a plausible sampling interval");
        // Local g on Earth lies within 9.76 .. 9.84 m/s^2; the wider range only catches a g in
        // other units (e.g. 1 for "g" or 980 for cm/s^2).
        require_range(v[5], 9.0, 10.5, error, f[5], "a plausible gravity in m/s^2");
        header.site = Site{v[0], v[1], v[2]};
        header.t0_s = v[3];
        header.interval_s = v[4] * 1e-3;
        header.gravity_m_s2 = v[5];
      } else {
        for (int c = 0; c < 6; ++c) {
          if (!(v[c] > 0.0)) error.raise(f[c], fmt::format("scale factor {} must be > 0", v[c]));
        }
        header.gyro_scale_arcsec_per_count = Eigen::Vector3d(v[0], v[1], v[2]);
        header.acc_scale_ug_s_per_count = Eigen::Vector3d(v[3], v[4], v[5]);
        gyro_rad_per_count = header.gyro_scale_arcsec_per_count * kRadPerArcsec;
        acc_m_s_per_count = header.acc_scale_ug_s_per_count * 1e-6 * header.gravity_m_s2;
      }
      ++headers_read;
      continue;
    }

    if (count != 6) {
      error.raise(count < 6 ? kDataFields[count] : "",
                  fmt::format("sample line has {} values, expected 6 integer counts (gyro x y z, "
                              "acc x y z)",
                              count));
    }
    if (series.samples.empty()) series.first_data_line = line_number;
    ImuSample sample;
    for (int c = 0; c < 3; ++c) {
      sample.gyro[c] = static_cast<double>(parse_count(tokens[c], error, kDataFields[c])) *
                       gyro_rad_per_count[c];
      sample.acc[c] = static_cast<double>(parse_count(tokens[c + 3], error, kDataFields[c + 3])) *
                      acc_m_s_per_count[c];
    }
    sample.t_s = header.t0_s + static_cast<double>(series.samples.size() + 1) * header.interval_s;
    series.samples.push_back(sample);
  }

  if (content.empty()) throw InputError(file, 0, "", "empty file: expected a PSINS-format log");
  if (headers_read < 3) {
    throw InputError(file, line_number, kHeaderFields[headers_read][0],
                     fmt::format("file ends after {} of the 3 PSINS header lines", headers_read));
  }
  if (series.samples.empty()) {
    throw InputError(file, line_number, "", "no sample lines after the 3 PSINS header lines");
  }

  series.nominal_dt_s = header.interval_s;
  series.site = header.site;
  for (int h = 0; h < 3; ++h) {
    for (int c = 0; c < 6; ++c) {
      series.metadata.emplace_back(kHeaderFields[h][c], fmt::format("{}", header_values[h][c]));
    }
  }
  series.metadata.emplace_back("format", "PSINS increment counts");
  series.metadata.emplace_back("sensor_axes", "X right, Y forward, Z up");
  if (header_out) *header_out = header;
  return series;
}

}  // namespace imscal::ims
