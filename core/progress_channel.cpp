#include "core/progress_channel.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <cstdlib>
#include <mutex>

namespace imscal {

namespace {

constexpr std::string_view kPrefix = "imscal-progress ";

}  // namespace

std::string progress_line(const std::string& stage, double fraction) {
  return fmt::format("{}{:.4f} {}", kPrefix, std::clamp(fraction, 0.0, 1.0), stage);
}

ProgressCallback progress_channel() {
  const char* asked = std::getenv(kProgressChannelVariable);
  if (!asked || std::string_view(asked) != "1") return [](const std::string&, double) {};
  return [](const std::string& stage, double fraction) {
    const std::string line = progress_line(stage, fraction) + "\n";
    std::fwrite(line.data(), 1, line.size(), stderr);
    std::fflush(stderr);
  };
}

std::optional<ProgressReport> parse_progress_line(std::string_view line) {
  if (line.substr(0, kPrefix.size()) != kPrefix) return std::nullopt;
  line.remove_prefix(kPrefix.size());
  const auto space = line.find(' ');
  if (space == std::string_view::npos) return std::nullopt;
  double fraction = 0.0;
  if (std::from_chars(line.data(), line.data() + space, fraction).ec != std::errc())
    return std::nullopt;
  return ProgressReport{std::string(line.substr(space + 1)), std::clamp(fraction, 0.0, 1.0)};
}

void request_progress_lines_from_children() {
  // Once per process: stages on several threads call this before they fork, and setenv must not
  // run while another thread forks (the child would copy a half-changed environment).
  static std::once_flag requested;
  std::call_once(requested, [] { ::setenv(kProgressChannelVariable, "1", 1); });
}

}  // namespace imscal
