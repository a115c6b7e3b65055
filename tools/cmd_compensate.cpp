// `imscal compensate`: the precontrol (eval/compensation_session.hpp) run offline on a robot log:
// for every controller cycle of robot.csv the offsets Δq̂ it would hand to the controller, with its
// state, and the supervisor's events. The same calls a controller integrator makes online.
#include <spdlog/spdlog.h>

#include <filesystem>
#include <memory>

#include "core/atomic_file.hpp"
#include "core/input_error.hpp"
#include "core/output_folder.hpp"
#include "eval/compensation_session.hpp"
#include "tools/command_registry.hpp"
#include "tools/model_torque_option.hpp"

namespace {

struct CompensateArgs {
  imscal::eval::CompensationSessionOptions session;
  std::string out;
  imscal::tools::ModelTorqueOption model_torque;  // for tables with the model-torque input
  bool force = false;
};

void run(const CompensateArgs& args) {
  if (!args.force && std::filesystem::exists(args.out)) {
    throw imscal::InputError(args.out, 0, "", "output exists; use --force to overwrite it");
  }
  imscal::eval::CompensationSessionOptions options = args.session;
  options.robot = args.model_torque.robot;
  options.model_torque = [&args](const std::string& robot, const std::string& data_file,
                                 const std::string& needed_by_file,
                                 const std::string& needed_by_field) {
    return args.model_torque.source(robot, data_file, needed_by_file, needed_by_field);
  };
  const imscal::eval::CompensationRunSummary run = imscal::eval::compensate_robot_log(options);
  // A missing folder of --out is created, as every command creates its output folder.
  const std::filesystem::path folder = std::filesystem::path(args.out).parent_path();
  if (!folder.empty()) imscal::create_output_folder(folder);
  imscal::write_file_atomically(
      args.out, run.offsets_csv,
      args.force ? imscal::Overwrite::kAllow : imscal::Overwrite::kRefuse);
  spdlog::info("compensate: {} cycles, {} active, {} events; wrote {}", run.cycles,
               run.active_cycles, run.events, args.out);
}

imscal::tools::CommandRegistration registration{
    "compensate", "Run the precontrol on a robot log: the offsets per cycle with their state",
    [](CLI::App& sub) {
      auto args = std::make_shared<CompensateArgs>();
      sub.add_option("--table", args->session.table, "parameters.json (imscal identify)")
          ->required();
      sub.add_option("--robot-log", args->session.robot_log, "robot.csv (desired joints, payload)")
          ->required();
      args->model_torque.add_to(sub);
      sub.add_option("--out", args->out, "offsets.csv")->required();
      sub.add_option("--offset-tolerance-rad", args->session.offset_tolerance_rad,
                     "supervisor tolerance on |offset| per joint [rad] (default 0.005)");
      sub.add_flag("--force", args->force, "Overwrite an existing output");
      sub.callback([args] { run(*args); });
    }};
}  // namespace
