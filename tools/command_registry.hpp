#pragma once
// Subcommands register themselves at static-initialisation time, so that adding a subcommand is
// adding one file tools/cmd_NAME.cpp:
//
//   static imscal::tools::CommandRegistration reg{"align", [](CLI::App& sub) { ... }};
//
// The setup function declares options on `sub` and sets sub.callback(...) to the work.
#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <vector>

namespace imscal::tools {

// Raised by a subcommand when a check on the data failed (exit code 1), as opposed to bad
// input (InputError, exit code 2).
struct CheckFailed : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct CommandSpec {
  std::string name;
  std::string description;
  std::function<void(CLI::App&)> setup;
};

std::vector<CommandSpec>& command_registry();

struct CommandRegistration {
  CommandRegistration(std::string name, std::string description,
                      std::function<void(CLI::App&)> setup) {
    command_registry().push_back({std::move(name), std::move(description), std::move(setup)});
  }
};

}  // namespace imscal::tools
