#include "core/subprocess.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <stdexcept>

namespace imscal {

namespace {
thread_local double children_cpu_s = 0.0;

double cpu_seconds_of(const rusage& usage) {
  double total = 0.0;
  for (const timeval& t : {usage.ru_utime, usage.ru_stime})
    total += double(t.tv_sec) + 1e-6 * double(t.tv_usec);
  return total;
}

void write_all(int fd, std::string_view text) {
  while (!text.empty()) {
    const ssize_t n = ::write(fd, text.data(), text.size());
    if (n <= 0) return;
    text.remove_prefix(static_cast<std::size_t>(n));
  }
}
}  // namespace

double children_cpu_seconds_of_this_thread() {
  return children_cpu_s;
}

SubprocessResult run_subprocess(const std::vector<std::string>& argv,
                                const SubprocessOptions& options) {
  if (argv.empty()) throw std::invalid_argument("run_subprocess: empty argv");
  // Everything the child needs is prepared before fork: between fork and exec only
  // async-signal-safe calls.
  std::vector<char*> child_argv;
  for (const std::string& arg : argv) child_argv.push_back(const_cast<char*>(arg.c_str()));
  child_argv.push_back(nullptr);
  const std::string working_dir = options.working_dir.string();
  const std::string exec_failed = "cannot run '" + argv[0] + "': ";

  int pipe_fds[2];
  if (::pipe2(pipe_fds, O_CLOEXEC) != 0)
    throw std::runtime_error(std::string("run_subprocess: pipe: ") + std::strerror(errno));
  const pid_t parent = ::getpid();
  const pid_t child = ::fork();
  if (child < 0) {
    ::close(pipe_fds[0]);
    ::close(pipe_fds[1]);
    throw std::runtime_error(std::string("run_subprocess: fork: ") + std::strerror(errno));
  }
  if (child == 0) {
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != parent) ::_exit(127);  // the parent died before prctl took effect
    const int null_fd = ::open("/dev/null", O_RDONLY);
    if (null_fd >= 0) ::dup2(null_fd, STDIN_FILENO);
    ::dup2(pipe_fds[1], STDOUT_FILENO);
    ::dup2(pipe_fds[1], STDERR_FILENO);
    if (!working_dir.empty() && ::chdir(working_dir.c_str()) != 0) {
      write_all(STDERR_FILENO, exec_failed);
      write_all(STDERR_FILENO, std::strerror(errno));
      ::_exit(127);
    }
    ::execvp(child_argv[0], child_argv.data());
    write_all(STDERR_FILENO, exec_failed);
    write_all(STDERR_FILENO, std::strerror(errno));
    write_all(STDERR_FILENO, "\n");
    ::_exit(127);
  }
  ::close(pipe_fds[1]);

  SubprocessResult result;
  const auto deadline = std::chrono::steady_clock::now() +
                        std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                            std::chrono::duration<double>(options.timeout_s));
  std::string pending;  // an incomplete last line
  const auto hand_over_lines = [&](bool flush) {
    std::size_t start = 0;
    for (std::size_t newline; (newline = pending.find('\n', start)) != std::string::npos;
         start = newline + 1) {
      if (options.on_line)
        options.on_line(std::string_view(pending).substr(start, newline - start));
    }
    pending.erase(0, start);
    if (flush && !pending.empty()) {
      if (options.on_line) options.on_line(pending);
      pending.clear();
    }
  };
  char buffer[4096];
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) {
      result.timed_out = true;
      ::kill(child, SIGKILL);
      break;
    }
    pollfd poll_fd{pipe_fds[0], POLLIN, 0};
    const int ready =
        ::poll(&poll_fd, 1, static_cast<int>(std::min<long long>(left.count(), 1000)));
    if (ready < 0 && errno == EINTR) continue;
    if (ready <= 0) continue;
    const ssize_t n = ::read(pipe_fds[0], buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;  // end of output: the child (and any grandchild) closed it
    result.output.append(buffer, static_cast<std::size_t>(n));
    pending.append(buffer, static_cast<std::size_t>(n));
    hand_over_lines(false);
  }
  hand_over_lines(true);
  ::close(pipe_fds[0]);
  // The output may close before the child ends: wait for it, still within the time limit.
  int status = 0;
  rusage usage{};  // of the child alone (and its waited-for children), not of a sibling's child
  for (;;) {
    const pid_t done = ::wait4(child, &status, result.timed_out ? 0 : WNOHANG, &usage);
    if (done == child) break;
    if (done < 0 && errno != EINTR) break;
    if (done == 0) {
      if (std::chrono::steady_clock::now() >= deadline) {
        result.timed_out = true;
        ::kill(child, SIGKILL);
      } else {
        ::usleep(2000);
      }
    }
  }
  result.cpu_seconds = cpu_seconds_of(usage);
  children_cpu_s += result.cpu_seconds;
  if (WIFEXITED(status)) {
    result.exit_code = WEXITSTATUS(status);
  } else if (WIFSIGNALED(status)) {
    result.exit_code = 128 + WTERMSIG(status);
  }
  return result;
}

}  // namespace imscal
