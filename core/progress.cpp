#include "core/progress.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>

namespace imscal {

Progress::Progress(Stages stages) : terminal_(::isatty(STDERR_FILENO) == 1), stages_(stages) {}

Progress::~Progress() {
  finish();
}

void Progress::clear_line_locked() {
  if (terminal_ && line_drawn_) std::fputs("\r\033[K", stderr);
  line_drawn_ = false;
  last_draw_ = {};
}

std::vector<std::string> Progress::end_locked(const std::function<bool(const Running&)>& ends) {
  std::vector<std::string> lines;
  const Clock::time_point now = Clock::now();
  for (const Running& r : running_)
    if (ends(r))
      lines.push_back(fmt::format("{}: done in {:.1f} s", r.stage,
                                  std::chrono::duration<double>(now - r.begin).count()));
  if (lines.empty()) return lines;
  running_.erase(std::remove_if(running_.begin(), running_.end(), ends), running_.end());
  clear_line_locked();
  return lines;
}

void Progress::finish(const std::string& stage) {
  std::vector<std::string> lines;
  {
    const std::lock_guard lock(mutex_);
    lines = end_locked([&](const Running& r) { return r.stage == stage; });
  }
  for (const std::string& line : lines) spdlog::info("{}", line);
}

void Progress::finish() {
  std::vector<std::string> lines;
  {
    const std::lock_guard lock(mutex_);
    lines = end_locked([](const Running&) { return true; });
  }
  for (const std::string& line : lines) spdlog::info("{}", line);
}

void Progress::above_line(const std::function<void()>& write) {
  const std::lock_guard lock(mutex_);
  clear_line_locked();
  write();
}

void Progress::draw_locked(Clock::time_point now) {
  std::string line = "\r\033[K";
  for (const Running& r : running_) {
    if (&r != &running_.front()) line += "  ·  ";
    line += fmt::format("{}  {:3.0f}%", r.stage, 100.0 * r.fraction);
    const double elapsed = std::chrono::duration<double>(now - r.begin).count();
    if (r.fraction > 0.02 && elapsed > 1.0)
      line += fmt::format("  {:.0f} s left", elapsed * (1.0 - r.fraction) / r.fraction);
  }
  std::fputs(line.c_str(), stderr);
  std::fflush(stderr);
  line_drawn_ = true;
  last_draw_ = now;
}

void Progress::update(const std::string& stage, double fraction) {
  if (stages_ == Stages::kOneAtATime) {
    bool another = false;
    {
      const std::lock_guard lock(mutex_);
      for (const Running& r : running_) another |= r.stage != stage;
    }
    if (another) finish();  // logs its "done in" line before the new stage draws
  }
  const Clock::time_point now = Clock::now();
  const std::lock_guard lock(mutex_);
  auto found = std::find_if(running_.begin(), running_.end(),
                            [&](const Running& r) { return r.stage == stage; });
  if (found == running_.end()) {
    running_.push_back({stage, now, 0.0});
    found = std::prev(running_.end());
  }
  found->fraction = std::clamp(fraction, 0.0, 1.0);
  if (terminal_ && now - last_draw_ >= std::chrono::milliseconds(100)) draw_locked(now);
}

}  // namespace imscal
