#pragma once
// A verification session as `imscal verify` runs it: the parameter table from a file, or
// identified from joint errors (a joint_errors.csv, or the simulator's truth of a scenario), the
// ablation tables from the same joint errors, then each scenario verified with all the tables
// (eval/verification.hpp) and its files written (eval/verification_files.hpp).
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "core/atomic_file.hpp"
#include "eval/verification.hpp"
#include "eval/verification_files.hpp"

namespace imscal::eval {

struct VerificationSessionOptions {
  std::string table;                   // parameters.json; empty: identified from the joint errors
  std::string joint_errors;            // joint_errors.csv for the table and the ablation
  std::string identify_scenario;       // else the joint errors are this scenario's simulator truth
  std::string ident_config;            // empty: datasets/identification/ident-default.yaml
  std::vector<std::string> scenarios;  // names or files, verified in this order
  bool ablation = true;
  bool search_order = false;  // the transmission error's order per joint from the data
  VerificationOptions verification;
};

// Stage ("tables" or the scenario's name) and the fraction of the session done, in [0, 1].
using VerificationSessionProgress = std::function<void(const std::string& stage, double fraction)>;
// Called after each scenario's files are written into `dir`, with its text report.
using ScenarioVerified =
    std::function<void(const std::filesystem::path& dir, const std::string& report_text)>;

// Runs the session into `out`: joint_errors_truth.csv (truth joint errors), parameters.json (a
// table identified here), and a folder per scenario. InputError on bad input (no table source,
// robots that differ, a scenario the verification refuses).
void verify_session(const VerificationSessionOptions& options, const std::filesystem::path& out,
                    Overwrite overwrite, const ScenarioVerified& on_scenario = {},
                    const VerificationSessionProgress& progress = {});

}  // namespace imscal::eval
