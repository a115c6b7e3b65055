#pragma once
// The imscal binary as the CLI tests run it (IMSCAL_BINARY, set by tests/CMakeLists.txt), and how
// often a piece occurs in the text it wrote.
#include <sys/wait.h>

#include <cstddef>
#include <cstdlib>
#include <filesystem>
#include <string>

namespace imscal::test_support {

// Runs `imscal ARGUMENTS`, stdout and stderr to `log`; returns the exit code (-1: killed).
inline int run_imscal(const std::string& arguments, const std::filesystem::path& log) {
  const std::string command =
      std::string(IMSCAL_BINARY) + " " + arguments + " > '" + log.string() + "' 2>&1";
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// Occurrences of `what` in `text` (overlapping ones counted).
inline std::size_t count_of(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

}  // namespace imscal::test_support
