#include "core/progress.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>

namespace imscal {

Progress::Progress() : terminal_(::isatty(STDERR_FILENO) == 1) {}

Progress::~Progress() {
  finish();
}

void Progress::finish() {
  if (stage_.empty()) return;
  const double seconds = std::chrono::duration<double>(Clock::now() - stage_begin_).count();
  if (terminal_) std::fputs("\r\033[K", stderr);
  spdlog::info("{}: done in {:.1f} s", stage_, seconds);
  stage_.clear();
}

void Progress::update(const std::string& stage, double fraction) {
  const Clock::time_point now = Clock::now();
  if (stage != stage_) {
    finish();
    stage_ = stage;
    stage_begin_ = now;
    last_draw_ = {};
  }
  if (!terminal_ || now - last_draw_ < std::chrono::milliseconds(100)) return;
  last_draw_ = now;
  fraction = std::clamp(fraction, 0.0, 1.0);
  const double elapsed = std::chrono::duration<double>(now - stage_begin_).count();
  std::string left = "";
  if (fraction > 0.02 && elapsed > 1.0) {
    left = fmt::format("  {:.0f} s left", elapsed * (1.0 - fraction) / fraction);
  }
  std::fputs(fmt::format("\r\033[K{}  {:3.0f}%{}", stage_, 100.0 * fraction, left).c_str(), stderr);
  std::fflush(stderr);
}

}  // namespace imscal
