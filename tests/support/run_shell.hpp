#pragma once
// A shell command as the workflow tests run it (snakemake, the Slurm daemons): its output to a log
// file, its exit code back.
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <string>

namespace imscal::test_support {

// Runs `command` with /bin/sh, stdout and stderr to `log`; returns the exit code (-1: killed).
inline int run_shell(const std::string& command, const std::filesystem::path& log) {
  const std::string line = "(" + command + ") > '" + log.string() + "' 2>&1";
  const int status = std::system(line.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// True when `program` is found on PATH.
inline bool on_path(const std::string& program) {
  return std::system(("command -v " + program + " > /dev/null 2>&1").c_str()) == 0;
}

}  // namespace imscal::test_support
