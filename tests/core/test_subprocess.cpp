// core::run_subprocess: exit codes, merged output handed over line by line, the time limit
// (a sleeping child is killed, the call returns soon after the limit), a missing program.
#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <vector>

#include "core/subprocess.hpp"

namespace {

TEST(Subprocess, ExitCodeAndLines) {
  std::vector<std::string> lines;
  imscal::SubprocessOptions options;
  options.on_line = [&](std::string_view line) { lines.emplace_back(line); };
  const auto r =
      imscal::run_subprocess({"sh", "-c", "echo one; echo two >&2; printf three; exit 3"}, options);
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_FALSE(r.timed_out);
  EXPECT_EQ(lines, (std::vector<std::string>{"one", "two", "three"}));
  EXPECT_EQ(r.output, "one\ntwo\nthree");
}

TEST(Subprocess, TimeLimitKillsTheChild) {
  imscal::SubprocessOptions options;
  options.timeout_s = 0.3;
  const auto t0 = std::chrono::steady_clock::now();
  const auto r = imscal::run_subprocess({"sleep", "20"}, options);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_TRUE(r.timed_out);
  EXPECT_EQ(r.exit_code, 128 + 9);  // SIGKILL
  // Returns soon after the limit: 0.3 s plus process start and kill (generous for sanitizers).
  EXPECT_LT(seconds, 5.0);
  EXPECT_GE(seconds, 0.29);
}

TEST(Subprocess, MissingProgram) {
  const auto r = imscal::run_subprocess({"imscal-no-such-program-xyz"});
  EXPECT_EQ(r.exit_code, 127);
  EXPECT_NE(r.output.find("cannot run 'imscal-no-such-program-xyz'"), std::string::npos);
}

}  // namespace
