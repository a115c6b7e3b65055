// A command run as a child process with its cost: wall time (steady clock), CPU time (user +
// system of the child and the subprocesses it waited for) and peak resident memory, from wait4's
// rusage (getrusage(2): ru_maxrss in KiB on Linux). For the benchmarks that time whole commands.
#pragma once

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace imscal::bench {

struct ChildRun {
  double wall_s = 0.0;
  double cpu_s = 0.0;  // user + system time of the child and its stages
  double peak_rss_mb = 0.0;
};

// Runs `words` (program path first), its stdout and stderr into `log`; throws naming `log` when
// it cannot start or exits other than 0.
inline ChildRun run_child(std::vector<std::string> words, const std::filesystem::path& log) {
  std::vector<char*> argv;
  for (auto& w : words) argv.push_back(w.data());
  argv.push_back(nullptr);
  const auto start = std::chrono::steady_clock::now();
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("fork failed");
  if (pid == 0) {
    if (!freopen(log.c_str(), "w", stdout) || !freopen(log.c_str(), "a", stderr)) _exit(126);
    execv(argv[0], argv.data());
    _exit(127);
  }
  int status = 0;
  rusage usage{};
  if (wait4(pid, &status, 0, &usage) != pid) throw std::runtime_error("wait4 failed");
  ChildRun r;
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  r.peak_rss_mb = double(usage.ru_maxrss) / 1024.0;
  r.cpu_s = double(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
            1e-6 * double(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
    throw std::runtime_error(words.front() + " " + (words.size() > 1 ? words[1] : "") +
                             " failed, see " + log.string());
  return r;
}

}  // namespace imscal::bench
