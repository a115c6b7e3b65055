#include "ims/nav_trajectory_io.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <array>
#include <charconv>
#include <cmath>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <string_view>

#include "core/csv_text.hpp"
#include "core/input_error.hpp"
#include "core/input_file.hpp"

namespace imscal::ims {
namespace {

constexpr std::array<std::string_view, 11> kStateColumns = {
    "t_s", "x_m", "y_m", "z_m", "qw", "qx", "qy", "qz", "vx_m_s", "vy_m_s", "vz_m_s"};
constexpr std::array<std::string_view, 9> kSigmaColumns = {
    "sigma_att_e_rad", "sigma_att_n_rad", "sigma_att_u_rad", "sigma_vx_m_s", "sigma_vy_m_s",
    "sigma_vz_m_s",    "sigma_x_m",       "sigma_y_m",       "sigma_z_m"};
constexpr double kQuaternionNormTolerance = 1e-6;

std::string header_line(bool with_sigmas) {
  std::string line;
  for (std::string_view c : kStateColumns) {
    if (!line.empty()) line += ',';
    line += c;
  }
  if (with_sigmas) {
    for (std::string_view c : kSigmaColumns) {
      line += ',';
      line += c;
    }
  }
  return line + '\n';
}

// Writes `text` to the stream of `file` in large pieces, then commits.
void flush_chunk(AtomicFile& file, std::string& text) {
  file.stream().write(text.data(), static_cast<std::streamsize>(text.size()));
  text.clear();
}

using csv::split;
using csv::trim;

}  // namespace

void write_trajectory_csv(const std::filesystem::path& file, const std::vector<NavState>& states,
                          const std::vector<NavSigma>* sigmas, Overwrite overwrite) {
  if (sigmas != nullptr && sigmas->size() != states.size()) {
    throw std::invalid_argument(fmt::format("write_trajectory_csv: {} sigmas for {} states",
                                            sigmas->size(), states.size()));
  }
  AtomicFile out(file, overwrite);
  std::string text = header_line(sigmas != nullptr);
  for (std::size_t i = 0; i < states.size(); ++i) {
    const NavState& s = states[i];
    // "{}" is the shortest representation that reads back to the same double.
    fmt::format_to(std::back_inserter(text), "{},{},{},{},{},{},{},{},{},{},{}", s.t_s, s.p_W.x(),
                   s.p_W.y(), s.p_W.z(), s.q_W_S.w(), s.q_W_S.x(), s.q_W_S.y(), s.q_W_S.z(),
                   s.v_W.x(), s.v_W.y(), s.v_W.z());
    if (sigmas != nullptr) {
      for (int k = 0; k < 9; ++k) fmt::format_to(std::back_inserter(text), ",{}", (*sigmas)[i][k]);
    }
    text += '\n';
    if (text.size() > (1u << 20)) flush_chunk(out, text);
  }
  flush_chunk(out, text);
  out.commit();
}

void write_trajectory_tum(const std::filesystem::path& file, const std::vector<NavState>& states,
                          Overwrite overwrite) {
  AtomicFile out(file, overwrite);
  std::string text =
      "# imscal trajectory of the sensor frame S in W (Earth-fixed ENU at the site)\n"
      "# t[s] x[m] y[m] z[m] qx qy qz qw   (q = q_W_S: p_W = q * p_S)\n";
  for (const NavState& s : states) {
    fmt::format_to(std::back_inserter(text), "{} {} {} {} {} {} {} {}\n", s.t_s, s.p_W.x(),
                   s.p_W.y(), s.p_W.z(), s.q_W_S.x(), s.q_W_S.y(), s.q_W_S.z(), s.q_W_S.w());
    if (text.size() > (1u << 20)) flush_chunk(out, text);
  }
  flush_chunk(out, text);
  out.commit();
}

NavTrajectory read_trajectory_csv(const std::filesystem::path& file) {
  const std::string name = file.string();
  std::ifstream in = open_input_stream(file);

  std::string line;
  std::size_t line_number = 0;
  bool have_header = false;
  bool with_sigmas = false;
  std::vector<std::string_view> columns;
  NavTrajectory result;
  std::array<double, 20> values{};

  while (std::getline(in, line)) {
    ++line_number;
    if (line_number == 1 && strip_byte_order_mark(line))
      spdlog::warn("{}: a UTF-8 byte-order mark at the start was skipped", name);
    const std::string_view text = trim(line);
    if (!have_header) {
      if (text.empty() || text.front() == '#') continue;
      const std::vector<std::string_view> names = split(text, ',');
      with_sigmas = names.size() == kStateColumns.size() + kSigmaColumns.size();
      const std::string expected = header_line(with_sigmas);
      if (std::string(text) + '\n' != expected) {
        throw InputError(
            name, line_number, "",
            fmt::format("expected the header '{}' (optionally with the 9 sigma "
                        "columns), found '{}'",
                        header_line(false).substr(0, header_line(false).size() - 1), text));
      }
      for (std::string_view c : kStateColumns) columns.push_back(c);
      if (with_sigmas) {
        for (std::string_view c : kSigmaColumns) columns.push_back(c);
      }
      have_header = true;
      continue;
    }
    if (text.empty()) continue;
    const std::vector<std::string_view> fields = split(text, ',');
    if (fields.size() != columns.size()) {
      throw InputError(name, line_number, "",
                       fmt::format("expected {} fields, found {}", columns.size(), fields.size()));
    }
    for (std::size_t k = 0; k < fields.size(); ++k) {
      const std::string_view field = trim(fields[k]);
      double value = 0.0;
      const auto [end, error] = std::from_chars(field.data(), field.data() + field.size(), value);
      if (error != std::errc() || end != field.data() + field.size() || !std::isfinite(value)) {
        throw InputError(name, line_number, std::string(columns[k]),
                         fmt::format("expected a finite number, found '{}'", field));
      }
      values[k] = value;
    }
    NavState s;
    s.t_s = values[0];
    s.p_W = Eigen::Vector3d(values[1], values[2], values[3]);
    s.q_W_S = Eigen::Quaterniond(values[4], values[5], values[6], values[7]);
    s.v_W = Eigen::Vector3d(values[8], values[9], values[10]);
    if (!result.states.empty() && !(s.t_s > result.states.back().t_s)) {
      throw InputError(name, line_number, "t_s",
                       fmt::format("time {} s does not follow the previous line's {} s", s.t_s,
                                   result.states.back().t_s));
    }
    const double norm = s.q_W_S.norm();
    if (std::abs(norm - 1.0) > kQuaternionNormTolerance) {
      throw InputError(name, line_number, "qw",
                       fmt::format("the quaternion (qw, qx, qy, qz) has norm {}, expected 1 "
                                   "(within {})",
                                   norm, kQuaternionNormTolerance));
    }
    s.q_W_S.normalize();
    result.states.push_back(s);
    if (with_sigmas) {
      NavSigma sigma;
      for (int k = 0; k < 9; ++k) {
        sigma[k] = values[11 + k];
        if (sigma[k] < 0.0) {
          throw InputError(name, line_number, std::string(kSigmaColumns[k]),
                           fmt::format("a 1-sigma cannot be negative, found {}", sigma[k]));
        }
      }
      result.sigmas.push_back(sigma);
    }
  }
  if (!have_header) throw InputError(name, 0, "", "no header line: the file is empty");
  return result;
}

}  // namespace imscal::ims
