#include "eval/verification_files.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cctype>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "core/json_output.hpp"
#include "core/output_folder.hpp"
#include "core/units.hpp"
#include "eval/path_evaluation.hpp"

namespace imscal::eval {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

constexpr double kMm = 1e3;

json figures_json(const PathFigures& f) {
  return {{"max_path_deviation_mm", f.max_path_deviation_m * kMm},
          {"rms_path_deviation_mm", f.rms_path_deviation_m * kMm},
          {"scatter_floor_mm", f.scatter_floor_m * kMm},
          {"systematic_max_mm", f.systematic_max_m * kMm},
          {"about_mean_max_mm", f.about_mean_max_m * kMm},
          {"AT_p_mm", f.AT_p_m * kMm},
          {"RT_p_mm", json_number_or_null(f.RT_p_m * kMm)},
          {"AT_a_deg", f.AT_abc_rad[0] * kDegPerRad},
          {"AT_b_deg", f.AT_abc_rad[1] * kDegPerRad},
          {"AT_c_deg", f.AT_abc_rad[2] * kDegPerRad},
          {"RT_a_deg", json_number_or_null(f.RT_abc_rad[0] * kDegPerRad)},
          {"RT_b_deg", json_number_or_null(f.RT_abc_rad[1] * kDegPerRad)},
          {"RT_c_deg", json_number_or_null(f.RT_abc_rad[2] * kDegPerRad)},
          {"CO_mm", f.CO_m * kMm},
          {"CR_mm", json_number_or_null(f.CR_m * kMm)},
          {"AV_percent", f.AV_percent},
          {"RV_percent", json_number_or_null(f.RV_percent)},
          {"FV_m_s", f.FV_m_s},
          {"missed_crossings", f.missed_crossings}};
}

const char* kCsvHeader =
    "case,max_path_deviation_mm,reduction_percent,rms_path_deviation_mm,AT_p_mm,RT_p_mm,AT_a_deg,"
    "AT_b_deg,AT_c_deg,RT_a_deg,RT_b_deg,RT_c_deg,CO_mm,AV_percent,RV_percent,FV_m_s,"
    "inactive_cycles\n";

std::string csv_row(const VerificationCase& c, const PathFigures& before) {
  const auto& f = c.figures;
  return fmt::format(
      "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n", c.label, f.max_path_deviation_m * kMm,
      reduction_percent(before.max_path_deviation_m, f.max_path_deviation_m),
      f.rms_path_deviation_m * kMm, f.AT_p_m * kMm, f.RT_p_m * kMm, f.AT_abc_rad[0] * kDegPerRad,
      f.AT_abc_rad[1] * kDegPerRad, f.AT_abc_rad[2] * kDegPerRad, f.RT_abc_rad[0] * kDegPerRad,
      f.RT_abc_rad[1] * kDegPerRad, f.RT_abc_rad[2] * kDegPerRad, f.CO_m * kMm, f.AV_percent,
      f.RV_percent, f.FV_m_s, c.inactive_cycles);
}

std::string text_row(const VerificationCase& c, const PathFigures& before) {
  const auto& f = c.figures;
  return fmt::format(
      "{:<16} {:>9.3f} {:>7.1f} {:>8.3f} {:>7.3f} {:>7.4f} {:>7.4f} {:>7.4f} {:>7.3f} {:>+7.2f} "
      "{:>7.4f}\n",
      c.label, f.max_path_deviation_m * kMm,
      reduction_percent(before.max_path_deviation_m, f.max_path_deviation_m), f.AT_p_m * kMm,
      f.RT_p_m * kMm, f.AT_abc_rad[0] * kDegPerRad, f.AT_abc_rad[1] * kDegPerRad,
      f.AT_abc_rad[2] * kDegPerRad, f.CO_m * kMm, f.AV_percent, f.FV_m_s);
}

std::string slug(std::string s) {
  for (char& c : s)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return s;
}

// Every case of a result, the uncompensated one first.
std::vector<const VerificationCase*> all_cases(const VerificationResult& r) {
  std::vector<const VerificationCase*> cases{&r.before};
  for (const VerificationCase& c : r.after) cases.push_back(&c);
  return cases;
}

json case_json(const VerificationCase& c, const VerificationResult& r) {
  json j = figures_json(c.figures);
  j["case"] = c.label;
  j["reduction_of_max_path_deviation_percent"] =
      reduction_percent(r.before.figures.max_path_deviation_m, c.figures.max_path_deviation_m);
  j["inactive_cycles"] = c.inactive_cycles;
  j["true_path"] = figures_json(c.true_figures);
  j["true_path"]["reduction_of_max_path_deviation_percent"] = reduction_percent(
      r.before.true_figures.max_path_deviation_m, c.true_figures.max_path_deviation_m);
  json events = json::array();
  for (const auto& e : c.events)
    events.push_back({{"cycle", e.cycle},
                      {"joint", e.joint},
                      {"cause", ident::to_string(e.cause)},
                      {"value", e.value}});
  j["precontrol_events"] = events;
  return j;
}

// The same cases on the plant's true link-side path: the measurement's own share.
std::string true_path_text(const VerificationResult& r) {
  std::string text = fmt::format(
      "\nThe attained paths above are as the IMS chain measures them (simulated IMS record,\n"
      "mechanization, zero-velocity smoothing, frames, inverse kinematics). The same runs on "
      "the\n"
      "plant's true link-side path:\n{:<16} {:>9} {:>7} {:>8} {:>7}\n",
      "case", "maxdev_mm", "red_%", "AT_p_mm", "RT_p_mm");
  for (const VerificationCase* c : all_cases(r)) {
    const auto& f = c->true_figures;
    text += fmt::format(
        "{:<16} {:>9.3f} {:>7.1f} {:>8.3f} {:>7.3f}\n", c->label, f.max_path_deviation_m * kMm,
        reduction_percent(r.before.true_figures.max_path_deviation_m, f.max_path_deviation_m),
        f.AT_p_m * kMm, f.RT_p_m * kMm);
  }
  return text;
}

// Scatter floor, systematic and about-the-mean parts, and the notes closing the report.
std::string scatter_text(const VerificationResult& r, bool measured_with_ims) {
  std::string text =
      "\nScatter floor (the cycles' own scatter; no precontrol fed the desired path gets the "
      "max deviation below it):\n";
  for (const VerificationCase* c : all_cases(r)) {
    text +=
        fmt::format("{:<16} {:>7.3f} mm as measured", c->label, c->figures.scatter_floor_m * kMm);
    if (measured_with_ims)
      text += fmt::format(", {:.3f} mm on the true path", c->true_figures.scatter_floor_m * kMm);
    text += "\n";
  }
  text +=
      "\nThe cycles split at each instant into their mean (systematic: what the model gets "
      "wrong) and the distances from it (about the mean: the max a precontrol exact on average "
      "would leave):\n";
  for (const VerificationCase* c : all_cases(r)) {
    text +=
        fmt::format("{:<16} systematic {:.3f} mm, about the mean {:.3f} mm as measured", c->label,
                    c->figures.systematic_max_m * kMm, c->figures.about_mean_max_m * kMm);
    if (measured_with_ims)
      text += fmt::format("; {:.3f} and {:.3f} mm on the true path",
                          c->true_figures.systematic_max_m * kMm,
                          c->true_figures.about_mean_max_m * kMm);
    text += "\n";
  }
  text +=
      "\nCO: overshoot beyond the end point of each straight segment (the paths stop at every "
      "end; CR undefined). Cycles: friction drawn anew per cycle (eval/verification.hpp).\n";
  return text;
}

// verification.json, .csv and .txt; returns the text.
std::string write_tables(const fs::path& dir, const VerificationResult& r,
                         const VerificationRecord& record, Overwrite overwrite) {
  json cases = json::array();
  std::string csv = kCsvHeader, text;
  text += fmt::format("imscal verify: scenario {}, {} cycles, segments {} ({:.3f}..{:.3f} s)\n\n",
                      r.scenario, r.cycles, fmt::join(r.segments, ", "), r.evaluated_from_s,
                      r.evaluated_to_s);
  text += fmt::format("{:<16} {:>9} {:>7} {:>8} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7}\n",
                      "case", "maxdev_mm", "red_%", "AT_p_mm", "RT_p_mm", "AT_a°", "AT_b°", "AT_c°",
                      "CO_mm", "AV_%", "FV_m/s");
  for (const VerificationCase* c : all_cases(r)) {
    cases.push_back(case_json(*c, r));
    csv += csv_row(*c, r.before.figures);
    text += text_row(*c, r.before.figures);
  }
  if (record.measured_with_ims) text += true_path_text(r);
  text += scatter_text(r, record.measured_with_ims);
  const json doc = {{"scenario", r.scenario},
                    {"cycles", r.cycles},
                    {"seed", record.seed},
                    {"look_ahead_cycles", record.look_ahead_cycles},
                    {"inversion_iterations", record.inversion_iterations},
                    {"segments", r.segments},
                    {"evaluated_from_s", r.evaluated_from_s},
                    {"evaluated_to_s", r.evaluated_to_s},
                    {"table", record.table.empty() ? json(nullptr) : json(record.table)},
                    {"measured_by", record.measured_with_ims ? "ims chain" : "true link angles"},
                    {"cases", cases}};
  write_file_atomically(dir / "verification.json",
                        json_text(doc, 1, (dir / "verification.json").string()), overwrite);
  write_file_atomically(dir / "verification.csv", csv, overwrite);
  write_file_atomically(dir / "verification.txt", text, overwrite);
  return text;
}

// Fig. 5 and 6 series (cycle 0): before = uncompensated, after = the first table.
void write_figure_series(const fs::path& dir, const VerificationResult& r, Overwrite overwrite) {
  const PlotSeries& b = r.before.series;
  const PlotSeries* a = r.after.empty() ? nullptr : &r.after.front().series;
  std::string fig5 =
      "t_s,desired_x_mm,desired_y_mm,desired_z_mm,uncalibrated_x_mm,uncalibrated_y_mm,"
      "uncalibrated_z_mm,calibrated_x_mm,calibrated_y_mm,calibrated_z_mm\n";
  std::string fig6 = "t_s,arc_length_mm,deviation_uncalibrated_mm,deviation_calibrated_mm\n";
  for (std::size_t k = 0; k < b.t_s.size(); ++k) {
    const Eigen::Vector3d d = b.desired_m[k] * kMm, u = b.attained_m[k] * kMm;
    const Eigen::Vector3d c =
        a && k < a->attained_m.size() ? Eigen::Vector3d(a->attained_m[k] * kMm) : u;
    fig5 += fmt::format("{},{},{},{},{},{},{},{},{},{}\n", b.t_s[k], d.x(), d.y(), d.z(), u.x(),
                        u.y(), u.z(), c.x(), c.y(), c.z());
    fig6 += fmt::format("{},{},{},{}\n", b.t_s[k], b.arc_length_m[k] * kMm, b.deviation_m[k] * kMm,
                        a && k < a->deviation_m.size() ? a->deviation_m[k] * kMm : 0.0);
  }
  write_file_atomically(dir / "fig5_paths.csv", fig5, overwrite);
  write_file_atomically(dir / "fig6_deviation.csv", fig6, overwrite);
}

void write_figure_scripts(const fs::path& dir, const std::string& scenario, Overwrite overwrite) {
  const std::string fig5_gp =
      "set terminal svg size 1000,450\nset output 'fig5.svg'\nset datafile separator ','\n"
      "set key autotitle columnhead\nset multiplot layout 1,2 title 'desired and attained "
      "flange path (" +
      scenario +
      ")'\nset xlabel 'x [mm]'\nset ylabel 'y [mm]'\n"
      "plot 'fig5_paths.csv' u 2:3 w l t 'desired', '' u 5:6 w l t 'uncalibrated', '' u 8:9 w l "
      "t 'calibrated'\nset xlabel 'y [mm]'\nset ylabel 'z [mm]'\nplot 'fig5_paths.csv' u 3:4 w l "
      "t 'desired', '' u 6:7 w l t 'uncalibrated', '' u 9:10 w l t 'calibrated'\nunset "
      "multiplot\n";
  const std::string fig6_gp =
      "set terminal svg size 800,400\nset output 'fig6.svg'\nset datafile separator ','\n"
      "set title 'path deviation (" +
      scenario +
      ")'\nset xlabel 'time [s]'\n"
      "set ylabel 'path deviation [mm]'\nplot 'fig6_deviation.csv' u 1:3 w l t 'uncalibrated', "
      "'' u 1:4 w l t 'calibrated'\n";
  write_file_atomically(dir / "fig5.gp", fig5_gp, overwrite);
  write_file_atomically(dir / "fig6.gp", fig6_gp, overwrite);
}

// Path files for `imscal evaluate`.
void write_path_files(const fs::path& dir, const VerificationResult& r, Overwrite overwrite) {
  write_file_atomically(dir / "commanded.csv",
                        path_file_text(r.desired_poses, "commanded flange path"), overwrite);
  for (std::size_t c = 0; c < r.attained_poses.size(); ++c) {
    const std::string label = c == 0 ? r.before.label : r.after[c - 1].label;
    for (std::size_t j = 0; j < r.attained_poses[c].size(); ++j) {
      write_file_atomically(
          dir / fmt::format("attained_{}_{}.csv", slug(label), j),
          path_file_text(r.attained_poses[c][j], fmt::format("{}, cycle {}", label, j)), overwrite);
    }
  }
}

}  // namespace

std::string write_verification_files(const fs::path& dir, const VerificationResult& result,
                                     const VerificationRecord& record, Overwrite overwrite) {
  create_output_folder(dir);
  const std::string text = write_tables(dir, result, record, overwrite);
  write_figure_series(dir, result, overwrite);
  write_figure_scripts(dir, result.scenario, overwrite);
  write_path_files(dir, result, overwrite);
  return text;
}

VerifiedFigures read_verified_figures(const fs::path& verification_json) {
  std::ifstream in(verification_json);
  const json doc = json::parse(in);
  const json& cases = doc.at("cases");
  for (const json& c : cases) {
    if (c.at("case") != "compensated") continue;
    return {cases.front().at("max_path_deviation_mm").get<double>(),
            c.at("max_path_deviation_mm").get<double>(),
            c.at("reduction_of_max_path_deviation_percent").get<double>(),
            c.at("true_path").at("reduction_of_max_path_deviation_percent").get<double>(),
            c.at("scatter_floor_mm").get<double>(),
            c.at("systematic_max_mm").get<double>()};
  }
  throw std::runtime_error(verification_json.string() + ": no compensated case");
}

}  // namespace imscal::eval
