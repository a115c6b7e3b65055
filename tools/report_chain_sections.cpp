#include "tools/report_chain_sections.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <vector>

#include "calib/mounting_report_json.hpp"
#include "core/input_error.hpp"

namespace imscal::tools {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

std::optional<std::string> read_text(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return std::nullopt;
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string esc(const std::string& text) {
  return html_escape(text);
}

std::string num(double value, int digits = 6) {
  return std::isfinite(value) ? fmt::format("{:.{}g}", value, digits) : "n/a";
}

std::string verdict_class(const std::string& verdict) {
  return verdict == "pass" ? "ok" : verdict == "warn" ? "filled" : "fail";
}

std::string list_items(const json& list) {
  std::string items;
  for (const json& item : list)
    if (item.is_string()) items += "<li>" + esc(item.get<std::string>()) + "</li>\n";
  return items.empty() ? "" : "<ul>\n" + items + "</ul>\n";
}

// The completed stage's folder, or the reason it is missing.
std::optional<fs::path> stage_dir(const StageWorkspace& ws, const std::string& stage,
                                  std::string& why) {
  const auto dir = ws.upstream_dir(stage);
  if (!dir) why = fmt::format("the {} stage did not run in this run.", stage);
  return dir;
}

}  // namespace

std::optional<json> read_json_file(const fs::path& file) {
  const auto text = read_text(file);
  if (!text) return std::nullopt;
  json value = json::parse(*text, nullptr, false);
  if (value.is_discarded()) return std::nullopt;
  return value;
}

std::string not_run_note(const std::string& what) {
  return "<p class=\"not-run\">Not run: " + esc(what) + "</p>\n";
}

std::string figure_html(const std::string& svg, const std::string& caption) {
  return "<figure>\n" + svg + "\n<figcaption>" + esc(caption) + "</figcaption>\n</figure>\n";
}

std::string mounting_body(const StageWorkspace& ws) {
  std::string why;
  const auto dir = stage_dir(ws, "calibrate", why);
  if (!dir) return not_run_note(why);
  const auto frames = read_json_file(*dir / "frames.json");
  if (!frames) return not_run_note("calibrate left no frames.json.");
  std::optional<calib::MountingReport> report;
  try {
    report = calib::read_mounting_report(*dir / "mounting_report.json");
  } catch (const InputError& e) {
    return not_run_note(e.what());
  }
  const std::string verdict = calib::to_string(report->validation.verdict);
  std::string body = fmt::format("<p>Mounting verdict: <b class=\"{}\">{}</b></p>\n",
                                 verdict_class(verdict), esc(verdict));
  body += list_items(report->validation.reasons);
  body +=
      "<table>\n<tr><th>estimate</th><th>component</th><th>value</th><th>1&sigma;</th>"
      "<th>unit</th></tr>\n";
  for (const json& e : frames->value("estimates", json::array())) {
    const json components = e.value("components", json::array());
    const json values = e.value("value", json::array()), sigmas = e.value("sigma", json::array());
    for (std::size_t i = 0; i < components.size() && i < values.size() && i < sigmas.size(); ++i)
      body += fmt::format("<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>\n",
                          i == 0 ? esc(e.value("name", "")) : "",
                          esc(components[i].get<std::string>()), num(values[i].get<double>()),
                          num(sigmas[i].get<double>(), 3), esc(e.value("unit", "")));
  }
  body += "</table>\n";
  for (const char* frame : {"T_S_H", "T_R_W"}) {
    const json t = frames->value(frame, json::object());
    const json xyz = t.value("xyz_mm", json::array()), rpy = t.value("rpy_deg", json::array());
    if (xyz.size() == 3 && rpy.size() == 3)
      body += fmt::format("<p>{}: xyz {} {} {} mm, roll/pitch/yaw {} {} {} deg.</p>\n", frame,
                          num(xyz[0].get<double>(), 8), num(xyz[1].get<double>(), 8),
                          num(xyz[2].get<double>(), 8), num(rpy[0].get<double>(), 8),
                          num(rpy[1].get<double>(), 8), num(rpy[2].get<double>(), 8));
  }
  std::string weak;
  for (const json& w : frames->value("weak_directions", json::array()))
    weak += fmt::format("<li>{}: 1&sigma; {} {}; {}</li>\n", esc(w.value("description", "")),
                        num(w.value("sigma", 0.0), 3), esc(w.value("unit", "")),
                        esc(w.value("suggestion", "")));
  if (!weak.empty())
    body += "<p>Directions the pose set hardly excites:</p>\n<ul>\n" + weak + "</ul>\n";
  body += fmt::format("<p>Rest poses used: {}; outlier blocks: {}; solver: {}</p>\n",
                      frames->value("rests", json::object()).value("used", 0),
                      report->validation.outlier_count,
                      esc(frames->value("solver", json::object()).value("brief_report", "")));
  return body;
}

// One verified scenario's folder (verify/<scenario>/): its ISO 9283 table and Fig. 5/6.
std::string scenario_paths(const fs::path& dir, GnuplotRenderer& gnuplot) {
  const std::string name = dir.filename().string();
  std::string body = "<h3>" + esc(name) + "</h3>\n";
  if (const auto text = read_text(dir / "verification.txt"))
    body += "<pre>" + esc(*text) + "</pre>\n";
  const std::string fig5 = gnuplot_quoted(dir / "fig5_paths.csv");
  const std::string fig6 = gnuplot_quoted(dir / "fig6_deviation.csv");
  if (fs::exists(dir / "fig5_paths.csv")) {
    const std::string script =
        "set datafile separator ','\nset key outside bottom center horizontal\n"
        "set multiplot layout 1,2\nset xlabel 'x [mm]'\nset ylabel 'y [mm]'\nplot " +
        fig5 +
        " every ::1 u 2:3 w l lw 2 t 'desired', '' every ::1 u 5:6 w l t 'uncalibrated', '' "
        "every ::1 u 8:9 w l t 'calibrated'\nset xlabel 'y [mm]'\nset ylabel 'z [mm]'\nplot " +
        fig5 +
        " every ::1 u 3:4 w l lw 2 t 'desired', '' every ::1 u 6:7 w l t 'uncalibrated', '' "
        "every ::1 u 9:10 w l t 'calibrated'\nunset multiplot\n";
    body += figure_html(
        gnuplot.render("fig5-" + name, "Fig. 5 (" + name + "): desired and attained paths", script,
                       1000, 450),
        "Desired and attained flange paths of " + name +
            " before (uncalibrated) and after (calibrated: with the precontrol), xy and yz "
            "projections, first cycle (paper Fig. 5).");
  }
  if (fs::exists(dir / "fig6_deviation.csv")) {
    const std::string script =
        "set datafile separator ','\nset xlabel 'time [s]'\nset ylabel 'path deviation [mm]'\n"
        "plot " +
        fig6 + " every ::1 u 1:3 w l t 'uncalibrated', '' every ::1 u 1:4 w l t 'calibrated'\n";
    body += figure_html(
        gnuplot.render("fig6-" + name, "Fig. 6 (" + name + "): path deviation", script, 900, 400),
        "Perpendicular path deviation of " + name +
            " along the path before and after calibration (paper Fig. 6).");
  }
  return body;
}

std::string paths_body(const StageWorkspace& ws, GnuplotRenderer& gnuplot) {
  std::string why;
  const auto dir = stage_dir(ws, "verify", why);
  if (!dir) return not_run_note(why);
  std::vector<fs::path> scenarios;
  for (const auto& entry : fs::directory_iterator(*dir))
    if (entry.is_directory() && fs::exists(entry.path() / "verification.txt"))
      scenarios.push_back(entry.path());
  std::sort(scenarios.begin(), scenarios.end());
  if (scenarios.empty()) return not_run_note("verify left no verification.txt.");
  std::string body;
  for (const fs::path& scenario : scenarios) body += scenario_paths(scenario, gnuplot);
  return body;
}

std::string gap_body(const StageWorkspace& ws) {
  std::string why;
  const auto dir = stage_dir(ws, "diagnose", why);
  if (!dir) return not_run_note(why);
  const auto text = read_text(*dir / "report.txt");
  if (!text) return not_run_note("diagnose left no report.txt.");
  std::string body = "<pre>" + esc(*text) + "</pre>\n";
  // The diagnosis' own gnuplot figures (ids already prefixed per figure by GnuplotRenderer).
  const std::pair<const char*, const char*> figures[] = {
      {"gap-where.svg", "Where the gap lies: its energy by joint and by motion phase."},
      {"gap-spectrum.svg", "Spectrum of the gap per joint (Welch)."},
      {"gap-model-error.svg",
       "Model-error model: frequency response from the desired joint angle to the gap, with its "
       "2-sigma band (frequencies the motion does not excite get wide bands)."}};
  for (const auto& [file, caption] : figures)
    if (const auto svg = read_text(*dir / file)) body += figure_html(*svg, caption);
  return body;
}

}  // namespace imscal::tools
