// `imscal identify`: the per-joint ARX error models of the paper (equation 2, Table 2) with
// backlash (equation 3), from a joint_errors.csv, written as parameters.json (the table the
// precontrol loads), parameters.csv and identification_report.json (chosen orders, criterion
// curves, validation figures, backlash, filled cells with reasons).
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <filesystem>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <vector>

#include "core/atomic_file.hpp"
#include "core/config_node.hpp"
#include "core/input_error.hpp"
#include "core/json_output.hpp"
#include "core/output_folder.hpp"
#include "core/payload_plausibility.hpp"
#include "core/version.hpp"
#include "eval/model_torque.hpp"
#include "eval/transmission_error_order.hpp"
#include "eval/verification.hpp"
#include "ident/identification_config.hpp"
#include "ident/identification_config_record.hpp"
#include "ident/identification_report.hpp"
#include "ident/identify_joints.hpp"
#include "ident/joint_error_io.hpp"
#include "ident/joint_identification.hpp"
#include "ident/parameter_table_io.hpp"
#include "tools/command_registry.hpp"
#include "tools/model_torque_option.hpp"

namespace {
namespace fs = std::filesystem;
namespace ident = imscal::ident;
using nlohmann::json;

struct IdentifyArgs {
  std::string joint_errors;
  std::string config;
  imscal::tools::ModelTorqueOption model_torque;  // for configs with the model-torque input
  std::string out;
  bool search_order = false;  // the transmission error's order per joint from the data
  bool force = false;
};

// The model torques of the log's path (eval/model_torque.hpp), when the config's models take
// them.
void attach_model_torques(ident::JointErrorLog& log, const ident::IdentificationConfig& config,
                          const IdentifyArgs& args) {
  if (!config.options.model_torque_input) return;
  const imscal::eval::ModelTorqueSource model = args.model_torque.source(
      log.robot, args.joint_errors, args.config, "model.model_torque", log.cycle_s);
  spdlog::info("identify: model torques of {} along the {} path", model.robot.name,
               imscal::eval::torque_along_measured_path(config.options) ? "measured" : "desired");
  imscal::eval::attach_model_torques(log, model, config.options);
}

// `--search-transmission-error-order`: each joint's harmonic found from the data replaces the
// config's (eval/transmission_error_order.hpp); the search for the report.
ident::OrderSearchReport search_orders(const ident::JointErrorLog& log, const IdentifyArgs& args,
                                       ident::IdentificationConfig& config) {
  if (!config.options.transmission_error_input)
    throw imscal::InputError(args.config, 0, "model.transmission_error",
                             "--search-transmission-error-order needs the transmission-error "
                             "inputs (model.transmission_error: true)");
  spdlog::info("identify: searching the transmission error's order per motor revolution");
  const imscal::eval::TransmissionErrorOrderSearch search =
      imscal::eval::search_transmission_error_orders(log, config,
                                                     imscal::eval::default_order_candidates());
  ident::OrderSearchReport report;
  report.candidates_per_motor_rev = search.candidates;
  for (std::size_t j = 0; j < search.chosen_harmonic.size(); ++j) {
    spdlog::info("identify: {}: {}", log.joint_names[j],
                 imscal::eval::describe_order_search(search, j));
    std::vector<double> fits;
    for (const auto& per_candidate : search.fit_percent) fits.push_back(per_candidate[j]);
    report.joints.push_back({log.joint_names[j], search.prior_harmonic[j], search.best_harmonic[j],
                             search.gain_points[j], search.chosen_harmonic[j], fits});
  }
  config = imscal::eval::with_searched_orders(std::move(config), search);
  return report;
}

// The outputs of this config, relative to --out; written all or nothing.
std::vector<fs::path> output_names(const ident::IdentificationConfig& config) {
  std::vector<fs::path> names = {"identification_report.json", "parameters.csv", "parameters.json"};
  if (config.options.form == ident::ArxModelForm::kInverse)
    names.emplace_back("forward_parameters.json");
  return names;
}

// The order sweep's longest model must leave rows to fit it: a segment needs more samples than
// the longest lag plus the coefficients, or every cell fits from no rows and corrects nothing.
void check_orders_fit_record(const ident::JointErrorLog& log,
                             const ident::IdentificationConfig& config,
                             const imscal::ConfigNode& config_node, const std::string& file,
                             const std::string& log_file) {
  const auto& grid = config.options.grid;
  const std::size_t longest_lag =
      std::size_t(std::max(grid.na_max, grid.nb_max + grid.dead_time_max));
  const std::size_t coefficients = std::size_t(grid.na_max + grid.nb_max);
  std::size_t longest_segment = 0;
  for (const auto& [begin, end] : log.segments())
    longest_segment = std::max(longest_segment, end - begin);
  if (longest_segment > longest_lag + coefficients) return;
  const auto order = config_node.optional_child("order");
  throw imscal::InputError(
      file, order ? order->line() : 0, "order",
      fmt::format("the largest model (na {}, nb {}, dead time {}) needs more than {} samples in "
                  "one segment; the longest segment of {} has {}",
                  grid.na_max, grid.nb_max, grid.dead_time_max, longest_lag + coefficients,
                  log_file, longest_segment));
}

// The log's payload against the rating of the config (the payload cells are fractions of it).
void check_payload_plausible(const ident::JointErrorLog& log,
                             const ident::IdentificationConfig& config, const IdentifyArgs& args) {
  imscal::check_payload_series(
      log.payload_kg, log.time_s, config.nominal_payload_kg,
      {args.joint_errors, 0, "payload_kg",
       fmt::format("robot {} ({}: joints.nominal_payload_kg)", log.robot, args.config)});
}

// A table in which no joint was identified corrects nothing: a failed check, not a result.
void check_some_joint_identified(const std::vector<ident::JointOutcome>& outcomes,
                                 const ident::JointErrorLog& log, const std::string& log_file) {
  std::string reasons;
  for (std::size_t j = 0; j < outcomes.size(); ++j) {
    if (outcomes[j].failure.empty()) return;
    reasons += fmt::format("{}joint {}: {}", reasons.empty() ? "" : "; ", log.joint_names[j],
                           outcomes[j].failure);
  }
  throw imscal::tools::CheckFailed(fmt::format(
      "{}: no joint could be identified, the table would correct nothing ({})", log_file, reasons));
}

void print_joint(const ident::JointOutcome& outcome, const std::string& name) {
  const ident::JointIdentification& r = outcome.result;
  if (!outcome.failure.empty()) {
    // No cell of this joint could be identified (e.g. it did not move): the other joints'
    // models are still good, so this joint has the neutral model (zero correction) and the
    // table says why, instead of the whole run failing.
    spdlog::warn("joint {}: not identified, its table holds the neutral model (no correction): {}",
                 name, outcome.failure);
  }
  int identified = 0;
  for (const auto& c : r.cells) identified += c.status == ident::CellStatus::kIdentified;
  spdlog::info("joint {}: {}/{} cells identified, backlash l = {:.3g} ± {:.2g} rad, {:.2f} s", name,
               identified, r.cells.size(), r.parameters.backlash_l_rad,
               r.parameters.backlash_l_sigma_rad, outcome.seconds);
  // A cell's figures judge its own model on its own held-out runs (each restarted from the
  // measured output); the table line judges what the precontrol applies: every cell blended.
  for (const auto& c : r.cells) {
    const ident::CellFitFigures& f = r.parameters.cells[std::size_t(c.cell)].figures;
    std::cout << fmt::format(
        "{:>4} cell {:>2} {:<40} {:<10} {:>14} cell's own held-out fit: angle {:>7.2f} %, "
        "joint error {:>7.2f} %\n",
        name, c.cell, c.label, ident::to_string(c.status),
        c.sweep ? ident::to_string(c.sweep->chosen) : "-", f.simulation_fit_percent,
        f.joint_error_fit_percent);
  }
  std::cout << fmt::format(
      "{:>4} table: held-out joint-error fit {:>7.2f} % over {} rows (all {} cells blended as "
      "the precontrol applies them)\n",
      name, r.table_fit.joint_error_fit_percent, r.table_fit.rows, r.cells.size());
}

// An inverse-form table does not predict the joint error from q_d (the gap diagnosis's "sim"):
// the paper's forward error model from the same data is written beside it.
std::optional<ident::ParameterTable> forward_table_of(const ident::JointErrorLog& log,
                                                      const ident::IdentificationConfig& config,
                                                      const ident::ParameterTable& table) {
  if (config.options.form != ident::ArxModelForm::kInverse) return std::nullopt;
  spdlog::info("identify: the forward error model (paper form) for the gap diagnosis");
  const ident::IdentificationConfig forward = imscal::eval::paper_form(config);
  ident::ParameterTable forward_table = ident::parameter_table_header(log, forward, table.source);
  for (auto& outcome : ident::identify_joints(log, forward))
    forward_table.joints.push_back(std::move(outcome.result.parameters));
  return forward_table;
}

void run(const IdentifyArgs& args) {
  const auto start = std::chrono::steady_clock::now();
  ident::JointErrorLog log = ident::read_joint_errors_csv(args.joint_errors);
  const imscal::ConfigNode config_node = imscal::ConfigNode::load_file(args.config);
  std::vector<std::string> warnings;
  ident::IdentificationConfig config =
      ident::resolve_for_record(ident::load_identification_config(config_node), log.robot,
                                log.cycle_s, args.joint_errors, &warnings);
  for (const std::string& w : warnings) spdlog::warn("identify: {}", w);
  attach_model_torques(log, config, args);
  if (config.max_speed_rad_s.size() != log.joint_count())
    throw imscal::InputError(
        args.config, config_node.child("joints").child("max_speed_deg_s").line(),
        "joints.max_speed_deg_s",
        fmt::format("{} maximum speeds, but {} has {} joints ({})", config.max_speed_rad_s.size(),
                    args.joint_errors, log.joint_count(), fmt::join(log.joint_names, ", ")));
  check_payload_plausible(log, config, args);
  check_orders_fit_record(log, config, config_node, args.config, args.joint_errors);
  imscal::OutputFolder folder(args.out, output_names(config),
                              args.force ? imscal::Overwrite::kAllow : imscal::Overwrite::kRefuse);
  std::optional<ident::OrderSearchReport> order_search;
  if (args.search_order) order_search = search_orders(log, args, config);

  const auto segments = log.segments();
  ident::ParameterTable table =
      ident::parameter_table_header(log, config,
                                    {args.joint_errors, ident::file_sha256_hex(args.joint_errors),
                                     log.sample_count(), log.source});
  spdlog::info("identify: {} joints, {} samples in {} segments, cycle {} s", log.joint_count(),
               log.sample_count(), segments.size(), log.cycle_s);
  spdlog::info("identify: per joint {} cells, order sweep na {}..{} nb {}..{} d {}..{}",
               config.joint_grid(0).cell_count(), config.options.grid.na_min,
               config.options.grid.na_max, config.options.grid.nb_min, config.options.grid.nb_max,
               config.options.grid.dead_time_min, config.options.grid.dead_time_max);
  // Progress: "joint NAME (DONE/TOTAL)" (the identify stage of `imscal run` reads it).
  const auto outcomes =
      ident::identify_joints(log, config, 0, [&log](std::size_t joint, std::size_t done) {
        spdlog::info("joint {} ({}/{}) done", log.joint_names[joint], done, log.joint_count());
      });
  for (std::size_t j = 0; j < log.joint_count(); ++j) {
    print_joint(outcomes[j], log.joint_names[j]);
    table.joints.push_back(outcomes[j].result.parameters);
  }
  check_some_joint_identified(outcomes, log, args.joint_errors);
  const ident::IdentificationReportHeader header{
      table.created_by,
      args.joint_errors,
      table.source.sha256,
      args.config,
      log.sample_count(),
      segments.size(),
      log.cycle_s,
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
      order_search};
  const json report = ident::identification_report_json(header, outcomes);
  const std::optional<ident::ParameterTable> forward_table = forward_table_of(log, config, table);
  const fs::path report_path = folder.folder() / "identification_report.json";
  imscal::write_file_atomically(folder.staged("identification_report.json"),
                                imscal::json_text(report, 1, report_path.string()));
  if (forward_table)
    ident::write_parameters_json(folder.staged("forward_parameters.json"), *forward_table);
  ident::write_parameters_csv(folder.staged("parameters.csv"), table);
  ident::write_parameters_json(folder.staged("parameters.json"), table);
  folder.commit();
  spdlog::info("wrote {}, {}, {}", (folder.folder() / "parameters.json").string(),
               (folder.folder() / "parameters.csv").string(), report_path.string());
}

imscal::tools::CommandRegistration registration{
    "identify",
    "Identify the per-joint ARX error models (operating-point cells, backlash) from joint errors",
    [](CLI::App& sub) {
      auto args = std::make_shared<IdentifyArgs>();
      sub.add_option("--joint-errors", args->joint_errors, "joint_errors.csv (imscal calibrate)")
          ->required();
      sub.add_option("--config", args->config,
                     "Identification config (datasets/identification/ident-default.yaml)")
          ->required();
      args->model_torque.add_to(sub);
      sub.add_option("--out", args->out, "Output folder")->required();
      sub.add_flag("--search-transmission-error-order", args->search_order,
                   "find each joint's transmission-error harmonic per motor revolution (0.5 .. "
                   "4) from the joint errors' held-out fit; the config's is the prior");
      sub.add_flag("--force", args->force, "Overwrite existing outputs");
      sub.callback([args] { run(*args); });
    }};
}  // namespace
