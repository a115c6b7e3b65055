#include "ident/joint_error_io.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <map>
#include <stdexcept>
#include <string_view>

#include "core/csv_text.hpp"
#include "core/input_error.hpp"
#include "core/input_file.hpp"
#include "core/sha256.hpp"

namespace imscal::ident {
namespace {

constexpr int kFormatVersion = 1;
// A step longer than this many cycles is a gap between two runs (a dropped sample or a pause in
// the recording): no regressor may reach across it.
constexpr double kGapCycles = 1.5;

using csv::parse_number;
using csv::trim;

// A joint error (q_desired - q_measured) beyond this is no calibration residual but a corrupted
// sample (controller logs hold such words): the simulated KR 16 at full speed lags by at most
// 0.031 rad, and one corrupted sample would become the table's offset envelope, the
// supervisor's tolerance.
constexpr double kMaxJointError_rad = 0.5;

// Row layout: t_s, payload_kg, q_desired per joint, q_measured per joint[, q_internal per joint].
void check_joint_errors_plausible(const std::vector<double>& row,
                                  const std::vector<std::string>& joint_names,
                                  const std::string& file, std::size_t line) {
  const std::size_t joints = joint_names.size();
  for (std::size_t j = 0; j < joints; ++j) {
    const double error = row[2 + j] - row[2 + joints + j];
    if (std::abs(error) > kMaxJointError_rad)
      throw InputError(
          file, line, "q_measured_" + joint_names[j] + "_rad",
          fmt::format("joint error q_desired - q_measured = {:.6g} rad exceeds {} rad: "
                      "a corrupted sample (remove it, or split the log there)",
                      error, kMaxJointError_rad));
  }
}

std::vector<std::string> expected_columns(const std::vector<std::string>& joints,
                                          bool with_internal) {
  std::vector<std::string> names{"t_s", "payload_kg"};
  for (const char* family : {"q_desired", "q_measured", "q_internal"}) {
    if (std::string_view(family) == "q_internal" && !with_internal) break;
    for (const auto& j : joints) names.push_back(fmt::format("{}_{}_rad", family, j));
  }
  return names;
}

// Joint names from the q_desired_<J>_rad columns of the header.
std::vector<std::string> joints_from_header(const std::string& file, std::size_t line,
                                            const std::vector<std::string>& columns) {
  std::vector<std::string> joints;
  for (std::size_t c = 2; c < columns.size(); ++c) {
    const std::string& name = columns[c];
    if (!name.starts_with("q_desired_")) break;
    if (!name.ends_with("_rad") || name.size() <= 14)
      throw InputError(file, line, name,
                       "desired joint angles must be named q_desired_<joint>_rad (radians)");
    joints.push_back(name.substr(10, name.size() - 14));
  }
  if (joints.empty())
    throw InputError(file, line, columns.size() > 2 ? columns[2] : "",
                     "expected the columns t_s,payload_kg,q_desired_<joint>_rad...");
  return joints;
}

// Reserves the columns for the lines left in `in` (counted, then `in` put back): each column
// then takes what it holds, not up to twice as its vector grows.
void reserve_rows(std::istream& in, JointErrorLog& log, bool with_internal) {
  const std::size_t lines = csv::lines_left(in);
  if (lines == 0) return;
  log.time_s.reserve(lines);
  log.payload_kg.reserve(lines);
  log.sample_lines.reserve(lines);
  for (std::size_t j = 0; j < log.joint_count(); ++j) {
    log.q_desired_rad[j].reserve(lines);
    log.q_measured_rad[j].reserve(lines);
    if (with_internal) log.q_internal_rad[j].reserve(lines);
  }
}

}  // namespace

std::vector<std::pair<std::size_t, std::size_t>> JointErrorLog::segments() const {
  std::vector<std::pair<std::size_t, std::size_t>> out;
  for (std::size_t s = 0; s < segment_starts.size(); ++s) {
    const std::size_t end = s + 1 < segment_starts.size() ? segment_starts[s + 1] : sample_count();
    if (end > segment_starts[s]) out.emplace_back(segment_starts[s], end);
  }
  return out;
}

void split_at_gaps(JointErrorLog& log) {
  log.segment_starts = {0};
  for (std::size_t k = 1; k < log.time_s.size(); ++k)
    if (log.time_s[k] - log.time_s[k - 1] > kGapCycles * log.cycle_s)
      log.segment_starts.push_back(k);
}

JointErrorLog read_joint_errors_csv(const std::filesystem::path& path) {
  const std::string file = path.string();
  std::ifstream in = open_input_stream(path);
  JointErrorLog log;
  std::map<std::string, std::size_t, std::less<>> seen;
  std::string text;
  std::size_t line = 0;
  std::vector<std::string> columns;
  // Header comments, then the column line.
  while (std::getline(in, text)) {
    ++line;
    if (line == 1 && strip_byte_order_mark(text))
      spdlog::warn("{}: a UTF-8 byte-order mark at the start was skipped", file);
    const std::string_view t = trim(text);
    if (t.empty()) continue;
    if (t.front() != '#') {
      std::size_t start = 0;
      const std::string_view all = t;
      while (true) {
        const auto comma = all.find(',', start);
        columns.emplace_back(trim(all.substr(start, comma - start)));
        if (comma == std::string_view::npos) break;
        start = comma + 1;
      }
      break;
    }
    const std::string_view body = trim(t.substr(1));
    const auto colon = body.find(':');
    if (colon == std::string_view::npos) continue;  // a free comment
    const std::string key(trim(body.substr(0, colon)));
    const std::string value(trim(body.substr(colon + 1)));
    if (seen.contains(key))
      throw InputError(file, line, key,
                       fmt::format("header key given twice (first on line {})", seen[key]));
    seen[key] = line;
    if (key == "imscal-joint-errors") {
      if (value != std::to_string(kFormatVersion))
        throw InputError(file, line, key,
                         fmt::format("unknown format version '{}'; this imscal reads version {}",
                                     value, kFormatVersion));
    } else if (key == "robot") {
      log.robot = value;
    } else if (key == "cycle_s") {
      if (!parse_number(value, log.cycle_s) || !std::isfinite(log.cycle_s) || log.cycle_s <= 0.0)
        throw InputError(file, line, key,
                         fmt::format("expected a positive cycle time in seconds, got '{}'", value));
    } else if (key == "source") {
      log.source = value;
    } else {
      log.metadata.emplace_back(key, value);
    }
  }
  if (!seen.contains("imscal-joint-errors"))
    throw InputError(
        file, 1, "imscal-joint-errors",
        "not a joint_errors.csv: the header line '# imscal-joint-errors: 1' is missing");
  if (!seen.contains("robot")) throw InputError(file, 1, "robot", "header '# robot: NAME' missing");
  if (!seen.contains("cycle_s"))
    throw InputError(file, 1, "cycle_s", "header '# cycle_s: SECONDS' missing");
  if (columns.empty()) throw InputError(file, line, "", "no column header line");
  const std::size_t header_line = line;
  log.joint_names = joints_from_header(file, header_line, columns);
  // The q_internal block is there when any column follows q_measured's; then whole.
  const bool with_internal = columns.size() > 2 + 2 * log.joint_names.size();
  const std::vector<std::string> expected = expected_columns(log.joint_names, with_internal);
  for (std::size_t c = 0; c < std::max(expected.size(), columns.size()); ++c) {
    if (c >= columns.size())
      throw InputError(file, header_line, expected[c], "column missing from the header");
    if (c >= expected.size() || columns[c] != expected[c])
      throw InputError(file, header_line, columns[c],
                       fmt::format("unexpected column {} '{}'; expected '{}'", c + 1, columns[c],
                                   c < expected.size() ? expected[c] : "(no further column)"));
  }
  const std::size_t joints = log.joint_names.size();
  log.q_desired_rad.assign(joints, {});
  log.q_measured_rad.assign(joints, {});
  if (with_internal) log.q_internal_rad.assign(joints, {});
  reserve_rows(in, log, with_internal);
  std::vector<double> row(expected.size());
  while (std::getline(in, text)) {
    ++line;
    const std::string_view t = trim(text);
    if (t.empty() || t.front() == '#') continue;
    if (log.first_data_line == 0) log.first_data_line = line;
    std::size_t start = 0, c = 0;
    while (true) {
      const auto comma = t.find(',', start);
      if (c >= row.size())
        throw InputError(file, line, "",
                         fmt::format("more than the {} columns of the header", row.size()));
      const std::string_view cell = t.substr(start, comma - start);
      if (!parse_number(cell, row[c]))
        throw InputError(file, line, expected[c],
                         fmt::format("'{}' is not a number", std::string(trim(cell))));
      if (!std::isfinite(row[c]))
        throw InputError(file, line, expected[c], "value is not finite (NaN or infinite)");
      ++c;
      if (comma == std::string_view::npos) break;
      start = comma + 1;
    }
    if (c != row.size())
      throw InputError(file, line, expected[c],
                       fmt::format("{} columns, the header has {}", c, row.size()));
    if (!log.time_s.empty() && !(row[0] > log.time_s.back()))
      throw InputError(file, line, "t_s",
                       fmt::format("time {} s does not increase (previous sample {} s)", row[0],
                                   log.time_s.back()));
    // The robot log's rule (robot/robot_log.hpp): a step under half a cycle is jitter no
    // real-time controller produces, so `identify` and `compensate` refuse the same logs.
    if (!log.time_s.empty() && row[0] - log.time_s.back() < 0.5 * log.cycle_s)
      throw InputError(file, line, "t_s",
                       fmt::format("step of {:.6g} s is less than half the cycle of {} s "
                                   "(time stamps jitter or the cycle_s header is wrong)",
                                   row[0] - log.time_s.back(), log.cycle_s));
    if (row[1] < 0.0) throw InputError(file, line, "payload_kg", "negative payload");
    check_joint_errors_plausible(row, log.joint_names, file, line);
    log.time_s.push_back(row[0]);
    log.sample_lines.push_back(line);
    log.payload_kg.push_back(row[1]);
    for (std::size_t j = 0; j < joints; ++j) {
      log.q_desired_rad[j].push_back(row[2 + j]);
      log.q_measured_rad[j].push_back(row[2 + joints + j]);
      if (with_internal) log.q_internal_rad[j].push_back(row[2 + 2 * joints + j]);
    }
  }
  if (log.time_s.empty()) throw InputError(file, line, "", "no samples after the header");
  split_at_gaps(log);
  if (log.segment_starts.size() > 1)
    spdlog::warn("{}: {} time gaps longer than {} cycles; the data are used as {} separate runs",
                 file, log.segment_starts.size() - 1, kGapCycles, log.segment_starts.size());
  return log;
}

namespace {

// The header lines of joint_errors.csv up to the column names. Throws std::invalid_argument for
// no joints, a bad joint name or cycle_s <= 0.
void write_joint_errors_header(std::ostream& s, const JointErrorLog& header, bool with_internal) {
  if (header.joint_count() == 0) throw std::invalid_argument("write_joint_errors_csv: no joints");
  if (!(header.cycle_s > 0.0)) throw std::invalid_argument("write_joint_errors_csv: cycle_s <= 0");
  for (const auto& name : header.joint_names)
    if (name.empty() || name.find_first_of(",# \t\n") != std::string::npos)
      throw std::invalid_argument("write_joint_errors_csv: bad joint name '" + name + "'");
  s << fmt::format("# imscal-joint-errors: {}\n# robot: {}\n# cycle_s: {}\n", kFormatVersion,
                   header.robot, header.cycle_s);
  if (!header.source.empty()) s << "# source: " << header.source << '\n';
  for (const auto& [key, value] : header.metadata) s << "# " << key << ": " << value << '\n';
  const auto names = expected_columns(header.joint_names, with_internal);
  for (std::size_t c = 0; c < names.size(); ++c) s << (c ? "," : "") << names[c];
  s << '\n';
}

}  // namespace

JointErrorsCsvWriter::JointErrorsCsvWriter(const std::filesystem::path& file,
                                           const JointErrorLog& header, bool with_internal,
                                           Overwrite overwrite)
    : out_(file, overwrite), joints_(header.joint_count()), with_internal_(with_internal) {
  write_joint_errors_header(out_.stream(), header, with_internal);
}

JointErrorsCsvWriter::JointErrorsCsvWriter(const std::filesystem::path& file, std::size_t joints,
                                           bool with_internal, Overwrite overwrite)
    : out_(file, overwrite),
      joints_(joints),
      with_internal_(with_internal),
      rows_file_(file.string() + ".rows") {
  if (joints_ == 0) throw std::invalid_argument("write_joint_errors_csv: no joints");
  rows_out_.open(rows_file_, std::ios::binary | std::ios::trunc);
  if (!rows_out_) throw std::runtime_error("cannot write " + rows_file_.string());
}

JointErrorsCsvWriter::~JointErrorsCsvWriter() {
  if (rows_file_.empty()) return;
  rows_out_.close();
  std::error_code ignored;
  std::filesystem::remove(rows_file_, ignored);
}

std::ostream& JointErrorsCsvWriter::rows() {
  return rows_file_.empty() ? static_cast<std::ostream&>(out_.stream()) : rows_out_;
}

void JointErrorsCsvWriter::add(double t_s, double payload_kg, std::span<const double> q_desired_rad,
                               std::span<const double> q_measured_rad,
                               std::span<const double> q_internal_rad) {
  if (q_desired_rad.size() != joints_ || q_measured_rad.size() != joints_ ||
      (with_internal_ && q_internal_rad.size() != joints_))
    throw std::invalid_argument("write_joint_errors_csv: inconsistent sizes");
  line_ = fmt::format("{:.17g},{:.17g}", t_s, payload_kg);
  const std::array<std::span<const double>, 3> families{q_desired_rad, q_measured_rad,
                                                        q_internal_rad};
  for (std::size_t f = 0; f < (with_internal_ ? 3U : 2U); ++f) {
    for (const double v : families[f]) {
      if (!std::isfinite(v))
        throw std::invalid_argument(
            fmt::format("write_joint_errors_csv: non-finite value at sample {}", samples_));
      fmt::format_to(std::back_inserter(line_), ",{:.17g}", v);
    }
  }
  line_ += '\n';
  rows() << line_;
  ++samples_;
}

void JointErrorsCsvWriter::commit() {
  if (!rows_file_.empty())
    throw std::logic_error("JointErrorsCsvWriter: the header is given at commit");
  out_.commit();
}

void JointErrorsCsvWriter::commit(const JointErrorLog& header) {
  if (rows_file_.empty()) throw std::logic_error("JointErrorsCsvWriter: the header is written");
  if (header.joint_count() != joints_)
    throw std::invalid_argument("write_joint_errors_csv: inconsistent sizes");
  write_joint_errors_header(out_.stream(), header, with_internal_);
  rows_out_.close();
  if (!rows_out_) throw std::runtime_error("cannot write " + rows_file_.string());
  if (samples_ > 0) {
    std::ifstream in(rows_file_, std::ios::binary);
    out_.stream() << in.rdbuf();
    if (!in || !out_.stream()) throw std::runtime_error("cannot copy " + rows_file_.string());
  }
  out_.commit();
}

void write_joint_errors_csv(const std::filesystem::path& file, const JointErrorLog& log,
                            Overwrite overwrite) {
  const std::size_t n = log.sample_count();
  const std::size_t joints = log.joint_count();
  if (joints == 0) throw std::invalid_argument("write_joint_errors_csv: no joints");
  if (log.payload_kg.size() != n || log.q_desired_rad.size() != joints ||
      log.q_measured_rad.size() != joints ||
      (log.has_q_internal() && log.q_internal_rad.size() != joints))
    throw std::invalid_argument("write_joint_errors_csv: inconsistent sizes");
  for (std::size_t j = 0; j < joints; ++j)
    if (log.q_desired_rad[j].size() != n || log.q_measured_rad[j].size() != n ||
        (log.has_q_internal() && log.q_internal_rad[j].size() != n))
      throw std::invalid_argument("write_joint_errors_csv: inconsistent sizes of joint " +
                                  log.joint_names[j]);
  JointErrorsCsvWriter out(file, log, log.has_q_internal(), overwrite);
  std::vector<double> desired(joints), measured(joints), internal(joints);
  for (std::size_t k = 0; k < n; ++k) {
    for (std::size_t j = 0; j < joints; ++j) {
      desired[j] = log.q_desired_rad[j][k];
      measured[j] = log.q_measured_rad[j][k];
      if (log.has_q_internal()) internal[j] = log.q_internal_rad[j][k];
    }
    out.add(log.time_s[k], log.payload_kg[k], desired, measured, internal);
  }
  out.commit();
}

// The file's checksum is core's SHA-256 (one implementation for the run folders and the tables).
std::string file_sha256_hex(const std::filesystem::path& file) {
  return sha256_hex_of_file(file);
}

}  // namespace imscal::ident
