#include "tools/stage_report.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>

#include "core/atomic_file.hpp"
#include "core/input_error.hpp"
#include "core/units.hpp"
#include "core/version.hpp"
#include "ident/identification_report.hpp"
#include "ident/joint_error_io.hpp"
#include "ident/parameter_table_io.hpp"
#include "tools/report_chain_sections.hpp"
#include "tools/report_figures.hpp"
#include "tools/report_gnuplot.hpp"
#include "tools/report_structure_section.hpp"
#include "tools/stage_chain.hpp"

namespace imscal::tools {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

std::string esc(const std::string& text) {
  return html_escape(text);
}

// "identified", "filled from <cell>" or "neutral" (the joint could not be identified).
std::string cell_status_text(const ident::CellParameters& cell) {
  if (cell.status == ident::CellStatus::kFilled)
    return fmt::format("filled from {}", cell.filled_from);
  return ident::to_string(cell.status);
}

std::string number(double value, int digits = 4) {
  return std::isfinite(value) ? fmt::format("{:.{}g}", value, digits) : "n/a";
}

std::string not_run(const std::string& what) {
  return not_run_note(what);
}

std::string section(const std::string& id, const std::string& title, const std::string& intro,
                    const std::string& body) {
  return fmt::format("<section id=\"{}\">\n<h2>{}</h2>\n<p class=\"intro\">{}</p>\n{}</section>\n",
                     id, esc(title), esc(intro), body);
}

std::string figure(const std::string& svg, const std::string& caption) {
  return figure_html(svg, caption);
}

std::string stages_section(const std::vector<std::string>& upstream, const StageWorkspace& ws) {
  std::string rows;
  std::string inputs;
  for (const std::string& name : upstream) {
    const auto dir = ws.upstream_dir(name);
    const auto record = dir ? read_json_file(*dir / kStageRecordName) : std::nullopt;
    if (!record) {
      rows += fmt::format("<tr><td>{}</td><td class=\"not-run\">not run</td><td></td></tr>\n",
                          esc(name));
      continue;
    }
    const std::string status = record->value("status", "?");
    rows +=
        fmt::format("<tr><td>{}</td><td class=\"{}\">{}</td><td>{}</td></tr>\n", esc(name),
                    status == "ok" ? "ok" : "fail", esc(status), esc(record->value("message", "")));
    for (const json& file : record->value("inputs", json::object()).value("files", json::array()))
      inputs += fmt::format("<tr><td>{}</td><td>{}</td><td><code>{}</code></td><td>{}</td></tr>\n",
                            esc(name), esc(file.value("role", "")), esc(file.value("path", "")),
                            esc(file.value("sha256", "")));
  }
  return "<table>\n<tr><th>stage</th><th>status</th><th>result</th></tr>\n" + rows +
         "</table>\n<h3>Input files (SHA-256)</h3>\n<table class=\"small\">\n<tr><th>stage</th>"
         "<th>role</th><th>file</th><th>SHA-256</th></tr>\n" +
         inputs + "</table>\n";
}

std::string validation_body(const StageWorkspace& ws) {
  const auto dir = ws.upstream_dir("validate");
  if (!dir) return not_run("no raw IMS file or robot log in this run's inputs.");
  const auto v = read_json_file(*dir / "validation.json");
  if (!v) return not_run("validate/validation.json is missing or unreadable.");
  std::string body =
      "<table>\n<tr><th>record</th><th>file</th><th>samples</th><th>first t [s]</th>"
      "<th>last t [s]</th><th>duration [s]</th><th>step [s]</th></tr>\n";
  if (v->contains("imu")) {
    const json& i = (*v)["imu"];
    body += fmt::format(
        "<tr><td>IMS</td><td><code>{}</code></td><td>{}</td><td>{}</td><td>{}</td><td>{}</td>"
        "<td>{} (median)</td></tr>\n",
        esc(i.value("file", "")), i.value("samples", 0), number(i.value("first_t_s", 0.0), 8),
        number(i.value("last_t_s", 0.0), 8), number(i.value("duration_s", 0.0), 6),
        number(i.value("median_dt_s", 0.0)));
  }
  if (v->contains("robot_log")) {
    const json& r = (*v)["robot_log"];
    body += fmt::format(
        "<tr><td>robot log ({})</td><td><code>{}</code></td><td>{}</td><td>{}</td><td>{}</td>"
        "<td>{}</td><td>{} (cycle)</td></tr>\n",
        esc(r.value("robot", "")), esc(r.value("file", "")), r.value("samples", 0),
        number(r.value("first_t_s", 0.0), 8), number(r.value("last_t_s", 0.0), 8),
        number(r.value("duration_s", 0.0), 6), number(r.value("cycle_s", 0.0)));
  }
  body += "</table>\n";
  if (v->contains("overlap")) {
    const json& o = (*v)["overlap"];
    body += fmt::format(
        "<p>Overlap of the two raw clocks: {} s (from {} s to {} s; required at least {} s).</p>\n",
        number(o.value("duration_s", 0.0), 6), number(o.value("begin_s", 0.0), 8),
        number(o.value("end_s", 0.0), 8), number(o.value("min_overlap_s", 0.0)));
  }
  if (v->contains("imu") && !(*v)["imu"]["warnings"].empty()) {
    body += "<p>Warnings of the IMS reader:</p>\n<ul>\n";
    for (const json& w : (*v)["imu"]["warnings"])
      body += "<li>" + esc(w.get<std::string>()) + "</li>\n";
    body += "</ul>\n";
  }
  if (v->contains("check"))
    body += fmt::format("<p class=\"{}\">Check: {}</p>\n",
                        (*v)["check"].value("status", "") == "ok" ? "ok" : "fail",
                        esc((*v)["check"].value("message", "")));
  return body;
}

// The whole table's held-out joint-error fit of `joint` from identification_report.json (its
// cells blended as the precontrol blends them; ident/table_fit.hpp), or "n/a".
std::string table_fit_of(const std::optional<ident::IdentificationReport>& report,
                         const std::string& joint) {
  if (report)
    for (const ident::ReportedJoint& j : report->joints)
      if (j.name == joint) return number(j.table_joint_error_fit_percent);
  return "n/a";
}

std::string models_body(const ident::ParameterTable& table,
                        const std::optional<ident::IdentificationReport>& report,
                        GnuplotRenderer& gnuplot) {
  std::string body = fmt::format(
      "<p>Robot <b>{}</b>, sample time {} s, {} joints, identified from <code>{}</code> ({} "
      "samples, SHA-256 {}). Model per cell (paper eq. 2): q(k) + a<sub>1</sub> q(k-1) + ... + "
      "a<sub>na</sub> q(k-na) = b<sub>0</sub> q<sub>d</sub>(k-d) + ... ; fits are on held-out "
      "data.</p>\n",
      esc(table.robot), number(table.sample_time_s), table.joints.size(), esc(table.source.file),
      table.source.samples, esc(table.source.sha256));
  body +=
      "<table>\n<tr><th>joint</th><th>backlash l [mdeg]</th><th>1&sigma; [mdeg]</th>"
      "<th>identified</th><th>cells identified / all</th><th>table's joint-error fit [%] "
      "(held-out, cells blended as the precontrol applies them)</th></tr>\n";
  for (const auto& joint : table.joints) {
    int identified = 0;
    for (const auto& c : joint.cells) identified += c.status == ident::CellStatus::kIdentified;
    body += fmt::format(
        "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{} / {}</td><td>{}</td></tr>\n",
        esc(joint.name), number(joint.backlash_l_rad * kDegPerRad * 1000.0),
        number(joint.backlash_l_sigma_rad * kDegPerRad * 1000.0),
        joint.backlash_identified ? "yes" : "no", identified, joint.cells.size(),
        table_fit_of(report, joint.name));
  }
  body += "</table>\n";
  if (report) body += structure_table_html(*report) + friction_levels_html(report->friction_levels);
  body += model_torque_links_html(table.model_torque_links);
  for (const auto& joint : table.joints) {
    const ident::CellGrid grid = joint.grid();
    body += fmt::format(
        "<h3>Joint {}</h3>\n<table class=\"small\">\n<tr><th>cell</th>"
        "<th>operating point (SI)</th><th>status</th><th>na</th><th>nb</th>"
        "<th>dead time [cycles]</th><th>one-step fit [%]</th>"
        "<th>simulation fit [%]</th><th>cell's own joint-error fit [%]</th>"
        "<th>residual RMS [mdeg]</th><th>spectral radius</th></tr>\n",
        esc(joint.name));
    for (std::size_t c = 0; c < joint.cells.size(); ++c) {
      const auto& cell = joint.cells[c];
      const auto& f = cell.figures;
      const std::string status = cell_status_text(cell);
      body += fmt::format(
          "<tr><td>{}</td><td>{}</td><td class=\"{}\">{}</td><td>{}</td><td>{}</td><td>{}</td>"
          "<td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>\n",
          c, esc(grid.label(int(c))),
          cell.status == ident::CellStatus::kIdentified ? "ok" : "filled", esc(status),
          cell.structure.na, cell.structure.nb, cell.structure.dead_time,
          number(f.one_step_fit_percent), number(f.simulation_fit_percent),
          number(f.joint_error_fit_percent), number(f.residual_rms_rad * kDegPerRad * 1000.0),
          number(f.spectral_radius));
    }
    body += "</table>\n";
    const std::string svg = frequency_response_figure(gnuplot, joint, table.sample_time_s);
    if (!svg.empty())
      body += figure(svg, fmt::format("Joint {}: frequency response of every identified cell "
                                      "model, from the identified a and b vectors.",
                                      joint.name));
  }
  return body;
}

std::string coverage_body(const ident::ParameterTable& table) {
  std::string body =
      "<p>Each joint's error model is a table of cells over the operating point (paper Table 2). "
      "A cell is identified from its own samples when it has enough of them; otherwise it carries "
      "the model of its nearest identified neighbour (filled), and the precontrol's accuracy there "
      "is not measured.</p>\n<table class=\"small\">\n<tr><th>joint</th><th>cell</th>"
      "<th>operating point (SI)</th><th>estimation rows</th><th>validation rows</th>"
      "<th>status</th><th>reason</th></tr>\n";
  for (const auto& joint : table.joints) {
    const ident::CellGrid grid = joint.grid();
    int identified = 0;
    for (std::size_t c = 0; c < joint.cells.size(); ++c) {
      const auto& cell = joint.cells[c];
      const bool own = cell.status == ident::CellStatus::kIdentified;
      identified += own;
      body += fmt::format(
          "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td class=\"{}\">{}</td>"
          "<td>{}</td></tr>\n",
          esc(joint.name), c, esc(grid.label(int(c))),
          own ? std::to_string(cell.figures.estimation_rows) : "-",
          own ? std::to_string(cell.figures.validation_rows) : "-", own ? "ok" : "filled",
          cell_status_text(cell), esc(cell.reason));
    }
    body += fmt::format(
        "<tr class=\"total\"><td>{}</td><td colspan=\"6\">coverage: {} of {} cells identified "
        "({:.0f} %)</td></tr>\n",
        esc(joint.name), identified, joint.cells.size(),
        100.0 * identified / double(std::max<std::size_t>(1, joint.cells.size())));
  }
  return body + "</table>\n";
}

constexpr const char* kStyle = R"(body{font-family:sans-serif;max-width:1100px;margin:2em auto;
padding:0 1em;color:#222;line-height:1.4}
h1{border-bottom:2px solid #1f5fbf}h2{margin-top:2em;border-bottom:1px solid #ccc}
table{border-collapse:collapse;margin:.5em 0}td,th{border:1px solid #ccc;padding:.2em .5em;
text-align:left;vertical-align:top}th{background:#eef2f8}table.small{font-size:.85em}
.ok{color:#176f2c}.fail{color:#b3261e;font-weight:bold}.filled{color:#8a5a00}
.not-run{color:#666;font-style:italic}.intro{color:#444}code{font-size:.9em;word-break:break-all}
figure{margin:1em 0}figure svg{width:100%;height:auto;border:1px solid #ddd}
figcaption{font-size:.9em;color:#444})";

}  // namespace

StageInputs ReportStage::inputs() const {
  StageInputs in;
  if (config_.joint_errors) in.files.emplace_back("joint_errors", *config_.joint_errors);
  in.upstream = upstream_;
  in.config = {{"title", config_.title},
               {"gnuplot_timeout_s", config_.report.gnuplot_timeout_s},
               {"max_points_per_curve", config_.report.max_points_per_curve}};
  return in;
}

StageOutcome ReportStage::run(StageWorkspace& workspace) {
  GnuplotRenderer gnuplot(config_.report.gnuplot_timeout_s);
  workspace.progress(0.0);
  std::string sections;
  sections += section("stages", "What ran",
                      "The stages of this run folder, their results and the input files they "
                      "used with their SHA-256 checksums (to check that a report belongs to the "
                      "files at hand).",
                      stages_section(upstream_, workspace));
  sections += section("inputs", "Raw inputs",
                      "The raw IMS record and the robot controller's log, as read and checked "
                      "(time stamps, units, gaps, saturation); the two clocks must overlap.",
                      validation_body(workspace));
  sections += section("mounting", "Frame calibration and mounting verdict",
                      "The robot base in the Earth-fixed frame (R_T_W), the sensor on the "
                      "flange (S_T_H) with their 1-sigma, and the verdict on the IMS mounting.",
                      mounting_body(workspace));
  workspace.progress(0.2);
  std::string joint_errors;
  if (const auto joint_errors_file = chain_joint_errors(config_, workspace)) {
    const ident::JointErrorLog log = ident::read_joint_errors_csv(*joint_errors_file);
    joint_errors = figure(
        joint_errors_figure(gnuplot, log, config_.report.max_points_per_curve),
        fmt::format("Joint angle errors of {} ({} samples, {} run(s)): blue the error seen at the "
                    "end effector by the IMS chain, red the error seen by the robot's internal "
                    "sensors (motor encoders); gear compliance and backlash appear only in blue.",
                    joint_errors_file->filename().string(), log.sample_count(),
                    log.segments().size()));
  } else {
    joint_errors = not_run(
        "no joint_errors.csv in this run's inputs, and no calibrate stage "
        "that completed.");
  }
  sections += section("joint-errors", "Joint angle errors (paper Fig. 2)",
                      "q_desired - q_measured (IMS) against q_desired - q_internal (internal "
                      "sensors), per joint, over time.",
                      joint_errors);
  workspace.progress(0.4);
  std::string models = not_run("the identify stage did not run in this run.");
  std::string coverage = models;
  if (const auto dir = workspace.upstream_dir("identify");
      dir && fs::exists(*dir / "parameters.json")) {
    const ident::ParameterTable table = ident::read_parameters_json(*dir / "parameters.json");
    std::optional<ident::IdentificationReport> report;
    try {
      report = ident::read_identification_report(*dir / "identification_report.json");
    } catch (const InputError& e) {
      spdlog::warn("report: no table fits: {}", e.what());
    }
    models = models_body(table, report, gnuplot);
    coverage = coverage_body(table);
  }
  sections += section("models", "Identified error models",
                      "Per joint and operating-point cell: model order, dead time, fit on "
                      "held-out data, and the frequency response computed from the a and b "
                      "vectors of parameters.json.",
                      models);
  sections += section("coverage", "Operating-point table coverage",
                      "Which cells of each joint's parameter table were identified from their own "
                      "data.",
                      coverage);
  workspace.progress(0.9);
  sections += section("paths",
                      "Paths and path deviation before and after calibration (paper "
                      "Fig. 5 and 6), ISO 9283",
                      "Desired and measured paths (xy and yz projections), the path deviation "
                      "along the path and the ISO 9283 path characteristics, uncalibrated and "
                      "calibrated.",
                      paths_body(workspace, gnuplot));
  sections += section("gap", "Sim-to-real gap diagnosis",
                      "What the robot model and the error model still miss, by comparing the "
                      "simulation with the measurement.",
                      gap_body(workspace));

  const std::string html = fmt::format(
      "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
      "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
      "<title>{}</title>\n<style>\n{}\n</style>\n</head>\n<body>\n<h1>{}</h1>\n"
      "<p>Dynamic calibration of an industrial robot with an inertial measurement system. "
      "Made by imscal {} from the run config <code>{}</code>. Angles in this report are in "
      "mdeg (1/1000 degree) unless named otherwise; the data files are in SI units.</p>\n"
      "{}</body>\n</html>\n",
      esc(config_.title), kStyle, esc(config_.title), kVersion, esc(config_.file.string()),
      sections);
  write_file_atomically(workspace.output_dir() / "report.html", html);
  workspace.progress(1.0);
  StageOutcome outcome;
  outcome.message = "report.html written";
  return outcome;
}

}  // namespace imscal::tools
