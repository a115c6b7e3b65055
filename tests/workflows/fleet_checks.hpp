#pragma once
// What the fleet workflow's tests check of its summary: fleet.csv against the run folders it
// summarises, read here apart from the workflow's script (nlohmann, not Python's csv/json).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

namespace imscal::test_support {

// fleet.csv as rows of column -> text (its cells hold no commas: names, verdicts, numbers).
inline std::vector<std::map<std::string, std::string>> read_fleet_csv(
    const std::filesystem::path& file) {
  std::ifstream in(file);
  std::string line;
  std::vector<std::string> columns;
  std::vector<std::map<std::string, std::string>> rows;
  for (bool header = true; std::getline(in, line); header = false) {
    if (!line.empty() && line.back() == '\r') line.pop_back();  // CSV's CRLF, if written so
    std::stringstream cells(line);
    std::vector<std::string> values;
    for (std::string cell; std::getline(cells, cell, ',');) values.push_back(cell);
    if (header) {
      columns = values;
      continue;
    }
    std::map<std::string, std::string>& row = rows.emplace_back();
    for (std::size_t i = 0; i < columns.size() && i < values.size(); ++i)
      row[columns[i]] = values[i];
  }
  return rows;
}

// The robot's row agrees with its run folder: every stage ok, the mounting verdict, and the
// verification's before/after figures (to 1e-9 mm: Python prints doubles with 17 digits).
inline void expect_row_matches_run(const std::map<std::string, std::string>& row,
                                   const std::filesystem::path& run) {
  for (const char* stage : {"validate", "calibrate", "identify", "verify", "diagnose", "report"})
    EXPECT_EQ(row.at(std::string(stage) + "_status"), "ok") << run << " " << stage;
  std::ifstream mounting(run / "calibrate" / "mounting_report.json");
  EXPECT_EQ(row.at("mounting_verdict"), nlohmann::json::parse(mounting).at("verdict"));
  std::ifstream verification(run / "verify" / "campaign-line" / "verification.json");
  const nlohmann::json cases = nlohmann::json::parse(verification).at("cases");
  EXPECT_NEAR(std::stod(row.at("campaign-line_before_mm")),
              cases.at(0).at("max_path_deviation_mm").get<double>(), 1e-9);
  EXPECT_NEAR(std::stod(row.at("campaign-line_after_mm")),
              cases.at(1).at("max_path_deviation_mm").get<double>(), 1e-9);
  // The table's version as its own file states it (the summary must not hold another).
  std::ifstream table(run / "identify" / "parameters.json");
  EXPECT_EQ(row.at("table_schema_version"),
            std::to_string(nlohmann::json::parse(table).at("schema_version").get<int>()));
  EXPECT_EQ(row.at("table_sha256").size(), 64u);
}

}  // namespace imscal::test_support
