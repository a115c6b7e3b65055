// The verification and identification figures, measured against the simulator's truth: the ARX
// tables identified on the `identification` scenario (joint errors q_d - q_link from the plant, a
// stand-in for the IMS chain), verified on `seed-line` (the paper's line; backlash on A2, A3 and
// A5) and on the 100 % velocity paths of `iso9283`, which were not used for identification. Prints
// the before/after ISO 9283 table, the ablation (backlash term off, one cell instead of the grid)
// and the held-out simulation fit per joint with the chosen orders and dead times.
//
// Release: ~identification 130 s of plant + 3 identifications + 10 cycles x 4 runs of seed-line
// + 10 x 2 runs of the iso9283 100 % part (~55 s). Under IMSCAL_SANITIZED: the first 60 s of the
// identification program and 2 cycles (the figures are then only printed, the goals not
// asserted: too little identification data).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>

#include "eval/path_deviation.hpp"
#include "eval/verification.hpp"
#include "ident/identification_config.hpp"
#include "robot/forward_kinematics.hpp"
#include "sim/motion_planner.hpp"
#include "sim/motion_program.hpp"
#include "tests/support/record_figure.hpp"

namespace imscal::eval {
namespace {

namespace fs = std::filesystem;
using test_support::record_figure;

bool sanitized() {
  return std::getenv("IMSCAL_SANITIZED") != nullptr;
}
// Goals not met are asserted only with IMSCAL_VERIFY_GOALS set (printed figures and the report
// say why); the always-on assertions check the measurement itself, and the goals, which
// are met (>= 95 % on seed-line, >= 90 % on the ISO 9283 set), are
// asserted always in Release.
bool assert_goals() {
  return std::getenv("IMSCAL_VERIFY_GOALS") != nullptr;
}

sim::Scenario scenario(const std::string& name) {
  return sim::load_scenario(fs::path(IMSCAL_SOURCE_DIR) / "datasets/scenarios" / (name + ".yaml"));
}

// The identification run and its config, made once per process.
struct IdentificationData {
  ident::JointErrorLog log;
  ident::IdentificationConfig config;
  ModelTorqueSource torque_model;
};

const IdentificationData& identification_data() {
  static const IdentificationData d = [] {
    const sim::Scenario identification = scenario("identification");
    const char* config_file = std::getenv("IMSCAL_VERIFY_CONFIG");
    return IdentificationData{simulate_truth_joint_errors(identification, sanitized() ? 60.0 : 1e9),
                              ident::load_identification_config(ConfigNode::load_file(
                                  config_file ? fs::path(config_file)
                                              : fs::path(IMSCAL_SOURCE_DIR) /
                                                    "datasets/identification/ident-default.yaml")),
                              scenario_model_torque(identification)};
  }();
  return d;
}

// The default table, and the ablation's (eval::ablation_configs) only where a test needs them
// (each is an identification of its own: ~25 s under the sanitizers).
const IdentifiedTable& full_table() {
  static const IdentifiedTable t = [] {
    const IdentificationData& d = identification_data();
    IdentifiedTable table = identify_table(d.log, d.config, "simulator truth", &d.torque_model);
    for (const auto& failed : table.failed_joints)
      std::printf("not identified: %s\n", failed.c_str());
    return table;
  }();
  return t;
}

const std::vector<std::pair<std::string, IdentifiedTable>>& ablation_tables() {
  static const std::vector<std::pair<std::string, IdentifiedTable>> tables = [] {
    const IdentificationData& d = identification_data();
    std::vector<std::pair<std::string, IdentifiedTable>> out;
    for (const auto& a : ablation_configs(d.config)) {
      out.emplace_back(a.label,
                       identify_table(d.log, a.config, "simulator truth", &d.torque_model));
      for (const auto& failed : out.back().second.failed_joints)
        std::printf("%s: not identified: %s\n", a.label.c_str(), failed.c_str());
    }
    return out;
  }();
  return tables;
}

int look_ahead() {
  const char* v = std::getenv("IMSCAL_VERIFY_LOOK_AHEAD");
  return v ? std::atoi(v) : VerificationOptions{}.compensation.look_ahead_cycles;
}
int inversion_iterations() {
  const char* v = std::getenv("IMSCAL_VERIFY_ITERATIONS");
  return v ? std::atoi(v) : VerificationOptions{}.compensation.inversion_iterations;
}

void print_case(const VerificationCase& c, const PathFigures& before,
                const PathFigures& before_true) {
  const PathFigures& f = c.figures;
  constexpr double mm = 1e3, deg = 180.0 / M_PI;
  std::printf(
      "  %-16s max dev %7.3f mm (%6.1f %%)  AT_p %7.3f  RT_p %6.3f mm  AT_abc %.4f %.4f %.4f "
      "RT_abc %.4f %.4f %.4f deg  CO %6.3f mm  AV %+6.2f %%  RV %5.2f %%  FV %6.4f m/s  "
      "(inactive cycles %zu, events %zu)\n"
      "  %-16s   scatter floor %6.3f mm (best reachable %5.1f %%), systematic %6.3f mm, about the "
      "mean %6.3f mm (exact on average: %5.1f %%)\n"
      "  %-16s   true path: max dev %7.3f mm (%6.1f %%)  AT_p %7.3f  RT_p %6.3f mm  scatter floor "
      "%6.3f mm (best reachable %5.1f %%), systematic %6.3f mm, about the mean %6.3f mm (exact on "
      "average: %5.1f %%)\n",
      c.label.c_str(), f.max_path_deviation_m * mm,
      reduction_percent(before.max_path_deviation_m, f.max_path_deviation_m), f.AT_p_m * mm,
      f.RT_p_m * mm, f.AT_abc_rad[0] * deg, f.AT_abc_rad[1] * deg, f.AT_abc_rad[2] * deg,
      f.RT_abc_rad[0] * deg, f.RT_abc_rad[1] * deg, f.RT_abc_rad[2] * deg, f.CO_m * mm,
      f.AV_percent, f.RV_percent, f.FV_m_s, c.inactive_cycles, c.events.size(), "",
      f.scatter_floor_m * mm, reduction_percent(before.max_path_deviation_m, f.scatter_floor_m),
      f.systematic_max_m * mm, f.about_mean_max_m * mm,
      reduction_percent(before.max_path_deviation_m, f.about_mean_max_m), "",
      c.true_figures.max_path_deviation_m * mm,
      reduction_percent(before_true.max_path_deviation_m, c.true_figures.max_path_deviation_m),
      c.true_figures.AT_p_m * mm, c.true_figures.RT_p_m * mm, c.true_figures.scatter_floor_m * mm,
      reduction_percent(before_true.max_path_deviation_m, c.true_figures.scatter_floor_m),
      c.true_figures.systematic_max_m * mm, c.true_figures.about_mean_max_m * mm,
      reduction_percent(before_true.max_path_deviation_m, c.true_figures.about_mean_max_m));
}

VerificationResult run(const std::string& name, const std::string& filter, bool ablation) {
  VerificationOptions options;
  // ISO 9283's 10 cycles (2 under the sanitizers).
  options.cycles = sanitized() ? 2 : 10;
  if (const char* n = std::getenv("IMSCAL_VERIFY_CYCLES")) options.cycles = std::atoi(n);
  options.segment_filter = filter;
  // Under the sanitizers the attained paths are the plant's own (the IMS chain's measurement of
  // a run has its own test there: tests/eval/test_ims_measured_path.cpp).
  options.measure_with_ims = !sanitized();
  options.compensation.look_ahead_cycles = look_ahead();
  options.compensation.inversion_iterations = inversion_iterations();
  if (const char* v = std::getenv("IMSCAL_VERIFY_OFFSET_TOLERANCE_RAD"))
    options.compensation.precontrol.offset_tolerance_rad.fill(std::atof(v));
  if (const char* v = std::getenv("IMSCAL_VERIFY_RATE_TOLERANCE_RAD_S"))
    options.compensation.precontrol.rate_tolerance_rad_s.fill(std::atof(v));
  if (const char* v = std::getenv("IMSCAL_VERIFY_RATE_LIMIT_RAD_S"))
    options.compensation.precontrol.rate_limit_rad_s.fill(std::atof(v));
  std::vector<NamedTable> named{{"compensated", full_table().table}};
  if (ablation)
    for (const auto& [label, t] : ablation_tables()) named.push_back({label, t.table});
  const VerificationResult r = verify_scenario(scenario(name), named, options);
  std::printf("%s (%d cycles, segments:", name.c_str(), r.cycles);
  for (const auto& s : r.segments) std::printf(" '%s'", s.c_str());
  std::printf(", look-ahead %d cycles, inversion iterations %d)\n",
              options.compensation.look_ahead_cycles, options.compensation.inversion_iterations);
  print_case(r.before, r.before.figures, r.before.true_figures);
  for (const auto& c : r.after) {
    print_case(c, r.before.figures, r.before.true_figures);
    for (std::size_t i = 0; i < c.events.size() && i < 5; ++i) {
      std::printf("    precontrol event: cycle %llu joint %d %s (%g)\n",
                  static_cast<unsigned long long>(c.events[i].cycle), int(c.events[i].joint),
                  ident::to_string(c.events[i].cause), c.events[i].value);
    }
  }
  return r;
}

TEST(Verification, IdentificationFitPerJoint) {
  const IdentifiedTable& full = full_table();
  // Release (the whole identification program): every joint identified. Under sanitizers (60 s
  // of it) A5 can fail (a pole at 0.9995 with that little data); it must then carry the neutral
  // model: one pass-through cell, no backlash (zero correction, checked in
  // tests/ident/test_precontrol.cpp).
  if (!sanitized()) {
    EXPECT_TRUE(full.failed_joints.empty());
  }
  std::vector<const IdentifiedTable*> all{&full};
  for (const auto& a : ablation_tables()) all.push_back(&a.second);
  for (const IdentifiedTable* table : all) {
    for (const auto& failed : table->failed_joints) {
      const std::string name = failed.substr(0, failed.find(':'));
      for (const auto& joint : table->joints) {
        if (joint.parameters.name != name) continue;
        ASSERT_EQ(joint.parameters.cells.size(), 1u) << failed;
        EXPECT_EQ(joint.parameters.cells[0].b, std::vector<double>{1.0}) << failed;
        EXPECT_TRUE(joint.parameters.cells[0].a.empty()) << failed;
        EXPECT_EQ(joint.parameters.backlash_l_rad, 0.0) << failed;
      }
    }
  }
  for (const IdentifiedTable* table : all) {
    for (const auto& joint : table->joints) {
      // Backlash estimates are bounded (ident::BacklashOptions::max_l_rad = 20 mrad): an absurd
      // width (once 7e3 rad on A5/A6) never reaches a table.
      EXPECT_LE(joint.parameters.backlash_l_rad, 0.02) << joint.parameters.name;
      EXPECT_GE(joint.parameters.backlash_l_rad, 0.0) << joint.parameters.name;
      // Every model is at rest where it is told (joint-error form, static gain 1): the error at
      // rest, q (A(1) - B(1)), is below 3 nrad for |q| <= 3 rad (1e-9: rounding of the sums of
      // up to ~37 coefficients).
      for (const auto& cell : joint.parameters.cells) {
        double a1 = 1.0, b1 = 0.0;
        for (double a : cell.a) a1 += a;
        for (double b : cell.b) b1 += b;
        EXPECT_NEAR(a1 - b1, 0.0, 1e-9) << joint.parameters.name;
      }
    }
  }
  for (const auto& joint : full.joints) {
    const JointFitSummary s = summarize_fit(joint);
    std::printf(
        "%s: held-out simulation fit %.3f %%, joint-error fit %.1f %% (%zu rows); "
        "backlash l %.4f mrad (%s)\n",
        joint.parameters.name.c_str(), s.simulation_fit_percent, s.joint_error_fit_percent,
        s.validation_rows, joint.parameters.backlash_l_rad * 1e3,
        joint.parameters.backlash_identified ? "identified" : "none");
    std::printf("    offset envelope of the data: %.2f mrad, %.3f rad/s\n",
                joint.parameters.offset_envelope_rad * 1e3,
                joint.parameters.offset_rate_envelope_rad_s);
    std::printf("    backlash: %s; reversals found %zu used %zu, lag %zu\n",
                joint.backlash.reason.c_str(), std::size_t(joint.backlash.reversals_found),
                std::size_t(joint.backlash.reversals_used),
                std::size_t(joint.backlash.lag_samples));
    for (const auto& c : joint.cells) {
      if (c.status != ident::CellStatus::kIdentified || !c.sweep) continue;
      const auto& f = joint.parameters.cells[std::size_t(c.cell)].figures;
      std::printf(
          "    cell %d %-34s na %2d nb %2d d %d  sim fit %.3f %%  joint error fit %.1f %%\n",
          c.cell, c.label.c_str(), c.sweep->chosen.na, c.sweep->chosen.nb,
          c.sweep->chosen.dead_time, f.simulation_fit_percent, f.joint_error_fit_percent);
    }
    if (assert_goals() && !sanitized() && joint.parameters.name <= "A3") {
      // Goal: simulation NRMSE fit >= 90 % on held-out runs for every primary joint.
      EXPECT_GE(s.simulation_fit_percent, 90.0) << joint.parameters.name;
    }
  }
}

TEST(Verification, SeedLineWithAblation) {
  const VerificationResult r = run("seed-line", "line", true);
  const double before = r.before.figures.max_path_deviation_m;
  // The uncalibrated plant is of the paper's class (tests/sim: 8-20 mm).
  EXPECT_GT(before, 0.008);
  for (const auto& c : r.after) {
    // Every case ran and was measured: finite figures, every calculation point crossed.
    EXPECT_TRUE(std::isfinite(c.figures.max_path_deviation_m)) << c.label;
    EXPECT_EQ(c.figures.missed_crossings, 0) << c.label;
  }
  if (!sanitized()) {
    // What the chain reaches today (Release, 10 cycles, look-ahead 4), as the IMS chain measures
    // the attained path: 12.52 -> 0.604 mm (95.2 %); on the plant's true path 12.47 -> 0.611 mm
    // (95.1 %). Ablation on the true path: paper form 49.0 %, without the model torque 39.3 %,
    // without the transmission-error inputs 94.9 % (94.8 % as measured: the former
    // default), with eq. 3's backlash term 92.5 %, with the operating-point grid 95.2 % (94.8 %
    // as measured). Asserted 3 %-points below (compiler differences; the simulator and every
    // draw are deterministic), the precontrol active throughout, and each part of the default
    // measured: the paper's form and the model without the torque stay far behind. The goal of
    // 95 % itself is asserted below (Release).
    // Where the maximum arises (true path): the cycle whose A2 friction is drawn 13.9 % above
    // nominal, 0.22 s into the line's acceleration from rest (run-to-run friction, which no model
    // of the nominal robot predicts), 0.36 mm off the cycles' mean, which is 0.24 mm off the path
    // there (0.27 mm without the transmission-error inputs). The cycles' own scatter
    // (PathFigures::scatter_floor_m) is 0.47 mm on the true path, 0.51 mm as measured: no
    // precontrol fed the desired path gets below it (best reachable 95.9 % as measured).
    // Split about the cycles' mean: the compensated run's systematic part (the mean's largest
    // deviation, = AT_p) is 0.467 mm as measured, 0.371 mm true (0.538 / 0.513 without the
    // transmission-error inputs: the gear's 10 arcsec periodic error, which the motor encoders
    // do not see, was the largest part of the model's own error); the cycles' largest distance
    // from their mean is 0.583 / 0.571 mm, so a model exact on average would reach 95.3 %.
    EXPECT_EQ(r.after[0].inactive_cycles, 0u);
    EXPECT_GE(reduction_percent(before, r.after[0].figures.max_path_deviation_m), 92.2);
    const double before_true = r.before.true_figures.max_path_deviation_m;
    const double compensated =
        reduction_percent(before_true, r.after[0].true_figures.max_path_deviation_m);
    EXPECT_GE(compensated, 92.1);
    // The transmission-error inputs' share: the systematic part (true path) falls by > 20 %
    // (measured 0.513 -> 0.371 mm, 28 %).
    for (std::size_t c = 1; c < r.after.size(); ++c) {
      if (r.after[c].label == "without transmission error") {
        EXPECT_LT(r.after[0].true_figures.systematic_max_m,
                  0.8 * r.after[c].true_figures.systematic_max_m);
      }
    }
    // The floor lies under the maximum, and is the repeatability's order (RT_p 0.72 mm true).
    EXPECT_LE(r.after[0].figures.scatter_floor_m, r.after[0].figures.max_path_deviation_m);
    EXPECT_GT(r.after[0].true_figures.scatter_floor_m, 0.2 * r.after[0].true_figures.RT_p_m);
    // Split about the cycles' mean (eval::split_cycles): each cycle's deviation is the mean plus
    // its distance from it, so the max lies under their sum; exact on average still leaves at
    // least the floor.
    for (const PathFigures* f : {&r.after[0].figures, &r.after[0].true_figures}) {
      EXPECT_LE(f->max_path_deviation_m, f->systematic_max_m + f->about_mean_max_m + 1e-12);
      EXPECT_GE(f->about_mean_max_m, f->scatter_floor_m);
    }
    for (std::size_t c = 1; c < r.after.size(); ++c) {
      const double reduction =
          reduction_percent(before_true, r.after[c].true_figures.max_path_deviation_m);
      if (r.after[c].label == "paper form" || r.after[c].label == "without model torque")
        EXPECT_LT(reduction, compensated - 30.0) << r.after[c].label;
      else
        EXPECT_GE(reduction, 85.0) << r.after[c].label;
    }
    // The IMS chain measures the path to a fraction of the compensated deviation: the measured
    // and true maximum deviations differ by < 0.15 mm (measured 0.019 mm; 0.23 mm without
    // the rests before and after the line, VerificationOptions::lead_in_s / lead_out_s).
    EXPECT_LT(std::abs(r.after[0].figures.max_path_deviation_m -
                       r.after[0].true_figures.max_path_deviation_m),
              0.15e-3);
    // The repeatability floor: the same table on the plant with its nominal friction (no
    // run-to-run draw, one cycle): what the model leaves, without what no model of the nominal
    // robot can predict (the 10 cycles' friction drawn anew, sigma 5 %: RT_p 0.72 mm). Measured:
    // 12.43 -> 0.511 mm (95.9 %) through the IMS chain, 12.43 -> 0.371 mm (97.0 %) on the true
    // path, against 0.611 mm true over the 10 drawn cycles: the draws cost ~0.24 mm.
    VerificationOptions nominal;
    nominal.cycles = 1;
    nominal.friction_sigma_fraction = 0.0;
    nominal.segment_filter = "line";
    const VerificationResult n =
        verify_scenario(scenario("seed-line"), {{"compensated", full_table().table}}, nominal);
    const double floor_mm = n.after[0].figures.max_path_deviation_m * 1e3;
    std::printf(
        "seed-line, nominal friction, 1 cycle: %.3f -> %.3f mm (%.1f %%); true path %.3f -> %.3f "
        "mm (%.1f %%)\n",
        n.before.figures.max_path_deviation_m * 1e3, floor_mm,
        reduction_percent(n.before.figures.max_path_deviation_m,
                          n.after[0].figures.max_path_deviation_m),
        n.before.true_figures.max_path_deviation_m * 1e3,
        n.after[0].true_figures.max_path_deviation_m * 1e3,
        reduction_percent(n.before.true_figures.max_path_deviation_m,
                          n.after[0].true_figures.max_path_deviation_m));
    EXPECT_LT(n.after[0].figures.max_path_deviation_m, r.after[0].figures.max_path_deviation_m);
  }
  // The goal on seed-line, met with the transmission-error inputs (95.2 %
  // as the IMS chain measures it): asserted whenever the figures are (Release), so that a change
  // that loses it fails here. Over other friction draws (imscal verify --seed 2, 3, 4, true
  // path) 95.2, 95.4, 95.8 % (94.9-95.5 % without those inputs).
  if (!sanitized()) {
    const double full = reduction_percent(before, r.after[0].figures.max_path_deviation_m);
    EXPECT_GE(full, 95.0) << "goal on seed-line";
    record_figure("seed_line_before_mm", before * 1e3);
    record_figure("seed_line_after_mm", r.after[0].figures.max_path_deviation_m * 1e3);
    record_figure("seed_line_reduction_measured_percent", full);
    record_figure("seed_line_reduction_true_percent",
                  reduction_percent(r.before.true_figures.max_path_deviation_m,
                                    r.after[0].true_figures.max_path_deviation_m));
  }
}

TEST(Verification, Iso9283FullVelocity) {
  const VerificationResult r = run("iso9283", "100%", false);
  EXPECT_GT(r.before.figures.max_path_deviation_m, 0.001);
  if (!sanitized()) {
    // What the chain reaches today (Release, 10 cycles): as the IMS chain measures the attained
    // paths 8.19 -> 0.676 mm (91.8 %), on the true paths 8.19 -> 0.676 mm (91.8 %; 91.5 and
    // 91.2 % without the transmission-error inputs, AT_p 0.33 mm; the cycles'
    // scatter floor is 0.45 mm, best reachable 94.5 %), the precontrol
    // active throughout (its default tolerances come from the identification data's envelope).
    // The planner keeps Cartesian moves within the joints' acceleration and jerk limits
    // (sim/cartesian_timing.hpp): the 100 % D 40 mm circle runs at 42 % of its programmed speed.
    // Asserted 3 %-points below.
    EXPECT_EQ(r.after[0].inactive_cycles, 0u);
    EXPECT_GE(reduction_percent(r.before.figures.max_path_deviation_m,
                                r.after[0].figures.max_path_deviation_m),
              88.8);
    EXPECT_GE(reduction_percent(r.before.true_figures.max_path_deviation_m,
                                r.after[0].true_figures.max_path_deviation_m),
              88.8);
  }
  // The goal on this path set, met with the 60 input taps (90.8 % as the
  // IMS chain measures it): asserted whenever the figures are (Release), not only under
  // IMSCAL_VERIFY_GOALS, so that a change that loses it fails here.
  if (!sanitized()) {
    const double full = reduction_percent(r.before.figures.max_path_deviation_m,
                                          r.after[0].figures.max_path_deviation_m);
    EXPECT_GE(full, 90.0) << "goal on the ISO 9283 path set at 100 % velocity";
    record_figure("iso9283_100_reduction_measured_percent", full);
    record_figure("iso9283_100_reduction_true_percent",
                  reduction_percent(r.before.true_figures.max_path_deviation_m,
                                    r.after[0].true_figures.max_path_deviation_m));
  }
}

// The bound of the paper's scheme: the TRUE joint error of the uncompensated run used as the
// offset (a perfect model of eq. 2 + 3). The plant then errs by what the offset itself changes,
// (1 - G) applied twice instead of once: a second-order remainder.
TEST(Verification, TrueJointErrorAsOffsetBound) {
  const sim::Scenario s = scenario("seed-line");
  const calib::RobotDescription robot = sim::load_plant_robot(s);
  const sim::DesiredJointPath path =
      sim::plan_motion(robot, sim::load_motion_program(s.program_file));
  const sim::PlantConfig config = sim::make_plant_config(robot, s);
  const sim::PlantLog before = sim::simulate_plant(config, path, path.cycle_s);
  const sim::PlantLog after =
      sim::simulate_plant(config, command_path(path, joint_errors(path, before)), path.cycle_s);
  auto max_deviation = [&](const sim::PlantLog& log) {
    std::vector<TimedPoint> desired, actual;
    for (std::size_t k = 0; k < path.samples.size(); ++k) {
      bool on_line = false;
      for (const auto& seg : path.segments)
        on_line =
            on_line || (seg.kind == sim::SegmentKind::kLinear &&
                        path.samples[k].t_s >= seg.begin_s && path.samples[k].t_s <= seg.end_s);
      if (!on_line) continue;
      desired.push_back({path.samples[k].t_s,
                         calib::forward_kinematics<double>(robot.kinematics, path.samples[k].q_rad)
                             .translation()});
      actual.push_back({path.samples[k].t_s, calib::forward_kinematics<double>(
                                                 robot.kinematics, log.samples[k].q_link_rad)
                                                 .translation()});
    }
    return path_deviation(desired, actual, 0.25).max_m;
  };
  const double b = max_deviation(before), a = max_deviation(after);
  std::printf(
      "seed-line with the true joint error as offset: max path deviation %.3f -> %.3f mm "
      "(%.1f %%)\n",
      b * 1e3, a * 1e3, reduction_percent(b, a));
  // A perfect model of the error removes most of it (measured ~70 %: the offset itself changes the
  // arm's dynamic error, which a once-added predicted error does not anticipate). Loose bound
  // (half) so that only a broken loop fails it.
  EXPECT_LT(a, 0.5 * b);

  // Look-ahead: the same true error applied L cycles early, o(k) = e(k + L) (held at the end).
  const std::vector<calib::JointVector> e = joint_errors(path, before);
  double best_shift = a;
  // (Skipped under sanitizers, as the inversion below: 7 more plant runs.)
  for (int L : sanitized() ? std::vector<int>{} : std::vector<int>{4, 8}) {
    std::vector<calib::JointVector> shifted(e.size());
    for (std::size_t k = 0; k < e.size(); ++k) shifted[k] = e[std::min(e.size() - 1, k + L)];
    const double d =
        max_deviation(sim::simulate_plant(config, command_path(path, shifted), path.cycle_s));
    best_shift = std::min(best_shift, d);
    std::printf("  true error applied %d cycles early: %.3f mm (%.1f %%)\n", L, d * 1e3,
                reduction_percent(b, d));
  }
  // Inverting the loop with the true plant (the limit of inversion_iterations with a perfect
  // model): o_{i+1} = o_i + (q_d - q(q_d + o_i)), o_0 = 0 (i = 1 is the row above).
  std::vector<calib::JointVector> o(e.size(), calib::JointVector::Zero());
  double inverted = b;
  for (int i = 1; i <= (sanitized() ? 0 : 3); ++i) {
    const sim::PlantLog log = sim::simulate_plant(config, command_path(path, o), path.cycle_s);
    const std::vector<calib::JointVector> r = joint_errors(path, log);
    for (std::size_t k = 0; k < o.size(); ++k) o[k] += r[k];
    inverted = max_deviation(sim::simulate_plant(config, command_path(path, o), path.cycle_s));
    std::printf("  loop inverted with the true plant, %d iteration(s): %.3f mm (%.1f %%)\n", i,
                inverted * 1e3, reduction_percent(b, inverted));
  }
  if (!sanitized()) {
    // Where the inversion stops: remaining joint errors and drive torques at their limits.
    const sim::PlantLog log = sim::simulate_plant(config, command_path(path, o), path.cycle_s);
    const std::vector<calib::JointVector> r = joint_errors(path, log);
    calib::JointVector worst = calib::JointVector::Zero(), worst_before = worst;
    std::array<int, 6> at_limit{}, at_limit_before{};
    for (std::size_t k = 0; k < r.size(); ++k) {
      worst = worst.cwiseMax(r[k].cwiseAbs());
      worst_before = worst_before.cwiseMax(e[k].cwiseAbs());
      for (int j = 0; j < 6; ++j) {
        const double limit = robot.joints[std::size_t(j)].controller.torque_limit_nm;
        at_limit[std::size_t(j)] += std::abs(log.samples[k].tau_drive_nm[j]) >= 0.999 * limit;
        at_limit_before[std::size_t(j)] +=
            std::abs(before.samples[k].tau_drive_nm[j]) >= 0.999 * limit;
      }
    }
    for (int j = 0; j < 6; ++j)
      std::printf(
          "    A%d: max |joint error| %.4f -> %.4f mrad; cycles at the torque limit %d -> %d\n",
          j + 1, worst_before[j] * 1e3, worst[j] * 1e3, at_limit_before[std::size_t(j)],
          at_limit[std::size_t(j)]);
  }
  // Measured (Release): L = 8 gives 3.48 mm against 3.99 mm at L = 0 (L = 4: 3.74 mm), so an early
  // offset helps a little; the deterministic simulator makes this a strict comparison.
  if (!sanitized()) {
    EXPECT_LT(best_shift, a);
  }
  // The inversion with the TRUE plant does not converge (3.99 -> 3.84 -> 3.97 mm): the residual
  // is not the loop's response to the offset but vibration the offset cannot reach through the
  // motor-side loop (A1's remaining joint error grows from 10 to 23 mrad over the iterations,
  // see the printout). This is the limit of any joint-offset precontrol on this plant, shown
  // here so that a change of plant or loop that lifts it is noticed: asserted as the L = 0 bound.
  if (!sanitized()) {
    EXPECT_LT(inverted, 0.5 * b);
  }
}

}  // namespace
}  // namespace imscal::eval

namespace imscal::eval {
namespace {

// Identification and verification the way the paper works: the identification runs MEASURED by the
// IMS chain (the simulated navigation-grade IMS, mechanized, smoothed, through the frames and the
// inverse kinematics; eval/ims_measured_path.hpp), not the simulator's truth; the default table
// identified from them; the held-out fits and the verification on seed-line.
TEST(Verification, IdentifiedFromTheImsChain) {
  if (sanitized()) GTEST_SKIP() << "3 min of plant and IMS: Release only";
  const sim::Scenario identification = scenario("identification");
  const ident::JointErrorLog measured = simulate_ims_joint_errors(identification, 1);
  const ident::JointErrorLog truth = simulate_truth_joint_errors(identification);
  // The measurement's own error on the joint errors (the same plant run: deterministic), and
  // the measured log with the true link angles in place of the IMS's (same rows and runs).
  std::size_t k_truth = 0;
  calib::JointVector sq_error = calib::JointVector::Zero(), sq_signal = sq_error;
  ident::JointErrorLog truth_on_measured_rows = measured;
  for (std::size_t k = 0; k < measured.sample_count(); ++k) {
    while (truth.time_s[k_truth] < measured.time_s[k] - 1e-9) ++k_truth;
    for (int j = 0; j < 6; ++j) {
      truth_on_measured_rows.q_measured_rad[std::size_t(j)][k] =
          truth.q_measured_rad[std::size_t(j)][k_truth];
      const double e_true = truth.q_desired_rad[std::size_t(j)][k_truth] -
                            truth.q_measured_rad[std::size_t(j)][k_truth];
      const double e_ims =
          measured.q_desired_rad[std::size_t(j)][k] - measured.q_measured_rad[std::size_t(j)][k];
      sq_error(j) += (e_ims - e_true) * (e_ims - e_true);
      sq_signal(j) += e_true * e_true;
    }
  }
  std::printf(
      "identification measured by the IMS chain: %zu of %zu samples; joint error RMS "
      "(true | measurement error) [mrad]:",
      measured.sample_count(), truth.sample_count());
  for (int j = 0; j < 6; ++j)
    std::printf(" A%d %.3f | %.3f", j + 1,
                std::sqrt(sq_signal(j) / double(measured.sample_count())) * 1e3,
                std::sqrt(sq_error(j) / double(measured.sample_count())) * 1e3);
  std::printf("\n");

  const ident::IdentificationConfig config =
      ident::load_identification_config(ConfigNode::load_file(
          fs::path(IMSCAL_SOURCE_DIR) / "datasets/identification/ident-default.yaml"));
  const ModelTorqueSource torque_model = scenario_model_torque(identification);
  const IdentifiedTable table = identify_table(measured, config, "IMS chain", &torque_model);
  EXPECT_TRUE(table.failed_joints.empty());
  // The same models judged against the TRUE joint errors of the held-out rows: the model's own
  // error, without the measurement's in the target (ident::replay_held_out_fit).
  const std::vector<double> against_truth =
      replay_held_out_fits(table, truth_on_measured_rows, config, &torque_model);
  for (std::size_t j = 0; j < table.joints.size(); ++j) {
    const auto& joint = table.joints[j];
    const JointFitSummary s = summarize_fit(joint);
    const double signal_rms =
        std::sqrt(sq_signal(Eigen::Index(j)) / double(measured.sample_count()));
    const double noise_rms = std::sqrt(sq_error(Eigen::Index(j)) / double(measured.sample_count()));
    std::printf(
        "%s (from the IMS chain): held-out simulation fit %.3f %%, joint-error fit %.1f %% "
        "against the IMS-measured error, %.1f %% against the true error (a perfect model against "
        "the measured error: ~%.1f %%)\n",
        joint.parameters.name.c_str(), s.simulation_fit_percent, s.joint_error_fit_percent,
        against_truth[j], 100.0 * (1.0 - noise_rms / std::hypot(signal_rms, noise_rms)));
  }
  // The goal, >= 90 % held-out fit for every primary joint, met both ways (60 input taps,
  // positions corrected at the revisited poses, calib/revisited_poses.hpp). Measured: against
  // the IMS-measured errors A1 96.1, A2 95.1, A3 94.4 %; against the true errors 96.3, 95.1,
  // 94.4 % (with the transmission-error inputs; identified from the truth itself: 96.2, 95.3,
  // 94.5 % without them). The measurement's own error
  // in the held-out target (0.03-0.04 mrad RMS against a 3.5-3.7 mrad signal) caps a perfect
  // model at ~99 %. Without that correction the error was 0.21-0.31 mrad (cap ~94.4, 93.2,
  // 91.3 %) and the fits 93.5, 90.4, 84.4 % (95.7, 93.8, 93.0 % against the truth). Asserted in
  // Release at the goal itself: the chain is deterministic, the margin 4 %-points.
  for (std::size_t j = 0; j < 3; ++j) {
    EXPECT_GE(against_truth[j], 90.0) << table.joints[j].parameters.name;
    EXPECT_GE(summarize_fit(table.joints[j]).joint_error_fit_percent, 90.0)
        << table.joints[j].parameters.name << " against the IMS-measured errors";
  }
  VerificationOptions options;
  options.cycles = 10;  // ISO 9283
  options.segment_filter = "line";
  const VerificationResult r =
      verify_scenario(scenario("seed-line"), {{"from the IMS chain", table.table}}, options);
  std::printf("seed-line with the table identified from the IMS chain (%d cycles):\n", r.cycles);
  print_case(r.before, r.before.figures, r.before.true_figures);
  print_case(r.after[0], r.before.figures, r.before.true_figures);
  EXPECT_EQ(r.after[0].inactive_cycles, 0u);
  // Measured: 12.52 -> 0.632 mm (94.95 %) as the IMS chain sees the path, 12.47 -> 0.626 mm
  // (94.98 %) on the true path (10 cycles; 94.5 and 94.5 % without the
  // transmission-error inputs, 92.4 and 93.5 % without the warm-up and rests,
  // VerificationOptions): just short of the 95 % goal, which the table identified from the
  // simulator's truth reaches; asserted 3 %-points below, as above.
  EXPECT_GE(reduction_percent(r.before.figures.max_path_deviation_m,
                              r.after[0].figures.max_path_deviation_m),
            91.9);
  EXPECT_GE(reduction_percent(r.before.true_figures.max_path_deviation_m,
                              r.after[0].true_figures.max_path_deviation_m),
            91.9);
}

}  // namespace
}  // namespace imscal::eval
