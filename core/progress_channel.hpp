#pragma once
// Progress of a command for the process that runs it as a child (`imscal run`'s stages,
// tools/stage_subcommand.hpp): the library calls of a session report (stage, fraction) through a
// callback; when the parent asked for it (environment variable IMSCAL_PROGRESS_CHANNEL=1, set by
// the parent before it starts the child) the callback writes one line per report to stderr,
//   imscal-progress <fraction in [0, 1]> <stage>
// which the parent reads from the child's output by parse_progress_line. Without the variable
// the callback does nothing: a command run by hand logs as it always did.
#include <functional>
#include <optional>
#include <string>
#include <string_view>

namespace imscal {

inline constexpr const char* kProgressChannelVariable = "IMSCAL_PROGRESS_CHANNEL";

using ProgressCallback = std::function<void(const std::string& stage, double fraction)>;

// The callback a command hands its session: writes progress lines when the parent asked for them.
ProgressCallback progress_channel();

// The line progress_channel writes for (stage, fraction).
std::string progress_line(const std::string& stage, double fraction);

struct ProgressReport {
  std::string stage;
  double fraction = 0.0;  // clamped to [0, 1]
};

// The report of a progress line (as progress_line writes it), or nullopt for any other line.
std::optional<ProgressReport> parse_progress_line(std::string_view line);

// Asks the children this process starts from now on for progress lines (sets the variable).
void request_progress_lines_from_children();

}  // namespace imscal
