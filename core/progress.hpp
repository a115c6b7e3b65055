#pragma once
// Progress of long work on the terminal: "plant  45%  12 s left", redrawn in place on stderr at
// most 10 times a second, only when stderr is a terminal (quiet in pipes, logs and CI). Every
// stage's end is also logged (spdlog info) with its duration, terminal or not. Stages that run at
// the same time (kConcurrent) share the one line, "verify  40%  ·  diagnose  12%  20 s left";
// every call is thread-safe.
#include <chrono>
#include <functional>
#include <mutex>
#include <string>
#include <vector>

namespace imscal {

class Progress {
 public:
  enum class Stages { kOneAtATime, kConcurrent };
  // Decides once whether stderr is a terminal.
  explicit Progress(Stages stages = Stages::kOneAtATime);
  // fraction in [0, 1] of `stage`; with kOneAtATime a new stage name ends the previous one.
  void update(const std::string& stage, double fraction);
  void finish(const std::string& stage);  // ends that stage
  void finish();                          // ends every stage
  // Runs `write` (which prints a line on the terminal) with the progress line cleared first, so
  // that log lines never land inside it; the next update draws it again.
  void above_line(const std::function<void()>& write);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

 private:
  using Clock = std::chrono::steady_clock;
  struct Running {
    std::string stage;
    Clock::time_point begin;
    double fraction = 0.0;
  };
  void clear_line_locked();
  void draw_locked(Clock::time_point now);
  // Removes the stages that `ends` selects; returns their "done in" log lines.
  std::vector<std::string> end_locked(const std::function<bool(const Running&)>& ends);

  bool terminal_ = false;
  Stages stages_;
  std::recursive_mutex mutex_;  // recursive: above_line's writer may log through a sink that
                                // calls above_line again
  std::vector<Running> running_;
  bool line_drawn_ = false;
  Clock::time_point last_draw_{};
};

}  // namespace imscal
