// `imscal diagnose`: the sim-to-real gap diagnosis. "real": a joint_errors.csv (the
// joint errors measured through the IMS chain); "sim": the identified error model
// (parameters.json, run on the desired joints) or a second joint_errors.csv (e.g. the simulator
// with a given set of effects, same time stamps). Writes report.json and report.txt, with
// --figures also SVG figures drawn by gnuplot (gap spectrum, gap by joint and phase, the
// model-error model's frequency response with its confidence band), all or nothing
// (core/output_folder.hpp).
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <iostream>
#include <memory>

#include "calib/robot_description.hpp"
#include "core/atomic_file.hpp"
#include "core/input_error.hpp"
#include "core/json_output.hpp"
#include "core/output_folder.hpp"
#include "core/payload_plausibility.hpp"
#include "eval/gap_analysis.hpp"
#include "eval/gap_report.hpp"
#include "eval/gap_windows.hpp"
#include "ident/joint_error_io.hpp"
#include "ident/parameter_table_io.hpp"
#include "tools/command_registry.hpp"
#include "tools/report_gnuplot.hpp"

namespace {
namespace fs = std::filesystem;
namespace eval = imscal::eval;
namespace ident = imscal::ident;

struct DiagnoseArgs {
  std::string joint_errors, table, sim_joint_errors, robot, out;
  bool force = false;
  bool figures = false;
  double gnuplot_timeout_s = 30.0;
  double max_analysed_s = eval::AnalysisWindows{}.max_s;
};

constexpr const char* kSvgProlog = "<?xml version=\"1.0\" encoding=\"utf-8\" standalone=\"no\"?>\n";
constexpr const char* kColors[] = {"#1f5fbf", "#d0402b", "#2a9d3a",
                                   "#8e44ad", "#e08a00", "#17a2b8"};

// Welch spectrum of every joint's gap, log-log [rad²/Hz].
std::string spectrum_figure(imscal::tools::GnuplotRenderer& gnuplot, const eval::GapSignals& s) {
  std::string plot;
  for (std::size_t j = 0; j < s.joint_count(); ++j) {
    std::size_t longest = 0;
    for (const auto& [b, e] : s.runs) longest = std::max(longest, e - b);
    std::size_t window = 512;
    while (window > 16 && window > longest) window /= 2;
    const eval::Spectrum sp = eval::welch_spectrum(s.gap_rad[j], s.runs, s.cycle_s, window);
    std::string data;
    for (std::size_t i = 1; i < sp.frequency_hz.size(); ++i)  // without DC (log axis)
      data += fmt::format("{:.6g} {:.6g}\n", sp.frequency_hz[i], std::max(sp.density[i], 1e-30));
    const std::string file = gnuplot.data_file(fmt::format("psd-{}.dat", j), data);
    plot += fmt::format("{}{} using 1:2 with lines lw 1.3 lc rgb '{}' title '{}' noenhanced",
                        j == 0 ? "plot " : ", ", file, kColors[j % 6], s.joint_names[j]);
  }
  const std::string script =
      "set grid\nset logscale xy\nset format y '%.0e'\nset xlabel 'f [Hz]'\n"
      "set ylabel 'PSD of the gap [rad²/Hz]'\nset key outside right\n" +
      plot + "\n";
  return gnuplot.render("gap-spectrum", "Spectrum of the sim-to-real gap per joint", script, 900,
                        450);
}

// Share of the gap energy by joint, split by motion phase (stacked bars).
std::string where_figure(imscal::tools::GnuplotRenderer& gnuplot, const eval::Diagnosis& d) {
  std::string data = "joint";
  for (int p = 0; p < eval::kMotionPhaseCount; ++p)
    data += std::string(" ") + eval::to_string(eval::MotionPhase(p));
  data += "\n";
  for (const auto& j : d.where.joints) {
    data += j.joint;
    for (const auto& ph : j.by_phase)
      data += fmt::format(" {:.6g}", 100.0 * j.energy_share * ph.energy_share);
    data += "\n";
  }
  const std::string file = gnuplot.data_file("where.dat", data);
  std::string plot = "plot ";
  for (int p = 0; p < eval::kMotionPhaseCount; ++p)
    plot += fmt::format("{}{} using {}:xtic(1) title columnheader({}) lc rgb '{}'",
                        p == 0 ? "" : ", ", file, p + 2, p + 2, kColors[p]);
  const std::string script =
      "set style data histograms\nset style histogram rowstacked\nset style fill solid 0.8 "
      "border -1\nset boxwidth 0.7\nset grid y\nset ylabel 'share of the gap energy [%]'\n"
      "set key outside right noenhanced\nset yrange [0:*]\n" +
      plot + "\n";
  return gnuplot.render("gap-where", "Where the gap lies: by joint and motion phase", script, 900,
                        450);
}

// |G| of the model-error model per joint with its confidence band.
std::string model_error_figure(imscal::tools::GnuplotRenderer& gnuplot, const eval::GapSignals& s,
                               const eval::Diagnosis& d) {
  std::string script =
      "set multiplot layout 2,3 title 'Model-error model: gap from q_d, |G| with its 2-sigma band' "
      "noenhanced\nset grid\nset logscale x\nset xlabel 'f [Hz]'\nset ylabel '|G| [rad/rad]'\n"
      "set style fill transparent solid 0.3 noborder\nunset key\n";
  for (std::size_t j = 0; j < d.model_error.size(); ++j) {
    std::string data;
    for (const auto& p : d.model_error[j].response)
      data += fmt::format("{:.6g} {:.6g} {:.6g} {:.6g}\n", p.frequency_hz, p.magnitude, p.lower,
                          p.upper);
    if (data.empty()) continue;
    const std::string file = gnuplot.data_file(fmt::format("mem-{}.dat", j), data);
    script += fmt::format(
        "set title '{} (held-out explained {:.0f} %)' noenhanced\n"
        "plot {} using 1:3:4 with filledcurves lc rgb '{}', {} using 1:2 with linespoints pt 7 "
        "ps 0.4 lw 1.3 lc rgb '{}'\n",
        s.joint_names[j], d.model_error[j].heldout_explained_percent, file, kColors[j % 6], file,
        kColors[j % 6]);
  }
  script += "unset multiplot\n";
  return gnuplot.render("gap-model-error", "Model-error model frequency response", script, 1100,
                        650);
}

// A record longer than max_s [s]: its analysed windows only (eval/gap_windows.hpp), in both the
// real joint errors and the sim's.
void keep_analysed_windows(double max_s, ident::JointErrorLog& real,
                           std::vector<std::vector<double>>& sim_errors) {
  eval::AnalysisWindows windows;
  windows.max_s = max_s;
  const std::vector<bool> keep = eval::analysed_samples(real.time_s, windows);
  const auto kept = std::size_t(std::count(keep.begin(), keep.end(), true));
  if (kept == keep.size()) return;
  std::size_t windows_count = 0;
  for (std::size_t k = 0; k < keep.size(); ++k)
    windows_count += keep[k] && (k == 0 || !keep[k - 1]);
  spdlog::info(
      "diagnose: a {:.0f} s record: analysed on {} windows spread over it, {} of {} "
      "samples (--max-analysed-s {})",
      real.time_s.back() - real.time_s.front(), windows_count, kept, keep.size(), max_s);
  real = eval::keep_samples(real, keep);
  sim_errors = eval::keep_samples(sim_errors, keep);
}

void run(const DiagnoseArgs& args) {
  const auto overwrite = args.force ? imscal::Overwrite::kAllow : imscal::Overwrite::kRefuse;
  std::vector<fs::path> outputs = {"report.json", "report.txt"};
  if (args.figures)
    for (const char* f : {"gap-spectrum.svg", "gap-where.svg", "gap-model-error.svg"})
      outputs.push_back(f);
  imscal::OutputFolder folder(args.out, outputs, overwrite);
  ident::JointErrorLog real = ident::read_joint_errors_csv(args.joint_errors);
  const imscal::calib::RobotDescription robot = imscal::calib::load_robot_description(args.robot);
  if (robot.name != real.robot)
    throw imscal::InputError(args.joint_errors, 2, "robot",
                             fmt::format("'{}', but the robot file {} describes '{}'", real.robot,
                                         args.robot, robot.name));
  imscal::check_payload_series(
      real.payload_kg, real.time_s, robot.nominal_payload_kg,
      {args.joint_errors, 0, "payload_kg", fmt::format("robot {} ({})", robot.name, robot.source)});
  std::vector<std::vector<double>> sim_errors;
  std::optional<ident::ParameterTable> table;
  if (!args.table.empty()) {
    table = ident::read_parameters_json(args.table);
    if (table->sample_time_s != real.cycle_s)
      throw imscal::InputError(args.table, 0, "sample_time_s",
                               fmt::format("{} s, but {} has cycle_s {} s", table->sample_time_s,
                                           args.joint_errors, real.cycle_s));
    try {
      sim_errors = eval::predict_table_joint_errors(*table, real);
    } catch (const std::invalid_argument& e) {
      throw imscal::InputError(args.table, 0, "joints", e.what());
    }
  } else {
    const ident::JointErrorLog sim = ident::read_joint_errors_csv(args.sim_joint_errors);
    if (sim.joint_names != real.joint_names || sim.sample_count() != real.sample_count())
      throw imscal::InputError(args.sim_joint_errors, sim.first_data_line, "",
                               fmt::format("{} samples of joints {}; the real joint errors have {} "
                                           "samples of joints {} (they must match row by row)",
                                           sim.sample_count(), fmt::join(sim.joint_names, ","),
                                           real.sample_count(), fmt::join(real.joint_names, ",")));
    for (std::size_t k = 0; k < sim.sample_count(); ++k)
      if (std::abs(sim.time_s[k] - real.time_s[k]) > 0.25 * real.cycle_s)
        throw imscal::InputError(args.sim_joint_errors, sim.first_data_line + k, "t_s",
                                 fmt::format("{} s where the real joint errors have {} s",
                                             sim.time_s[k], real.time_s[k]));
    sim_errors = eval::measured_joint_errors(sim);
  }
  keep_analysed_windows(args.max_analysed_s, real, sim_errors);
  eval::GapSignals signals;
  try {
    signals = eval::make_gap_signals(real, sim_errors, robot, table ? &*table : nullptr);
  } catch (const std::invalid_argument& e) {
    throw imscal::InputError(args.robot, 0, "joints", e.what());
  }
  spdlog::info("diagnose: {} samples, {} joints, gap RMS to be analysed", signals.sample_count(),
               signals.joint_count());
  const eval::Diagnosis d = eval::diagnose_gap(signals);
  const std::string text = eval::diagnosis_text(signals, d);
  imscal::write_file_atomically(
      folder.staged("report.json"),
      imscal::json_text(eval::diagnosis_json(signals, d), 1, "diagnosis.json"),
      imscal::Overwrite::kAllow);
  imscal::write_file_atomically(folder.staged("report.txt"), text, imscal::Overwrite::kAllow);
  if (args.figures) {
    imscal::tools::GnuplotRenderer gnuplot(args.gnuplot_timeout_s);
    imscal::write_file_atomically(folder.staged("gap-spectrum.svg"),
                                  kSvgProlog + spectrum_figure(gnuplot, signals) + "\n",
                                  imscal::Overwrite::kAllow);
    imscal::write_file_atomically(folder.staged("gap-where.svg"),
                                  kSvgProlog + where_figure(gnuplot, d) + "\n",
                                  imscal::Overwrite::kAllow);
    imscal::write_file_atomically(folder.staged("gap-model-error.svg"),
                                  kSvgProlog + model_error_figure(gnuplot, signals, d) + "\n",
                                  imscal::Overwrite::kAllow);
  }
  folder.commit();
  std::cout << d.verdict << "\n";
  for (const auto& m : d.measure_next) std::cout << "  measure next: " << m << "\n";
  spdlog::info("wrote {}/report.json and report.txt", args.out);
}

imscal::tools::CommandRegistration registration{
    "diagnose",
    "Diagnose the sim-to-real gap: where it lies, which unmodelled effect causes it, how far it "
    "shrinks once modelled",
    [](CLI::App& sub) {
      auto args = std::make_shared<DiagnoseArgs>();
      sub.add_option("--joint-errors", args->joint_errors, "measured joint_errors.csv (real)")
          ->required();
      auto* table =
          sub.add_option("--table", args->table, "parameters.json (sim = identified model)");
      auto* sim = sub.add_option("--sim-joint-errors", args->sim_joint_errors,
                                 "joint_errors.csv of the sim (same time stamps)");
      table->excludes(sim);
      sim->excludes(table);
      sub.add_option("--robot", args->robot,
                     "robot description (datasets/robots/*.yaml or a .urdf)")
          ->required();
      sub.add_option("--out", args->out, "output folder (report.json, report.txt)")->required();
      sub.add_flag("--force", args->force, "overwrite existing outputs");
      sub.add_flag("--figures", args->figures,
                   "also write SVG figures (gnuplot): gap-spectrum.svg, gap-where.svg, "
                   "gap-model-error.svg");
      sub.add_option("--max-analysed-s", args->max_analysed_s,
                     "a longer record is analysed on windows of 30 s spread over it, this long "
                     "in all [s]; 0: the whole record")
          ->check(CLI::NonNegativeNumber);
      sub.add_option("--gnuplot-timeout", args->gnuplot_timeout_s,
                     "time limit of gnuplot per figure [s]")
          ->check(CLI::PositiveNumber);
      sub.callback([args] {
        if (args->table.empty() && args->sim_joint_errors.empty())
          throw CLI::RequiredError("--table or --sim-joint-errors");
        run(*args);
      });
    }};
}  // namespace
