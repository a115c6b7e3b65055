#include "eval/identification_session.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <stdexcept>

#include "core/atomic_file.hpp"
#include "core/config_node.hpp"
#include "core/input_error.hpp"
#include "core/json_output.hpp"
#include "core/payload_plausibility.hpp"
#include "eval/friction_identification.hpp"
#include "eval/joint_error_limits.hpp"
#include "eval/refined_links_choice.hpp"
#include "eval/transmission_error_gear_mode.hpp"
#include "eval/transmission_error_order.hpp"
#include "eval/transmission_error_order_spectrum.hpp"
#include "eval/verification.hpp"
#include "ident/friction_levels_report.hpp"
#include "ident/identification_config_record.hpp"
#include "ident/parameter_table_io.hpp"

namespace imscal::eval {

namespace fs = std::filesystem;

namespace {

// The model torques of the log's path (eval/model_torque.hpp), when the config's models take
// them; the refined links when the config refines them. `nominal` gets the robot file's model,
// `used` the one the torques were attached with (refined or not).
std::vector<ident::LinkMassParameters> attach_session_model_torques(
    ident::JointErrorLog& log, const ident::IdentificationConfig& config,
    const IdentificationSessionOptions& options, std::optional<ModelTorqueSource>& nominal,
    std::optional<ModelTorqueSource>& used) {
  if (!config.options.model_torque_input) return {};
  if (!options.model_torque)
    throw InputError(options.config, 0, "model.model_torque", "no rigid-body model given");
  ModelTorqueSource model = options.model_torque(log.robot, options.joint_errors, options.config,
                                                 "model.model_torque", log.cycle_s);
  check_joint_error_limits(log, options.joint_errors, model.robot);
  nominal = model;
  std::vector<ident::LinkMassParameters> links;
  if (config.refine_mass_parameters || config.refine_gravity) {
    try {
      model = refined_and_chosen_model(log, config, model, links, "identify");
    } catch (const std::invalid_argument& e) {
      throw InputError(
          options.joint_errors, 0,
          config.refine_gravity ? "model.refine_gravity" : "model.refine_mass_parameters",
          e.what());
    }
  }
  spdlog::info("identify: model torques of {} along the {} path", model.robot.name,
               torque_along_measured_path(config.options) ? "measured" : "desired");
  attach_model_torques(log, model, config.options);
  used = model;
  return links;
}

// `--search-transmission-error-order`: each joint's harmonic found from the data replaces the
// config's (eval/transmission_error_order.hpp); the search for the report.
ident::OrderSearchReport search_orders(const ident::JointErrorLog& log,
                                       const std::string& config_file,
                                       ident::IdentificationConfig& config, bool second_order) {
  if (!config.options.transmission_error_input)
    throw InputError(config_file, 0, "model.transmission_error",
                     "--search-transmission-error-order needs the transmission-error "
                     "inputs (model.transmission_error: true)");
  spdlog::info("identify: searching the transmission error's order per motor revolution");
  const TransmissionErrorOrderSearch search = search_transmission_error_orders(
      log, config, default_order_candidates(), nullptr, second_order);
  ident::OrderSearchReport report;
  report.candidates_per_motor_rev = search.candidates;
  for (std::size_t j = 0; j < search.chosen_harmonic.size(); ++j) {
    spdlog::info("identify: {}: {}", log.joint_names[j], describe_order_search(search, j));
    std::vector<double> fits;
    for (const auto& per_candidate : search.fit_percent) fits.push_back(per_candidate[j]);
    report.joints.push_back({log.joint_names[j], search.prior_harmonic[j], search.best_harmonic[j],
                             search.gain_points[j], search.chosen_harmonic[j], fits});
    if (j < search.second_harmonic.size()) {
      report.joints.back().second_harmonic_per_motor_rev = search.second_harmonic[j];
      report.joints.back().second_bic = search.second_bic[j];
    }
  }
  config = with_searched_orders(std::move(config), search);
  return report;
}

// `--track-transmission-error-orders`: each joint's strongest significant order of the joint
// errors' order spectrum replaces the held-out search's harmonic, the second strongest (if any)
// becomes the joint's second pair (eval/transmission_error_order_spectrum.hpp). A joint without
// a significant order keeps the search's harmonic and no second pair. The report's search gets
// the orders used.
void track_orders(const ident::JointErrorLog& log, ident::IdentificationConfig& config,
                  ident::OrderSearchReport& report) {
  const std::vector<JointOrderSpectrum> spectra =
      transmission_error_order_spectra(log, config.gear_ratio);
  std::vector<double> first, second;
  for (std::size_t j = 0; j < log.joint_count(); ++j) {
    const std::vector<OrderLine>& found = spectra[j].significant;
    spdlog::info("identify: {} order spectrum: {}", log.joint_names[j],
                 describe_order_spectrum(spectra[j]));
    first.push_back(found.empty() ? config.transmission_error_harmonic(j) : found[0].order);
    second.push_back(found.size() > 1 ? found[1].order : 0.0);
    ident::OrderSearchJoint& joint = report.joints.at(j);
    joint.chosen_harmonic_per_motor_rev = first.back();
    joint.second_harmonic_per_motor_rev = second.back();
    joint.tracking_windows = spectra[j].windows;
    for (const OrderLine& line : found)
      joint.tracked_orders.push_back({line.order, line.amplitude_rad, line.floor_rad,
                                      line.significance_sigma, line.t_statistic});
  }
  config.transmission_error_harmonic_per_joint = first;
  config.options.second_transmission_error_input =
      std::ranges::any_of(second, [](double h) { return h > 0.0; });
  config.transmission_error_second_harmonic_per_joint =
      config.options.second_transmission_error_input ? second : std::vector<double>{};
}

// The order sweep's longest model must leave rows to fit it: a segment needs more samples than
// the longest lag plus the coefficients, or every cell fits from no rows and corrects nothing.
void check_orders_fit_record(const ident::JointErrorLog& log,
                             const ident::IdentificationConfig& config,
                             const ConfigNode& config_node, const std::string& file,
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
  throw InputError(
      file, order ? order->line() : 0, "order",
      fmt::format("the largest model (na {}, nb {}, dead time {}) needs more than {} samples in "
                  "one segment; the longest segment of {} has {}",
                  grid.na_max, grid.nb_max, grid.dead_time_max, longest_lag + coefficients,
                  log_file, longest_segment));
}

// A table in which no joint was identified corrects nothing: why, or empty when one was.
std::string no_joint_identified(const std::vector<ident::JointOutcome>& outcomes,
                                const ident::JointErrorLog& log, const std::string& log_file) {
  std::string reasons;
  for (std::size_t j = 0; j < outcomes.size(); ++j) {
    if (outcomes[j].failure.empty()) return "";
    reasons += fmt::format("{}joint {}: {}", reasons.empty() ? "" : "; ", log.joint_names[j],
                           outcomes[j].failure);
  }
  return fmt::format("{}: no joint could be identified, the table would correct nothing ({})",
                     log_file, reasons);
}

// An inverse-form table does not predict the joint error from q_d (the gap diagnosis's "sim"):
// the paper's forward error model from the same data is written beside it.
std::optional<ident::ParameterTable> forward_table_of(const ident::JointErrorLog& log,
                                                      const ident::IdentificationConfig& config,
                                                      const ident::ParameterTable& table) {
  if (config.options.form != ident::ArxModelForm::kInverse) return std::nullopt;
  spdlog::info("identify: the forward error model (paper form) for the gap diagnosis");
  const ident::IdentificationConfig forward = paper_form(config);
  ident::ParameterTable forward_table = ident::parameter_table_header(log, forward, table.source);
  forward_table.model_torque_links = table.model_torque_links;
  for (auto& outcome : ident::identify_joints(log, forward))
    forward_table.joints.push_back(std::move(outcome.result.parameters));
  return forward_table;
}

// Each joint's friction levels from the record's motor encoders, beside the nominal robot's
// (eval/friction_identification.hpp).
nlohmann::json friction_report(const ident::JointErrorLog& log, const ModelTorqueSource& nominal) {
  spdlog::info("identify: friction levels from the motor encoders' following error");
  const auto levels = identify_friction_levels(log, nominal);
  for (std::size_t j = 0; j < levels.size(); ++j)
    spdlog::info("identify: {} {}", log.joint_names[j], describe_friction_levels(levels[j]));
  return ident::friction_levels_json(levels, log.joint_names);
}

}  // namespace

PreparedIdentification prepare_identification(const IdentificationSessionOptions& options) {
  PreparedIdentification p;
  p.start = std::chrono::steady_clock::now();
  p.options = options;
  p.log = ident::read_joint_errors_csv(options.joint_errors);
  const ConfigNode config_node = ConfigNode::load_file(options.config);
  std::vector<std::string> warnings;
  p.config = ident::resolve_for_record(ident::load_identification_config(config_node), p.log.robot,
                                       p.log.cycle_s, options.joint_errors, &warnings);
  for (const std::string& w : warnings) spdlog::warn("identify: {}", w);
  p.model_torque_links =
      attach_session_model_torques(p.log, p.config, options, p.nominal_model, p.model_torque);
  if (p.config.max_speed_rad_s.size() != p.log.joint_count())
    throw InputError(
        options.config, config_node.child("joints").child("max_speed_deg_s").line(),
        "joints.max_speed_deg_s",
        fmt::format("{} maximum speeds, but {} has {} joints ({})", p.config.max_speed_rad_s.size(),
                    options.joint_errors, p.log.joint_count(), fmt::join(p.log.joint_names, ", ")));
  // The log's payload against the rating of the config (the payload cells are fractions of it).
  check_payload_series(
      p.log.payload_kg, p.log.time_s, p.config.nominal_payload_kg,
      {options.joint_errors, 0, "payload_kg",
       fmt::format("robot {} ({}: joints.nominal_payload_kg)", p.log.robot, options.config)});
  check_orders_fit_record(p.log, p.config, config_node, options.config, options.joint_errors);
  return p;
}

std::vector<fs::path> identification_output_names(const ident::IdentificationConfig& config) {
  std::vector<fs::path> names = {"identification_report.json", "parameters.csv", "parameters.json"};
  if (config.options.form == ident::ArxModelForm::kInverse)
    names.emplace_back("forward_parameters.json");
  return names;
}

IdentificationResult identify_session(PreparedIdentification p,
                                      const IdentificationProgress& progress) {
  const ident::JointErrorLog& log = p.log;
  const std::string& file = p.options.joint_errors;
  std::optional<ident::OrderSearchReport> order_search;
  if (p.options.search_order)
    order_search = search_orders(log, p.options.config, p.config, p.options.search_second_order);
  if (p.options.track_orders && order_search) track_orders(log, p.config, *order_search);
  // The config's loading ensures the model torque (and so the model) with the gear mode.
  if (p.config.transmission_error_gear_mode && p.model_torque)
    set_transmission_error_gear_modes(p.config, log, *p.model_torque);
  const auto segments = log.segments();
  IdentificationResult r;
  r.joint_names = log.joint_names;
  r.table = ident::parameter_table_header(
      log, p.config, {file, ident::file_sha256_hex(file), log.sample_count(), log.source});
  r.table.model_torque_links = p.model_torque_links;
  spdlog::info("identify: {} joints, {} samples in {} segments, cycle {} s", log.joint_count(),
               log.sample_count(), segments.size(), log.cycle_s);
  spdlog::info("identify: per joint {} cells, order sweep na {}..{} nb {}..{} d {}..{}",
               p.config.joint_grid(0).cell_count(), p.config.options.grid.na_min,
               p.config.options.grid.na_max, p.config.options.grid.nb_min,
               p.config.options.grid.nb_max, p.config.options.grid.dead_time_min,
               p.config.options.grid.dead_time_max);
  if (progress) progress("joints", 0.0);
  r.outcomes = ident::identify_joints(log, p.config, 0, [&](std::size_t joint, std::size_t done) {
    spdlog::info("joint {} ({}/{}) done", log.joint_names[joint], done, log.joint_count());
    if (progress) progress("joints", double(done) / double(log.joint_count()));
  });
  for (const ident::JointOutcome& outcome : r.outcomes)
    r.table.joints.push_back(outcome.result.parameters);
  r.no_joint_identified = no_joint_identified(r.outcomes, log, file);
  if (!r.no_joint_identified.empty()) return r;
  const ident::IdentificationReportHeader header{
      r.table.created_by,
      file,
      r.table.source.sha256,
      p.options.config,
      log.sample_count(),
      segments.size(),
      log.cycle_s,
      std::chrono::duration<double>(std::chrono::steady_clock::now() - p.start).count(),
      order_search};
  r.report = ident::identification_report_json(header, r.outcomes);
  if (!r.table.model_torque_links.empty())
    r.report["model_torque_links"] = ident::model_torque_links_json(r.table.model_torque_links);
  if (p.nominal_model) r.report["friction_levels"] = friction_report(log, *p.nominal_model);
  r.forward_table = forward_table_of(log, p.config, r.table);
  return r;
}

std::string joint_summary_text(const ident::JointOutcome& outcome, const std::string& name) {
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
  std::string text;
  for (const auto& c : r.cells) {
    const ident::CellFitFigures& f = r.parameters.cells[std::size_t(c.cell)].figures;
    text += fmt::format(
        "{:>4} cell {:>2} {:<40} {:<10} {:>14} cell's own held-out fit: angle {:>7.2f} %, "
        "joint error {:>7.2f} %\n",
        name, c.cell, c.label, ident::to_string(c.status),
        c.sweep ? ident::to_string(c.sweep->chosen) : "-", f.simulation_fit_percent,
        f.joint_error_fit_percent);
  }
  text += fmt::format(
      "{:>4} table: held-out joint-error fit {:>7.2f} % over {} rows (all {} cells blended as "
      "the precontrol applies them)\n",
      name, r.table_fit.joint_error_fit_percent, r.table_fit.rows, r.cells.size());
  return text;
}

void write_identification(const OutputFolder& folder, const IdentificationResult& result) {
  const fs::path report_path = folder.folder() / "identification_report.json";
  write_file_atomically(folder.staged("identification_report.json"),
                        json_text(result.report, 1, report_path.string()));
  if (result.forward_table)
    ident::write_parameters_json(folder.staged("forward_parameters.json"), *result.forward_table);
  ident::write_parameters_csv(folder.staged("parameters.csv"), result.table);
  ident::write_parameters_json(folder.staged("parameters.json"), result.table);
}

}  // namespace imscal::eval
