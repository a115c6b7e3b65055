#pragma once
// Progress of long work on the terminal: "plant  45%  12 s left", redrawn in place on stderr at
// most 10 times a second, only when stderr is a terminal (quiet in pipes, logs and CI). Every
// stage's end is also logged (spdlog info) with its duration, terminal or not.
#include <chrono>
#include <string>

namespace imscal {

class Progress {
 public:
  Progress();  // decides once whether stderr is a terminal
  // fraction in [0, 1] of `stage`; a new stage name ends the previous one.
  void update(const std::string& stage, double fraction);
  void finish();  // ends the current stage
  ~Progress();

 private:
  using Clock = std::chrono::steady_clock;
  bool terminal_ = false;
  std::string stage_;
  Clock::time_point stage_begin_{};
  Clock::time_point last_draw_{};
};

}  // namespace imscal
