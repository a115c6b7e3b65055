#pragma once
// An identification session as `imscal identify` runs it: the per-joint ARX error models of the
// paper (equation 2, Table 2) with backlash (equation 3), from a joint_errors.csv and an
// identification config, with the model torques of the log's path when the config's models take
// them (eval/model_torque.hpp) and, on request, each joint's transmission-error order searched
// from the data (eval/transmission_error_order.hpp). Its outputs, written all or nothing:
// parameters.json (the table the precontrol loads), parameters.csv, identification_report.json
// (chosen orders, criterion curves, validation figures, backlash, filled cells with reasons) and,
// for an inverse-form config, forward_parameters.json (the paper's forward error model from the
// same data, for the gap diagnosis).
#include <chrono>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/output_folder.hpp"
#include "eval/model_torque.hpp"
#include "ident/identification_config.hpp"
#include "ident/identification_report.hpp"
#include "ident/identify_joints.hpp"
#include "ident/joint_error_io.hpp"

namespace imscal::eval {

struct IdentificationSessionOptions {
  std::string joint_errors;          // joint_errors.csv
  std::string config;                // identification config
  bool search_order = false;         // the transmission error's order per joint from the data
  bool search_second_order = false;  // with search_order: a second harmonic per joint (BIC)
  // The orders per joint from the joint errors' order spectrum instead (up to two per joint,
  // eval/transmission_error_order_spectrum.hpp).
  bool track_orders = false;
  // The rigid-body model for the data of robot `data_robot` (file `data_file`, sample time
  // data_cycle_s), asked only when the config's models take the model torque; `needed_by_file`
  // and `needed_by_field` name what asked, for its InputError (tools/model_torque_option.hpp).
  std::function<ModelTorqueSource(const std::string& data_robot, const std::string& data_file,
                                  const std::string& needed_by_file,
                                  const std::string& needed_by_field, double data_cycle_s)>
      model_torque;
};

// The log and config read and checked against each other (joint count, payload rating, orders
// that fit the record's segments): InputError naming file, line and field otherwise.
struct PreparedIdentification {
  IdentificationSessionOptions options;
  ident::JointErrorLog log;
  ident::IdentificationConfig config;
  // The model torque's links refined from the log (model.refine_mass_parameters), else empty.
  std::vector<ident::LinkMassParameters> model_torque_links;
  // The nominal robot's rigid-body model (before any refinement), when the config takes the model
  // torque: the friction levels are estimated beside its drive values.
  std::optional<ModelTorqueSource> nominal_model;
  // The rigid-body model the torques were attached with (when the config's models take them).
  std::optional<ModelTorqueSource> model_torque;
  std::chrono::steady_clock::time_point start;
};
PreparedIdentification prepare_identification(const IdentificationSessionOptions& options);

// The files the session writes for this config, relative to the output folder.
std::vector<std::filesystem::path> identification_output_names(
    const ident::IdentificationConfig& config);

struct IdentificationResult {
  ident::ParameterTable table;
  std::optional<ident::ParameterTable> forward_table;  // inverse-form configs
  std::vector<ident::JointOutcome> outcomes;           // in joint order
  std::vector<std::string> joint_names;
  nlohmann::json report;  // identification_report.json
  // Empty when a joint was identified; else why none was (a table that corrects nothing).
  std::string no_joint_identified;
};

// (stage, fraction of it done in [0, 1]); "joints" as each joint finishes.
using IdentificationProgress = std::function<void(const std::string& stage, double fraction)>;

// Identifies every joint (the forward table and the report only when one was identified).
IdentificationResult identify_session(PreparedIdentification prepared,
                                      const IdentificationProgress& progress = {});

// A joint's lines of the text summary: its cells' own held-out fits and its table's.
std::string joint_summary_text(const ident::JointOutcome& outcome, const std::string& name);

// Writes the result's files into the folder's staging (commit is the caller's).
void write_identification(const OutputFolder& folder, const IdentificationResult& result);

}  // namespace imscal::eval
