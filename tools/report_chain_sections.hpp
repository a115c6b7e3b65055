#pragma once
// The report's sections on the later stages of the chain, from their outputs in the run folder:
// the mounting verdict with the frames and their 1-sigma (calibrate: frames.json,
// mounting_report.json), the paths before and after calibration with the ISO 9283 table (verify:
// verification.txt, fig5_paths.csv, fig6_deviation.csv; paper Fig. 5 and 6, redrawn by gnuplot),
// and the sim-to-real gap diagnosis (diagnose: report.json, report.txt). Each returns the HTML
// body of its section, or a "not run" note saying why.
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "core/run_stage.hpp"
#include "tools/report_gnuplot.hpp"

namespace imscal::tools {

std::string mounting_body(const StageWorkspace& ws);
std::string paths_body(const StageWorkspace& ws, GnuplotRenderer& gnuplot);
std::string gap_body(const StageWorkspace& ws);

// Small helpers shared by the report's sections. read_json_file: the parsed file, or nullopt when
// it is missing or not JSON.
std::optional<nlohmann::json> read_json_file(const std::filesystem::path& file);
std::string not_run_note(const std::string& what);
std::string figure_html(const std::string& svg, const std::string& caption);

}  // namespace imscal::tools
