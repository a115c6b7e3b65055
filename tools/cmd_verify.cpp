// `imscal verify`: the paper's verification (section 4) in the simulator. The scenario's path is
// run by the uncalibrated robot and with the precontrol in the loop, n cycles each
// (eval/verification.hpp); written per scenario into OUT/<scenario>/:
//   verification.json / .csv / .txt   before/after ISO 9283 table (+ ablation), reductions
//   fig5_paths.csv, fig5.gp (+ .svg)  desired and attained flange paths, xy and yz (paper Fig. 5)
//   fig6_deviation.csv, fig6.gp (+ .svg)  path deviation along the path (paper Fig. 6)
//   commanded.csv, attained_<case>_<cycle>.csv  path files for `imscal evaluate`
// The table comes from --table, or is identified here from the simulator's truth of
// --identify-scenario (joint errors q_d - q_link; the IMS chain of `imscal calibrate` replaces it
// once ready; --joint-errors takes any joint_errors.csv instead). With joint errors at hand the
// ablation tables (backlash off, one cell) are identified from the same data.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>

#include "core/atomic_file.hpp"
#include "core/config_node.hpp"
#include "core/input_error.hpp"
#include "core/json_output.hpp"
#include "core/output_folder.hpp"
#include "core/payload_plausibility.hpp"
#include "core/units.hpp"
#include "eval/transmission_error_order.hpp"
#include "eval/verification.hpp"
#include "ident/identification_config.hpp"
#include "ident/joint_error_io.hpp"
#include "ident/parameter_table_io.hpp"
#include "tools/command_registry.hpp"

namespace {

using imscal::kDegPerRad;
namespace fs = std::filesystem;
namespace eval = imscal::eval;
namespace ident = imscal::ident;
using nlohmann::json;

struct VerifyArgs {
  std::string table, joint_errors, identify_scenario, ident_config, out, segments;
  std::vector<std::string> scenarios;
  int cycles = 10;
  std::uint64_t seed = 1;
  int look_ahead = eval::VerificationOptions{}.compensation.look_ahead_cycles;
  int inversion_iterations = eval::VerificationOptions{}.compensation.inversion_iterations;
  double offset_tolerance_rad = 0.0;  // 0: from the table's envelope
  bool measure_with_ims = true;
  bool ablation = true;
  bool search_order = false;  // the transmission error's order per joint from the data
  bool force = false;
};

// Replaces the config's harmonic per joint by the one the identification record fits best.
void search_orders(const ident::JointErrorLog& log, const eval::ModelTorqueSource& torque_model,
                   ident::IdentificationConfig& config) {
  spdlog::info("verify: searching the transmission error's order per motor revolution");
  const eval::TransmissionErrorOrderSearch search = eval::search_transmission_error_orders(
      log, config, eval::default_order_candidates(), &torque_model);
  for (std::size_t j = 0; j < search.chosen_harmonic.size(); ++j)
    spdlog::info("verify: {}: {}", log.joint_names[j], eval::describe_order_search(search, j));
  config = eval::with_searched_orders(std::move(config), search);
}

constexpr double kMm = 1e3;

json finite(double v) {
  return std::isfinite(v) ? json(v) : json(nullptr);
}

json figures_json(const eval::PathFigures& f) {
  return {{"max_path_deviation_mm", f.max_path_deviation_m * kMm},
          {"rms_path_deviation_mm", f.rms_path_deviation_m * kMm},
          {"scatter_floor_mm", f.scatter_floor_m * kMm},
          {"systematic_max_mm", f.systematic_max_m * kMm},
          {"about_mean_max_mm", f.about_mean_max_m * kMm},
          {"AT_p_mm", f.AT_p_m * kMm},
          {"RT_p_mm", finite(f.RT_p_m * kMm)},
          {"AT_a_deg", f.AT_abc_rad[0] * kDegPerRad},
          {"AT_b_deg", f.AT_abc_rad[1] * kDegPerRad},
          {"AT_c_deg", f.AT_abc_rad[2] * kDegPerRad},
          {"RT_a_deg", finite(f.RT_abc_rad[0] * kDegPerRad)},
          {"RT_b_deg", finite(f.RT_abc_rad[1] * kDegPerRad)},
          {"RT_c_deg", finite(f.RT_abc_rad[2] * kDegPerRad)},
          {"CO_mm", f.CO_m * kMm},
          {"CR_mm", finite(f.CR_m * kMm)},
          {"AV_percent", f.AV_percent},
          {"RV_percent", finite(f.RV_percent)},
          {"FV_m_s", f.FV_m_s},
          {"missed_crossings", f.missed_crossings}};
}

const char* kCsvHeader =
    "case,max_path_deviation_mm,reduction_percent,rms_path_deviation_mm,AT_p_mm,RT_p_mm,AT_a_deg,"
    "AT_b_deg,AT_c_deg,RT_a_deg,RT_b_deg,RT_c_deg,CO_mm,AV_percent,RV_percent,FV_m_s,"
    "inactive_cycles\n";

std::string csv_row(const eval::VerificationCase& c, const eval::PathFigures& before) {
  const auto& f = c.figures;
  return fmt::format(
      "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n", c.label, f.max_path_deviation_m * kMm,
      eval::reduction_percent(before.max_path_deviation_m, f.max_path_deviation_m),
      f.rms_path_deviation_m * kMm, f.AT_p_m * kMm, f.RT_p_m * kMm, f.AT_abc_rad[0] * kDegPerRad,
      f.AT_abc_rad[1] * kDegPerRad, f.AT_abc_rad[2] * kDegPerRad, f.RT_abc_rad[0] * kDegPerRad,
      f.RT_abc_rad[1] * kDegPerRad, f.RT_abc_rad[2] * kDegPerRad, f.CO_m * kMm, f.AV_percent,
      f.RV_percent, f.FV_m_s, c.inactive_cycles);
}

std::string text_row(const eval::VerificationCase& c, const eval::PathFigures& before) {
  const auto& f = c.figures;
  return fmt::format(
      "{:<16} {:>9.3f} {:>7.1f} {:>8.3f} {:>7.3f} {:>7.4f} {:>7.4f} {:>7.4f} {:>7.3f} {:>+7.2f} "
      "{:>7.4f}\n",
      c.label, f.max_path_deviation_m * kMm,
      eval::reduction_percent(before.max_path_deviation_m, f.max_path_deviation_m), f.AT_p_m * kMm,
      f.RT_p_m * kMm, f.AT_abc_rad[0] * kDegPerRad, f.AT_abc_rad[1] * kDegPerRad,
      f.AT_abc_rad[2] * kDegPerRad, f.CO_m * kMm, f.AV_percent, f.FV_m_s);
}

std::string path_file(const std::vector<Eigen::Matrix<double, 8, 1>>& rows,
                      const std::string& what) {
  std::string s = "# imscal-path: 1\n# frame: R (robot base), flange H\n# content: " + what +
                  "\nt_s,x_m,y_m,z_m,qw,qx,qy,qz\n";
  for (const auto& r : rows)
    s += fmt::format("{},{},{},{},{},{},{},{}\n", r[0], r[1], r[2], r[3], r[4], r[5], r[6], r[7]);
  return s;
}

std::string slug(std::string s) {
  for (char& c : s)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return s;
}

// Every case of a result, the uncompensated one first.
std::vector<const eval::VerificationCase*> all_cases(const eval::VerificationResult& r) {
  std::vector<const eval::VerificationCase*> cases{&r.before};
  for (const eval::VerificationCase& c : r.after) cases.push_back(&c);
  return cases;
}

// A command's outputs by their path in the output folder, published together at the end.
using OutputFiles = std::map<fs::path, std::string>;

// The scenario's outputs, in `dir` (relative to the output folder).
void write_scenario(const fs::path& dir, const eval::VerificationResult& r, const VerifyArgs& args,
                    OutputFiles& files) {
  const auto& before = r.before.figures;
  json cases = json::array();
  std::string csv = kCsvHeader, text;
  text += fmt::format("imscal verify: scenario {}, {} cycles, segments {} ({:.3f}..{:.3f} s)\n\n",
                      r.scenario, r.cycles, fmt::join(r.segments, ", "), r.evaluated_from_s,
                      r.evaluated_to_s);
  text += fmt::format("{:<16} {:>9} {:>7} {:>8} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7}\n",
                      "case", "maxdev_mm", "red_%", "AT_p_mm", "RT_p_mm", "AT_a°", "AT_b°", "AT_c°",
                      "CO_mm", "AV_%", "FV_m/s");
  for (const eval::VerificationCase* c : all_cases(r)) {
    json j = figures_json(c->figures);
    j["case"] = c->label;
    j["reduction_of_max_path_deviation_percent"] =
        eval::reduction_percent(before.max_path_deviation_m, c->figures.max_path_deviation_m);
    j["inactive_cycles"] = c->inactive_cycles;
    j["true_path"] = figures_json(c->true_figures);
    j["true_path"]["reduction_of_max_path_deviation_percent"] = eval::reduction_percent(
        r.before.true_figures.max_path_deviation_m, c->true_figures.max_path_deviation_m);
    json events = json::array();
    for (const auto& e : c->events)
      events.push_back({{"cycle", e.cycle},
                        {"joint", e.joint},
                        {"cause", ident::to_string(e.cause)},
                        {"value", e.value}});
    j["precontrol_events"] = events;
    cases.push_back(j);
    csv += csv_row(*c, before);
    text += text_row(*c, before);
  }
  if (args.measure_with_ims) {
    // The same cases on the plant's true link-side path: the measurement's own share.
    text += fmt::format(
        "\nThe attained paths above are as the IMS chain measures them (simulated IMS record,\n"
        "mechanization, zero-velocity smoothing, frames, inverse kinematics). The same runs on "
        "the\n"
        "plant's true link-side path:\n{:<16} {:>9} {:>7} {:>8} {:>7}\n",
        "case", "maxdev_mm", "red_%", "AT_p_mm", "RT_p_mm");
    for (const eval::VerificationCase* c : all_cases(r)) {
      const auto& f = c->true_figures;
      text += fmt::format("{:<16} {:>9.3f} {:>7.1f} {:>8.3f} {:>7.3f}\n", c->label,
                          f.max_path_deviation_m * kMm,
                          eval::reduction_percent(r.before.true_figures.max_path_deviation_m,
                                                  f.max_path_deviation_m),
                          f.AT_p_m * kMm, f.RT_p_m * kMm);
    }
  }
  text +=
      "\nScatter floor (the cycles' own scatter; no precontrol fed the desired path gets the "
      "max deviation below it):\n";
  for (const eval::VerificationCase* c : all_cases(r)) {
    text +=
        fmt::format("{:<16} {:>7.3f} mm as measured", c->label, c->figures.scatter_floor_m * kMm);
    if (args.measure_with_ims)
      text += fmt::format(", {:.3f} mm on the true path", c->true_figures.scatter_floor_m * kMm);
    text += "\n";
  }
  text +=
      "\nThe cycles split at each instant into their mean (systematic: what the model gets "
      "wrong) and the distances from it (about the mean: the max a precontrol exact on average "
      "would leave):\n";
  for (const eval::VerificationCase* c : all_cases(r)) {
    text +=
        fmt::format("{:<16} systematic {:.3f} mm, about the mean {:.3f} mm as measured", c->label,
                    c->figures.systematic_max_m * kMm, c->figures.about_mean_max_m * kMm);
    if (args.measure_with_ims)
      text += fmt::format("; {:.3f} and {:.3f} mm on the true path",
                          c->true_figures.systematic_max_m * kMm,
                          c->true_figures.about_mean_max_m * kMm);
    text += "\n";
  }
  text +=
      "\nCO: overshoot beyond the end point of each straight segment (the paths stop at every "
      "end; CR undefined). Cycles: friction drawn anew per cycle (eval/verification.hpp).\n";
  const json doc = {{"scenario", r.scenario},
                    {"cycles", r.cycles},
                    {"seed", args.seed},
                    {"look_ahead_cycles", args.look_ahead},
                    {"inversion_iterations", args.inversion_iterations},
                    {"segments", r.segments},
                    {"evaluated_from_s", r.evaluated_from_s},
                    {"evaluated_to_s", r.evaluated_to_s},
                    {"table", args.table.empty() ? json(nullptr) : json(args.table)},
                    {"measured_by", args.measure_with_ims ? "ims chain" : "true link angles"},
                    {"cases", cases}};
  files[dir / "verification.json"] =
      imscal::json_text(doc, 1, (dir / "verification.json").string());
  files[dir / "verification.csv"] = csv;
  files[dir / "verification.txt"] = text;
  std::cout << text;

  // Fig. 5 and 6 series (cycle 0): before = uncompensated, after = the first table.
  const eval::PlotSeries& b = r.before.series;
  const eval::PlotSeries* a = r.after.empty() ? nullptr : &r.after.front().series;
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
  files[dir / "fig5_paths.csv"] = fig5;
  files[dir / "fig6_deviation.csv"] = fig6;
  const std::string fig5_gp =
      "set terminal svg size 1000,450\nset output 'fig5.svg'\nset datafile separator ','\n"
      "set key autotitle columnhead\nset multiplot layout 1,2 title 'desired and attained "
      "flange path (" +
      r.scenario +
      ")'\nset xlabel 'x [mm]'\nset ylabel 'y [mm]'\n"
      "plot 'fig5_paths.csv' u 2:3 w l t 'desired', '' u 5:6 w l t 'uncalibrated', '' u 8:9 w l "
      "t 'calibrated'\nset xlabel 'y [mm]'\nset ylabel 'z [mm]'\nplot 'fig5_paths.csv' u 3:4 w l "
      "t 'desired', '' u 6:7 w l t 'uncalibrated', '' u 9:10 w l t 'calibrated'\nunset "
      "multiplot\n";
  const std::string fig6_gp =
      "set terminal svg size 800,400\nset output 'fig6.svg'\nset datafile separator ','\n"
      "set title 'path deviation (" +
      r.scenario +
      ")'\nset xlabel 'time [s]'\n"
      "set ylabel 'path deviation [mm]'\nplot 'fig6_deviation.csv' u 1:3 w l t 'uncalibrated', "
      "'' u 1:4 w l t 'calibrated'\n";
  files[dir / "fig5.gp"] = fig5_gp;
  files[dir / "fig6.gp"] = fig6_gp;
  // Path files for `imscal evaluate`.
  files[dir / "commanded.csv"] = path_file(r.desired_poses, "commanded flange path");
  for (std::size_t c = 0; c < r.attained_poses.size(); ++c) {
    const std::string label = c == 0 ? r.before.label : r.after[c - 1].label;
    for (std::size_t j = 0; j < r.attained_poses[c].size(); ++j) {
      files[dir / fmt::format("attained_{}_{}.csv", slug(label), j)] =
          path_file(r.attained_poses[c][j], fmt::format("{}, cycle {}", label, j));
    }
  }
}

// The figures' SVGs from their gnuplot scripts, in a published scenario folder: derived from
// the published CSV files, so drawn after them.
void plot_figures(const fs::path& dir) {
  if (std::system("command -v gnuplot > /dev/null 2>&1") != 0) {
    spdlog::info("gnuplot not found: run `gnuplot fig5.gp fig6.gp` in {} for the SVGs",
                 dir.string());
    return;
  }
  for (const char* gp : {"fig5.gp", "fig6.gp"}) {
    const std::string cmd = fmt::format("cd '{}' && gnuplot {} 2> /dev/null", dir.string(), gp);
    if (std::system(cmd.c_str()) != 0) spdlog::warn("gnuplot failed on {}", gp);
  }
}

// Every output of the command staged and published together (core/output_folder.hpp): the
// scenarios' files, and the truth joint errors and the identified table when there are any.
void publish(const fs::path& out, const OutputFiles& files, const ident::JointErrorLog* truth,
             const ident::ParameterTable* identified, imscal::Overwrite overwrite) {
  std::vector<fs::path> outputs;
  for (const auto& [name, text] : files) outputs.push_back(name);
  if (truth) outputs.emplace_back("joint_errors_truth.csv");
  if (identified) outputs.emplace_back("parameters.json");
  imscal::OutputFolder folder(out, outputs, overwrite);
  for (const auto& [name, text] : files) imscal::write_file_atomically(folder.staged(name), text);
  if (truth) ident::write_joint_errors_csv(folder.staged("joint_errors_truth.csv"), *truth);
  if (identified) ident::write_parameters_json(folder.staged("parameters.json"), *identified);
  folder.commit();
}

void run(const VerifyArgs& args) {
  const auto overwrite = args.force ? imscal::Overwrite::kAllow : imscal::Overwrite::kRefuse;
  const fs::path out(args.out);
  // Existing outputs are refused before the work (the output folder checks them again).
  for (const auto& name : args.scenarios) {
    const fs::path earlier = out /
                             imscal::sim::load_scenario(imscal::sim::resolve_scenario(name)).name /
                             "verification.json";
    if (!args.force && fs::exists(earlier))
      throw imscal::InputError(earlier.string(), 0, "--out",
                               "exists already (use --force to replace it)");
  }
  std::vector<eval::NamedTable> tables;
  std::optional<ident::ParameterTable> identified;
  // Joint errors: from a file, or the simulator's truth of a scenario.
  std::optional<ident::JointErrorLog> log;
  std::string source;
  if (!args.joint_errors.empty()) {
    log = ident::read_joint_errors_csv(args.joint_errors);
    source = args.joint_errors;
  } else if (!args.identify_scenario.empty()) {
    spdlog::info("verify: simulating {} for the truth joint errors", args.identify_scenario);
    log = eval::simulate_truth_joint_errors(
        imscal::sim::load_scenario(imscal::sim::resolve_scenario(args.identify_scenario)));
    source = (out / "joint_errors_truth.csv").string();
  }
  if (args.table.empty() && !log) {
    throw imscal::InputError("", 0, "--table",
                             "give --table, --joint-errors or --identify-scenario");
  }
  // The rigid-body model for multi-input tables: the nominal robot (never the plant) of the
  // identification scenario, else of the first verified scenario (the joint errors' robot must
  // be the same).
  const eval::ModelTorqueSource torque_model =
      eval::scenario_model_torque(imscal::sim::load_scenario(imscal::sim::resolve_scenario(
          args.identify_scenario.empty() ? args.scenarios.front() : args.identify_scenario)));
  if (log && log->robot != torque_model.robot.name)
    throw imscal::InputError(source, 0, "robot",
                             fmt::format("the joint errors are of robot '{}', the scenarios' "
                                         "nominal robot is '{}'",
                                         log->robot, torque_model.robot.name));
  std::optional<ident::IdentificationConfig> config;
  if (log) {
    const std::string config_file =
        args.ident_config.empty()
            ? (imscal::sim::resolve_scenario("identification").parent_path().parent_path() /
               "identification/ident-default.yaml")
                  .string()
            : args.ident_config;
    config = ident::load_identification_config(imscal::ConfigNode::load_file(config_file));
    // The log's payload against the rating its payload cells are fractions of.
    imscal::check_payload_series(
        log->payload_kg, log->time_s, config->nominal_payload_kg,
        {source, 0, "payload_kg",
         fmt::format("robot {} ({}: joints.nominal_payload_kg)", log->robot, config_file)});
  }
  if (args.search_order) {
    if (!config || !config->options.transmission_error_input)
      throw imscal::InputError(args.ident_config, 0, "--search-transmission-error-order",
                               "needs joint errors and a config with the transmission error");
    search_orders(*log, torque_model, *config);
  }
  if (!args.table.empty()) {
    tables.push_back({"compensated", ident::read_parameters_json(args.table)});
  } else {
    spdlog::info("verify: identifying the table from {}", source);
    const eval::IdentifiedTable t = eval::identify_table(*log, *config, source, &torque_model);
    for (const auto& f : t.failed_joints) spdlog::warn("verify: not identified: {}", f);
    identified = t.table;
    tables.push_back({"compensated", t.table});
  }
  if (log && args.ablation) {
    for (const auto& [label, cfg] : eval::ablation_configs(*config)) {
      spdlog::info("verify: ablation table '{}'", label);
      const eval::IdentifiedTable t = eval::identify_table(*log, cfg, source, &torque_model);
      for (const auto& f : t.failed_joints)
        spdlog::warn("verify: {}: not identified: {}", label, f);
      tables.push_back({label, t.table});
    }
  }
  eval::VerificationOptions options;
  options.cycles = args.cycles;
  options.seed = args.seed;
  options.segment_filter = args.segments;
  options.compensation.look_ahead_cycles = args.look_ahead;
  options.measure_with_ims = args.measure_with_ims;
  options.compensation.inversion_iterations = args.inversion_iterations;
  if (args.offset_tolerance_rad > 0.0)
    options.compensation.precontrol.offset_tolerance_rad.fill(args.offset_tolerance_rad);
  OutputFiles files;
  for (const auto& name : args.scenarios) {
    const imscal::sim::Scenario scenario =
        imscal::sim::load_scenario(imscal::sim::resolve_scenario(name));
    spdlog::info("verify: {} ({} cycles x {} runs)", scenario.name, args.cycles, tables.size() + 1);
    eval::VerificationResult r;
    try {
      r = eval::verify_scenario(scenario, tables, options);
    } catch (const std::invalid_argument& e) {
      throw imscal::InputError(scenario.file.string(), 0, "", e.what());
    }
    write_scenario(scenario.name, r, args, files);
  }
  publish(out, files, args.identify_scenario.empty() ? nullptr : &*log,
          identified ? &*identified : nullptr, overwrite);
  for (const auto& name : args.scenarios)
    plot_figures(out / imscal::sim::load_scenario(imscal::sim::resolve_scenario(name)).name);
}

imscal::tools::CommandRegistration registration{
    "verify",
    "Closed-loop verification in the simulator: ISO 9283 before/after, ablation, Fig. 5/6",
    [](CLI::App& sub) {
      auto args = std::make_shared<VerifyArgs>();
      sub.add_option("--table", args->table, "parameters.json (imscal identify)");
      sub.add_option("--joint-errors", args->joint_errors,
                     "joint_errors.csv for the table and the ablation (instead of --table)");
      sub.add_option("--identify-scenario", args->identify_scenario,
                     "identify from this scenario's simulator truth (e.g. identification)");
      sub.add_option("--ident-config", args->ident_config,
                     "identification config (default datasets/identification/ident-default.yaml)");
      sub.add_option("--scenario", args->scenarios, "scenario name or file (repeatable)")
          ->required();
      sub.add_option("--segments", args->segments,
                     "evaluate the Cartesian segments whose label contains this (default all)");
      sub.add_option("--cycles", args->cycles, "cycles per case (ISO 9283: 10)");
      sub.add_option("--seed", args->seed, "seed of the per-cycle friction draws");
      sub.add_option("--look-ahead", args->look_ahead,
                     "cycles of look-ahead of the precontrol's input");
      sub.add_option("--inversion-iterations", args->inversion_iterations,
                     "cascade stages inverting the loop (eval/closed_loop.hpp; 0: offset added "
                     "once)");
      sub.add_option("--offset-tolerance-rad", args->offset_tolerance_rad,
                     "supervisor tolerance on |offset| per joint [rad] (default: 1.5 x the table's "
                     "envelope of the identification data)");
      sub.add_flag("!--no-ablation", args->ablation, "skip the ablation tables");
      sub.add_flag("--search-transmission-error-order", args->search_order,
                   "find each joint's transmission-error harmonic per motor revolution (0.5 .. "
                   "4) from the joint errors' held-out fit instead of the config's");
      sub.add_flag("!--true-path", args->measure_with_ims,
                   "evaluate the plant's true link-side path instead of the IMS chain's "
                   "measurement (faster; the IMS chain is the default)");
      sub.add_option("--out", args->out, "output folder")->required();
      sub.add_flag("--force", args->force, "Overwrite existing outputs");
      sub.callback([args] { run(*args); });
    }};
}  // namespace
