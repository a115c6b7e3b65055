#pragma once
// parameters.json (the versioned table, exact round trip: numbers are written with the
// shortest representation that reads back to the same double) and parameters.csv (one row per
// joint and cell, for people and spreadsheets; not read back). Format: datasets/FORMAT.md,
// sections "parameters.json" and "parameters.csv".
//
// Loading checks the whole schema and refuses with InputError(file, 0, JSON path, problem) on:
// unknown schema version, missing or unknown key, wrong type, non-finite number, a/b vector
// lengths that do not match na/nb, a missing, repeated or out-of-range cell, bounds that are not
// strictly increasing, a band list that does not match the dimensions, an identified model that
// is unstable, a non-positive sample time, negative backlash, unknown units.
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "core/atomic_file.hpp"
#include "ident/parameter_table.hpp"

namespace imscal::ident {

std::string parameters_json_text(const ParameterTable& table);

// The table's model_torque_links as parameters.json writes them (and the identification report).
nlohmann::json model_torque_links_json(const std::vector<LinkMassParameters>& links);
std::string parameters_csv_text(const ParameterTable& table);

void write_parameters_json(const std::filesystem::path& file, const ParameterTable& table,
                           Overwrite overwrite = Overwrite::kAllow);
void write_parameters_csv(const std::filesystem::path& file, const ParameterTable& table,
                          Overwrite overwrite = Overwrite::kAllow);

// origin: the file name used in error messages.
ParameterTable parse_parameters_json(const std::string& text, const std::string& origin);
ParameterTable read_parameters_json(const std::filesystem::path& file);

}  // namespace imscal::ident
