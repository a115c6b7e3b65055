// `imscal diagnose`: the sim-to-real gap diagnosis (eval/gap_session.hpp). "real": a
// joint_errors.csv (the joint errors measured through the IMS chain); "sim": the identified error
// model (parameters.json, run on the desired joints) or a second joint_errors.csv (e.g. the
// simulator with a given set of effects, same time stamps). Writes report.json and report.txt,
// with --figures also SVG figures drawn by gnuplot (tools/diagnose_figures.hpp), all or nothing
// (core/output_folder.hpp).
#include <spdlog/spdlog.h>

#include <array>
#include <iostream>
#include <memory>

#include "core/atomic_file.hpp"
#include "core/json_output.hpp"
#include "core/output_folder.hpp"
#include "core/parallel_tasks.hpp"
#include "eval/gap_report.hpp"
#include "eval/gap_session.hpp"
#include "tools/command_registry.hpp"
#include "tools/diagnose_figures.hpp"

namespace {
namespace fs = std::filesystem;
namespace eval = imscal::eval;
namespace tools = imscal::tools;

struct DiagnoseArgs {
  eval::GapSessionOptions session;
  std::string out;
  bool force = false;
  bool figures = false;
  double gnuplot_timeout_s = 30.0;
};

constexpr const char* kSvgProlog = "<?xml version=\"1.0\" encoding=\"utf-8\" standalone=\"no\"?>\n";

// A figure of the diagnosis: its file and how gnuplot draws it.
struct FigureSpec {
  const char* file;
  std::string (*draw)(tools::GnuplotRenderer& gnuplot, const eval::GapSession& s);
};
constexpr std::array<FigureSpec, 3> kFigures = {{
    {"gap-spectrum.svg",
     [](tools::GnuplotRenderer& g, const eval::GapSession& s) {
       return tools::spectrum_figure(g, s.signals);
     }},
    {"gap-where.svg",
     [](tools::GnuplotRenderer& g, const eval::GapSession& s) {
       return tools::where_figure(g, s.diagnosis);
     }},
    {"gap-model-error.svg",
     [](tools::GnuplotRenderer& g, const eval::GapSession& s) {
       return tools::model_error_figure(g, s.signals, s.diagnosis);
     }},
}};

// The figures are drawn side by side, each by its own gnuplot (its own temporary folder):
// gnuplot runs ~0.05-0.1 s a figure, after the diagnosis, with the cores otherwise idle.
void write_figures(const imscal::OutputFolder& folder, const eval::GapSession& s,
                   double timeout_s) {
  std::array<std::string, kFigures.size()> svg;
  imscal::run_parallel_tasks(
      kFigures.size(),
      [&](std::size_t i) {
        tools::GnuplotRenderer gnuplot(timeout_s);
        svg[i] = kFigures[i].draw(gnuplot, s);
      },
      unsigned(kFigures.size()));
  for (std::size_t i = 0; i < kFigures.size(); ++i)
    imscal::write_file_atomically(folder.staged(kFigures[i].file), kSvgProlog + svg[i] + "\n",
                                  imscal::Overwrite::kAllow);
}

void run(const DiagnoseArgs& args) {
  const auto overwrite = args.force ? imscal::Overwrite::kAllow : imscal::Overwrite::kRefuse;
  std::vector<fs::path> outputs = {"report.json", "report.txt"};
  if (args.figures)
    for (const FigureSpec& figure : kFigures) outputs.push_back(figure.file);
  imscal::OutputFolder folder(args.out, outputs, overwrite);
  const eval::GapSession s = eval::diagnose_gap_session(args.session);
  const eval::Diagnosis& d = s.diagnosis;
  imscal::write_file_atomically(
      folder.staged("report.json"),
      imscal::json_text(eval::diagnosis_json(s.signals, d), 1, "diagnosis.json"),
      imscal::Overwrite::kAllow);
  imscal::write_file_atomically(folder.staged("report.txt"), eval::diagnosis_text(s.signals, d),
                                imscal::Overwrite::kAllow);
  if (args.figures) write_figures(folder, s, args.gnuplot_timeout_s);
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
      sub.add_option("--joint-errors", args->session.joint_errors,
                     "measured joint_errors.csv (real)")
          ->required();
      auto* table = sub.add_option("--table", args->session.table,
                                   "parameters.json (sim = identified model)");
      auto* sim = sub.add_option("--sim-joint-errors", args->session.sim_joint_errors,
                                 "joint_errors.csv of the sim (same time stamps)");
      table->excludes(sim);
      sim->excludes(table);
      sub.add_option("--robot", args->session.robot,
                     "robot description (datasets/robots/*.yaml or a .urdf)")
          ->required();
      sub.add_option("--frames", args->session.frames,
                     "frames.json of the calibration that measured the real joint errors: the "
                     "frames' covariance joins the IMS noise floor (joint_errors.csv's "
                     "q_measured_sigma_rms_rad) in the test of whether the gap is within what "
                     "the measurement explains");
      sub.add_option("--scenario", args->session.scenario,
                     "scenario (name or file) whose nominal model made --sim-joint-errors "
                     "(model-joint-errors --scenario): the joint model is refined by "
                     "re-simulating it (its nominal robot only, never its plant)")
          ->excludes(table);
      sub.add_option("--out", args->out, "output folder (report.json, report.txt)")->required();
      sub.add_flag("--force", args->force, "overwrite existing outputs");
      sub.add_flag("--figures", args->figures,
                   "also write SVG figures (gnuplot): gap-spectrum.svg, gap-where.svg, "
                   "gap-model-error.svg");
      sub.add_option("--max-analysed-s", args->session.max_analysed_s,
                     "a longer record is analysed on windows of 30 s spread over it, this long "
                     "in all [s]; 0: the whole record")
          ->check(CLI::NonNegativeNumber);
      sub.add_option("--gnuplot-timeout", args->gnuplot_timeout_s,
                     "time limit of gnuplot per figure [s]")
          ->check(CLI::PositiveNumber);
      sub.callback([args] {
        if (args->session.table.empty() && args->session.sim_joint_errors.empty())
          throw CLI::RequiredError("--table or --sim-joint-errors");
        run(*args);
      });
    }};
}  // namespace
