// `imscal diagnose`: the sim-to-real gap diagnosis (issue 7). "real": a joint_errors.csv (the
// joint errors measured through the IMS chain); "sim": the identified error model
// (parameters.json, run on the desired joints) or a second joint_errors.csv (e.g. the simulator
// with a given set of effects, same time stamps). Writes report.json and report.txt, all or
// nothing (core/output_folder.hpp).
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <iostream>
#include <memory>

#include "calib/robot_description.hpp"
#include "core/atomic_file.hpp"
#include "core/input_error.hpp"
#include "core/output_folder.hpp"
#include "eval/gap_report.hpp"
#include "ident/joint_error_io.hpp"
#include "ident/parameter_table_io.hpp"
#include "tools/command_registry.hpp"

namespace {
namespace fs = std::filesystem;
namespace eval = imscal::eval;
namespace ident = imscal::ident;

struct DiagnoseArgs {
  std::string joint_errors, table, sim_joint_errors, robot, out;
  bool force = false;
};

void run(const DiagnoseArgs& args) {
  const auto overwrite = args.force ? imscal::Overwrite::kAllow : imscal::Overwrite::kRefuse;
  imscal::OutputFolder folder(args.out, {"report.json", "report.txt"}, overwrite);
  const ident::JointErrorLog real = ident::read_joint_errors_csv(args.joint_errors);
  const imscal::calib::RobotDescription robot = imscal::calib::load_robot_description(args.robot);
  if (robot.name != real.robot)
    throw imscal::InputError(args.joint_errors, 2, "robot",
                             fmt::format("'{}', but the robot file {} describes '{}'", real.robot,
                                         args.robot, robot.name));
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
  imscal::write_file_atomically(folder.staged("report.json"),
                                eval::diagnosis_json(signals, d).dump(1) + "\n",
                                imscal::Overwrite::kAllow);
  imscal::write_file_atomically(folder.staged("report.txt"), text, imscal::Overwrite::kAllow);
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
      sub.add_option("--robot", args->robot, "robot description (datasets/robots/*.yaml)")
          ->required();
      sub.add_option("--out", args->out, "output folder (report.json, report.txt)")->required();
      sub.add_flag("--force", args->force, "overwrite existing outputs");
      sub.callback([args] {
        if (args->table.empty() && args->sim_joint_errors.empty())
          throw CLI::RequiredError("--table or --sim-joint-errors");
        run(*args);
      });
    }};
}  // namespace
