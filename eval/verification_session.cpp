#include "eval/verification_session.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <unistd.h>

#include <optional>
#include <stdexcept>
#include <system_error>
#include <vector>

#include "core/config_node.hpp"
#include "core/input_error.hpp"
#include "core/output_folder.hpp"
#include "core/payload_plausibility.hpp"
#include "eval/joint_error_limits.hpp"
#include "eval/refined_links_choice.hpp"
#include "eval/transmission_error_order.hpp"
#include "ident/identification_config.hpp"
#include "ident/joint_error_io.hpp"
#include "ident/parameter_table_io.hpp"

namespace imscal::eval {

namespace fs = std::filesystem;

namespace {

// The joint errors the tables are identified from, and the file that names them in messages.
struct JointErrorSource {
  std::optional<ident::JointErrorLog> log;
  std::string file;
};

// Where a session's files are published (`out`, the names its files and messages give) and
// where they are written until then (`work`, a hidden folder inside `out`).
struct SessionFolders {
  fs::path out, work;
};

// From a file, or the simulator's truth of a scenario (OUT/joint_errors_truth.csv).
JointErrorSource joint_error_source(const VerificationSessionOptions& options,
                                    const SessionFolders& folders) {
  JointErrorSource source;
  if (!options.joint_errors.empty()) {
    source.log = ident::read_joint_errors_csv(options.joint_errors);
    source.file = options.joint_errors;
  } else if (!options.identify_scenario.empty()) {
    spdlog::info("verify: simulating {} for the truth joint errors", options.identify_scenario);
    source.log = simulate_truth_joint_errors(
        sim::load_scenario(sim::resolve_scenario(options.identify_scenario)));
    source.file = (folders.out / "joint_errors_truth.csv").string();
    ident::write_joint_errors_csv(folders.work / "joint_errors_truth.csv", *source.log);
  }
  return source;
}

// The identification config, its payload rating checked against the log's payload.
ident::IdentificationConfig checked_config(const VerificationSessionOptions& options,
                                           const JointErrorSource& source) {
  const std::string config_file =
      options.ident_config.empty()
          ? (sim::resolve_scenario("identification").parent_path().parent_path() /
             "identification/ident-default.yaml")
                .string()
          : options.ident_config;
  ident::IdentificationConfig config =
      ident::load_identification_config(ConfigNode::load_file(config_file));
  check_payload_series(
      source.log->payload_kg, source.log->time_s, config.nominal_payload_kg,
      {source.file, 0, "payload_kg",
       fmt::format("robot {} ({}: joints.nominal_payload_kg)", source.log->robot, config_file)});
  return config;
}

// Replaces the config's harmonic per joint by the one the identification record fits best.
void search_orders(const ident::JointErrorLog& log, const ModelTorqueSource& torque_model,
                   ident::IdentificationConfig& config) {
  spdlog::info("verify: searching the transmission error's order per motor revolution");
  const TransmissionErrorOrderSearch search =
      search_transmission_error_orders(log, config, default_order_candidates(), &torque_model);
  for (std::size_t j = 0; j < search.chosen_harmonic.size(); ++j)
    spdlog::info("verify: {}: {}", log.joint_names[j], describe_order_search(search, j));
  config = with_searched_orders(std::move(config), search);
}

// The table identified with `config`, carrying the refined links (`links`, empty without) when
// its models take the model torque: the loop's precontrol then computes the torque with them.
ident::ParameterTable identified_table(const JointErrorSource& source,
                                       const ident::IdentificationConfig& config,
                                       const ModelTorqueSource& torque_model,
                                       const std::vector<ident::LinkMassParameters>& links,
                                       const std::string& label) {
  IdentifiedTable t = identify_table(*source.log, config, source.file, &torque_model);
  for (const auto& f : t.failed_joints) spdlog::warn("verify: {}: not identified: {}", label, f);
  if (config.options.model_torque_input) t.table.model_torque_links = links;
  return std::move(t.table);
}

// The compensated table (from the file or identified) and the ablation tables.
std::vector<NamedTable> session_tables(const VerificationSessionOptions& options,
                                       const JointErrorSource& source,
                                       const std::optional<ident::IdentificationConfig>& config,
                                       const ModelTorqueSource& torque_model,
                                       const std::vector<ident::LinkMassParameters>& links,
                                       const SessionFolders& folders) {
  std::vector<NamedTable> tables;
  if (!options.table.empty()) {
    tables.push_back({"compensated", ident::read_parameters_json(options.table)});
  } else {
    spdlog::info("verify: identifying the table from {}", source.file);
    const ident::ParameterTable table =
        identified_table(source, *config, torque_model, links, "compensated");
    ident::write_parameters_json(folders.work / "parameters.json", table);
    tables.push_back({"compensated", table});
  }
  if (source.log && options.ablation) {
    for (const auto& [label, cfg] : ablation_configs(*config)) {
      spdlog::info("verify: ablation table '{}'", label);
      tables.push_back({label, identified_table(source, cfg, torque_model, links, label)});
    }
  }
  return tables;
}

// The tables of the session: the joint errors' robot checked against the scenarios' nominal
// robot, whose rigid-body model (never the plant's) serves the multi-input tables.
std::vector<NamedTable> prepare_tables(const VerificationSessionOptions& options,
                                       const SessionFolders& folders) {
  const JointErrorSource source = joint_error_source(options, folders);
  if (options.table.empty() && !source.log)
    throw InputError("", 0, "--table", "give --table, --joint-errors or --identify-scenario");
  ModelTorqueSource torque_model = scenario_model_torque(sim::load_scenario(sim::resolve_scenario(
      options.identify_scenario.empty() ? options.scenarios.front() : options.identify_scenario)));
  if (source.log && source.log->robot != torque_model.robot.name)
    throw InputError(source.file, 0, "robot",
                     fmt::format("the joint errors are of robot '{}', the scenarios' "
                                 "nominal robot is '{}'",
                                 source.log->robot, torque_model.robot.name));
  if (!options.joint_errors.empty())
    check_joint_error_limits(*source.log, source.file, torque_model.robot);
  std::optional<ident::IdentificationConfig> config;
  if (source.log) config = checked_config(options, source);
  if (options.search_order) {
    if (!config || !config->options.transmission_error_input)
      throw InputError(options.ident_config, 0, "--search-transmission-error-order",
                       "needs joint errors and a config with the transmission error");
    search_orders(*source.log, torque_model, *config);
  }
  std::vector<ident::LinkMassParameters> links;
  const ModelTorqueSource refined =
      config && (config->refine_mass_parameters || config->refine_gravity)
          ? refined_and_chosen_model(*source.log, *config, torque_model, links, "verify")
          : torque_model;
  return session_tables(options, source, config, refined, links, folders);
}

// An earlier session's outputs are refused before any work (the output folder checks every file
// again when it publishes).
void refuse_earlier_outputs(const VerificationSessionOptions& options, const fs::path& out,
                            Overwrite overwrite) {
  if (overwrite == Overwrite::kAllow) return;
  std::vector<fs::path> earlier;
  for (const std::string& name : options.scenarios)
    earlier.push_back(out / sim::load_scenario(sim::resolve_scenario(name)).name /
                      "verification.json");
  if (options.table.empty()) earlier.push_back(out / "parameters.json");
  if (!options.identify_scenario.empty()) earlier.push_back(out / "joint_errors_truth.csv");
  for (const fs::path& file : earlier)
    if (fs::exists(file))
      throw InputError(file.string(), 0, "--out", "exists already (use --force to replace it)");
}

// The session's work folder, removed however the session ends, with the output folder when the
// session created it and published nothing (bad input leaves no trace).
struct WorkFolder {
  fs::path out, path;
  bool created_out = false;
  explicit WorkFolder(const fs::path& out_folder)
      : out(out_folder),
        path(out_folder / fmt::format(".imscal-verify-work-{}", ::getpid())),
        created_out(!fs::exists(out_folder)) {
    create_output_folder(out);
    fs::remove_all(path);
    fs::create_directories(path);
  }
  WorkFolder(const WorkFolder&) = delete;
  WorkFolder& operator=(const WorkFolder&) = delete;
  ~WorkFolder() {
    std::error_code ignored;
    fs::remove_all(path, ignored);
    if (created_out && fs::is_empty(out, ignored)) fs::remove(out, ignored);
  }
};

// A message about a file in the work folder, naming the file it is written for instead.
std::string named_as_published(std::string message, const fs::path& work, const fs::path& out) {
  const std::string from = work.string(), to = out.string();
  for (std::size_t at = message.find(from); at != std::string::npos;
       at = message.find(from, at + to.size()))
    message.replace(at, from.size(), to);
  return message;
}

// Every file the session wrote into `work`, published together into `out`
// (core/output_folder.hpp).
void publish(const fs::path& work, const fs::path& out, Overwrite overwrite) {
  std::vector<fs::path> names;
  for (const auto& entry : fs::recursive_directory_iterator(work))
    if (entry.is_regular_file()) names.push_back(fs::relative(entry.path(), work));
  OutputFolder folder(out, names, overwrite);
  for (const fs::path& name : names) fs::rename(work / name, folder.staged(name));
  folder.commit();
}

}  // namespace

void verify_session(const VerificationSessionOptions& options, const fs::path& out,
                    Overwrite overwrite, const ScenarioVerified& on_scenario,
                    const VerificationSessionProgress& progress) {
  if (progress) progress("tables", 0.0);
  refuse_earlier_outputs(options, out, overwrite);
  const WorkFolder work(out);
  const std::vector<NamedTable> tables = prepare_tables(options, {out, work.path});
  const VerificationOptions& verification = options.verification;
  const VerificationRecord record{options.verification.seed,
                                  options.verification.compensation.look_ahead_cycles,
                                  options.verification.compensation.inversion_iterations,
                                  options.table, options.verification.measure_with_ims};
  for (std::size_t i = 0; i < options.scenarios.size(); ++i) {
    const sim::Scenario scenario = sim::load_scenario(sim::resolve_scenario(options.scenarios[i]));
    spdlog::info("verify: {} ({} cycles x {} runs)", scenario.name, options.verification.cycles,
                 tables.size() + 1);
    if (progress) progress(scenario.name, double(i) / double(options.scenarios.size()));
    VerificationResult r;
    try {
      r = verify_scenario(scenario, tables, verification);
    } catch (const std::invalid_argument& e) {
      throw InputError(scenario.file.string(), 0, "", e.what());
    }
    const fs::path dir = work.path / scenario.name;
    std::string text;
    try {
      text = write_verification_files(dir, r, record, Overwrite::kAllow);
    } catch (const InputError&) {
      throw;
    } catch (const std::runtime_error& e) {  // a failed write: the file it was written for
      throw std::runtime_error(named_as_published(e.what(), work.path, out));
    }
    if (on_scenario) on_scenario(dir, text);
  }
  publish(work.path, out, overwrite);
  if (progress) progress("done", 1.0);
}

}  // namespace imscal::eval
