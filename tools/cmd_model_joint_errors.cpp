// `imscal model-joint-errors --joint-errors FILE (--robot FILE | --scenario NAME|FILE) --out FILE`:
// the model side of a sim-to-real comparison. The nominal robot runs in the plant simulator along
// the measured log's desired path and its joint errors are written on the same samples
// (eval/model_joint_errors.hpp), for `imscal diagnose --sim-joint-errors`. --scenario takes the
// scenario's nominal robot, its effects and its site's gravity; --robot a nominal robot file with
// the simulator's default effects.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <memory>
#include <optional>
#include <string>

#include "core/input_error.hpp"
#include "core/output_folder.hpp"
#include "core/payload_plausibility.hpp"
#include "eval/joint_error_limits.hpp"
#include "eval/model_joint_errors.hpp"
#include "ident/joint_error_io.hpp"
#include "sim/scenario.hpp"
#include "tools/command_registry.hpp"

namespace {
using namespace imscal;

struct ModelJointErrorsArgs {
  std::string joint_errors, robot, scenario, out;
  bool force = false;
};

void run(const ModelJointErrorsArgs& args) {
  const Overwrite overwrite = args.force ? Overwrite::kAllow : Overwrite::kRefuse;
  prepare_output_file(args.out, overwrite);
  const ident::JointErrorLog measured = ident::read_joint_errors_csv(args.joint_errors);
  std::optional<sim::Scenario> scenario;
  if (!args.scenario.empty()) scenario = sim::load_scenario(sim::resolve_scenario(args.scenario));
  const sim::NominalRobot nominal =
      scenario ? sim::load_nominal_robot(*scenario)
               : sim::NominalRobot{calib::load_robot_description(args.robot)};
  imscal::check_payload_series(
      measured.payload_kg, measured.time_s, nominal.description.nominal_payload_kg,
      {args.joint_errors, 0, "payload_kg",
       "robot " + nominal.description.name + " (" + nominal.description.source + ")"});
  eval::check_joint_error_limits(measured, args.joint_errors, nominal.description);
  ident::JointErrorLog model;
  try {
    model = eval::nominal_model_joint_errors(measured, nominal, scenario ? &*scenario : nullptr);
  } catch (const std::invalid_argument& e) {
    throw InputError(args.joint_errors, 0, "robot", e.what());
  }
  ident::write_joint_errors_csv(args.out, model, overwrite);
  spdlog::info("model-joint-errors: {} samples of robot {} ({}), written to {}",
               model.sample_count(), model.robot, model.source, args.out);
}

tools::CommandRegistration registration{
    "model-joint-errors",
    "The nominal model's joint errors on the samples of a measured joint_errors.csv (the sim side "
    "of `imscal diagnose --sim-joint-errors`)",
    [](CLI::App& sub) {
      auto args = std::make_shared<ModelJointErrorsArgs>();
      sub.add_option("--joint-errors", args->joint_errors,
                     "measured joint_errors.csv (imscal calibrate): its desired path and samples")
          ->required();
      auto* robot = sub.add_option("--robot", args->robot,
                                   "nominal robot description (simulator's default effects)");
      auto* scenario = sub.add_option("--scenario", args->scenario,
                                      "scenario name or file: its nominal robot, effects, gravity");
      robot->excludes(scenario);
      scenario->excludes(robot);
      sub.add_option("--out", args->out, "model joint_errors.csv (written atomically)")->required();
      sub.add_flag("--force", args->force, "Replace an existing output");
      sub.callback([args] {
        if (args->robot.empty() && args->scenario.empty())
          throw CLI::RequiredError("--robot or --scenario");
        run(*args);
      });
    }};
}  // namespace
