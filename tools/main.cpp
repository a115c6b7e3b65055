// imscal: dynamic calibration of industrial robots with an inertial measurement system.
// Exit codes: 0 success, 1 a check on the data failed, 2 bad input or config, 3 other failure.
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <iostream>

#include "core/input_error.hpp"
#include "core/version.hpp"
#include "tools/command_registry.hpp"

namespace imscal::tools {
std::vector<CommandSpec>& command_registry() {
  static std::vector<CommandSpec> registry;
  return registry;
}
}  // namespace imscal::tools

int main(int argc, char** argv) {
  using namespace imscal;
  CLI::App app{
      "imscal: dynamic calibration of industrial robots with an inertial measurement "
      "system (IMS)"};
  app.set_version_flag("--version", std::string("imscal ") + kVersion);
  app.require_subcommand(1);
  app.add_flag_callback(
      "-v,--verbose", [] { spdlog::set_level(spdlog::level::debug); }, "Print debug messages");

  auto& registry = tools::command_registry();
  std::sort(registry.begin(), registry.end(),
            [](const auto& a, const auto& b) { return a.name < b.name; });
  for (auto& spec : registry) {
    CLI::App* sub = app.add_subcommand(spec.name, spec.description);
    spec.setup(*sub);
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  } catch (const InputError& e) {
    spdlog::error("{}", e.what());
    return 2;
  } catch (const tools::CheckFailed& e) {
    spdlog::error("check failed: {}", e.what());
    return 1;
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 3;
  }
  return 0;
}
