#pragma once
// Runs another program (gnuplot, or imscal itself for a stage) as a child process with a time
// limit, its stdout and stderr merged and handed over line by line. The child is killed when the
// time limit passes and dies with the parent (PR_SET_PDEATHSIG), so that killing `imscal run`
// never leaves a child writing into a run folder.
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace imscal {

struct SubprocessResult {
  int exit_code = -1;        // the child's exit status; 128 + signal when killed by a signal
  bool timed_out = false;    // killed because the time limit passed
  std::string output;        // stdout and stderr, merged, as the child wrote them
  double cpu_seconds = 0.0;  // the child's CPU time, user plus system (wait4's rusage)
};

struct SubprocessOptions {
  double timeout_s = 60.0;
  std::filesystem::path working_dir;  // empty: the parent's
  // Called with every complete output line (without '\n'), as it arrives.
  std::function<void(std::string_view)> on_line;
};

// argv[0] is looked up in PATH. A program that cannot be started gives exit code 127 and the
// reason in `output`. Throws std::runtime_error only when no child can be created at all.
SubprocessResult run_subprocess(const std::vector<std::string>& argv,
                                const SubprocessOptions& options = {});

// CPU time [s] of every child the calling thread has run through run_subprocess so far (each
// one's threads and its own waited-for children): a stage's CPU time when several stages of one
// process run at once (getrusage's RUSAGE_CHILDREN mixes them).
double children_cpu_seconds_of_this_thread();

}  // namespace imscal
