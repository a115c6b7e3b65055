// `imscal identify`: the per-joint ARX error models of the paper (equation 2, Table 2) with
// backlash (equation 3), from a joint_errors.csv (eval/identification_session.hpp), written as
// parameters.json (the table the precontrol loads), parameters.csv and
// identification_report.json (chosen orders, criterion curves, validation figures, backlash,
// filled cells with reasons). Progress goes to the parent's channel (core/progress_channel.hpp).
#include <spdlog/spdlog.h>

#include <iostream>
#include <memory>

#include "core/output_folder.hpp"
#include "core/progress_channel.hpp"
#include "eval/identification_session.hpp"
#include "tools/command_registry.hpp"
#include "tools/model_torque_option.hpp"

namespace {
namespace eval = imscal::eval;

struct IdentifyArgs {
  eval::IdentificationSessionOptions session;
  imscal::tools::ModelTorqueOption model_torque;  // for configs with the model-torque input
  std::string out;
  bool force = false;
};

void run(const IdentifyArgs& args) {
  eval::IdentificationSessionOptions options = args.session;
  options.model_torque = [&args](const std::string& robot, const std::string& data_file,
                                 const std::string& needed_by_file,
                                 const std::string& needed_by_field, double data_cycle_s) {
    return args.model_torque.source(robot, data_file, needed_by_file, needed_by_field,
                                    data_cycle_s);
  };
  eval::PreparedIdentification prepared = eval::prepare_identification(options);
  imscal::OutputFolder folder(args.out, eval::identification_output_names(prepared.config),
                              args.force ? imscal::Overwrite::kAllow : imscal::Overwrite::kRefuse);
  const eval::IdentificationResult result =
      eval::identify_session(std::move(prepared), imscal::progress_channel());
  for (std::size_t j = 0; j < result.outcomes.size(); ++j)
    std::cout << eval::joint_summary_text(result.outcomes[j], result.joint_names[j]);
  if (!result.no_joint_identified.empty())
    throw imscal::tools::CheckFailed(result.no_joint_identified);
  eval::write_identification(folder, result);
  folder.commit();
  spdlog::info("wrote {}, {}, {}", (folder.folder() / "parameters.json").string(),
               (folder.folder() / "parameters.csv").string(),
               (folder.folder() / "identification_report.json").string());
}

imscal::tools::CommandRegistration registration{
    "identify",
    "Identify the per-joint ARX error models (operating-point cells, backlash) from joint errors",
    [](CLI::App& sub) {
      auto args = std::make_shared<IdentifyArgs>();
      sub.add_option("--joint-errors", args->session.joint_errors,
                     "joint_errors.csv (imscal calibrate)")
          ->required();
      sub.add_option("--config", args->session.config,
                     "Identification config (datasets/identification/ident-default.yaml)")
          ->required();
      args->model_torque.add_to(sub);
      sub.add_option("--out", args->out, "Output folder")->required();
      sub.add_flag("--search-transmission-error-order", args->session.search_order,
                   "find each joint's transmission-error harmonic per motor revolution (0.5 .. "
                   "4) from the joint errors' held-out fit; the config's is the prior");
      sub.add_flag("--search-second-transmission-error-order", args->session.search_second_order,
                   "with --search-transmission-error-order: also a second harmonic per joint "
                   "beside the first, kept where it lowers the held-out rows' BIC")
          ->needs("--search-transmission-error-order");
      sub.add_flag("--track-transmission-error-orders", args->session.track_orders,
                   "with --search-transmission-error-order: each joint's orders (up to two) from "
                   "the significant peaks of the joint errors' order spectrum over the motor "
                   "angle, where it has one")
          ->needs("--search-transmission-error-order");
      sub.add_flag("--force", args->force, "Overwrite existing outputs");
      sub.callback([args] { run(*args); });
    }};
}  // namespace
