#include "eval/verification.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <random>
#include <stdexcept>
#include <utility>

#include "core/parallel_tasks.hpp"
#include "eval/ims_measured_path.hpp"
#include "eval/iso9283_path.hpp"
#include "eval/path_deviation.hpp"
#include "eval/transmission_error_gear_mode.hpp"
#include "ident/identification_config_record.hpp"
#include "ident/identify_joints.hpp"
#include "ims/earth_model.hpp"
#include "robot/forward_kinematics.hpp"
#include "sim/motion_planner.hpp"
#include "sim/motion_program.hpp"

namespace imscal::eval {
namespace {

// The site's normal gravity in the robot base R [m/s²] (as sim::run_simulation computes it).
Eigen::Vector3d gravity_in_base(const sim::Scenario& scenario) {
  const ims::EarthModel earth(scenario.site);
  return scenario.T_W_R.linear().transpose() * earth.gravity_W(scenario.T_W_R.translation());
}

// The scenario's plant (plant_robot: sim::load_plant_robot), feeling the site's gravity.
sim::PlantConfig scenario_plant(const sim::Scenario& scenario,
                                const calib::RobotDescription& plant_robot) {
  sim::PlantConfig config = sim::make_plant_config(plant_robot, scenario);
  config.gravity_in_base_m_s2 = gravity_in_base(scenario);
  return config;
}

double payload_mass(const sim::DesiredJointPath& path, const sim::DesiredJointSample& s) {
  return path.payloads.empty() ? 0.0 : path.payloads[std::size_t(s.payload_index)].body.mass_kg;
}

bool is_cartesian(sim::SegmentKind kind) {
  return kind == sim::SegmentKind::kLinear || kind == sim::SegmentKind::kCircular;
}

std::size_t index_of(double t_s, double cycle_s) {
  return std::size_t(std::max(0L, std::lround(t_s / cycle_s)));
}

// The path from sample k0 to k1 (inclusive), re-timed to start at 0.
sim::DesiredJointPath cut_path(const sim::DesiredJointPath& path, std::size_t k0, std::size_t k1) {
  sim::DesiredJointPath out;
  out.cycle_s = path.cycle_s;
  out.payloads = path.payloads;
  const double t0 = path.samples[k0].t_s, t1 = path.samples[k1].t_s;
  for (std::size_t k = k0; k <= k1; ++k) {
    sim::DesiredJointSample s = path.samples[k];
    s.t_s = double(k - k0) * path.cycle_s;
    out.samples.push_back(s);
  }
  for (sim::PathSegment segment : path.segments) {
    if (segment.end_s <= t0 || segment.begin_s >= t1) continue;
    segment.begin_s = std::max(segment.begin_s, t0) - t0;
    segment.end_s = std::min(segment.end_s, t1) - t0;
    out.segments.push_back(segment);
  }
  return out;
}

std::vector<PathPose> flange_path(const calib::RobotDescription& robot,
                                  const std::vector<double>& t_s,
                                  const std::vector<calib::JointVector>& q) {
  std::vector<PathPose> poses(q.size());
  for (std::size_t k = 0; k < q.size(); ++k) {
    const Eigen::Isometry3d T_R_H = calib::forward_kinematics<double>(robot.kinematics, q[k]);
    poses[k] = {t_s[k], T_R_H.translation(), Eigen::Quaterniond(T_R_H.linear()).normalized()};
  }
  return poses;
}

std::vector<PathPose> attained_path(const calib::RobotDescription& robot,
                                    const sim::PlantLog& log) {
  std::vector<double> t;
  std::vector<calib::JointVector> q;
  for (const sim::PlantSample& s : log.samples) {
    t.push_back(s.t_s);
    q.push_back(s.q_link_rad);
  }
  return flange_path(robot, t, q);
}

PoseSeries window(const std::vector<PathPose>& poses, double from_s, double to_s) {
  PoseSeries out;
  for (const PathPose& p : poses)
    if (p.t_s >= from_s - 1e-9 && p.t_s <= to_s + 1e-9) out.push_back(p);
  return out;
}

// Per case (the uncompensated path, then each command) and cycle: the attained path as measured,
// and the true one.
struct AttainedPaths {
  std::vector<std::vector<std::vector<PathPose>>> measured, truth;
};

// The plant's draws per cycle (friction factors), in the order one loop over the cycles would
// draw them.
std::vector<sim::PlantConfig> cycle_plants(const sim::PlantConfig& base,
                                           const VerificationOptions& options) {
  std::mt19937_64 rng(options.seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<sim::PlantConfig> plants;
  for (int j = 0; j < options.cycles; ++j) {
    sim::PlantConfig config = base;
    for (auto& joint : config.robot.joints) {
      // Clamped to >= 0.5 so that a rare draw cannot make the friction vanish or turn negative.
      const double factor = std::max(0.5, 1.0 + options.friction_sigma_fraction * normal(rng));
      joint.drive.coulomb_nm *= factor;
      joint.drive.viscous_nm_s_per_rad *= factor;
    }
    plants.push_back(std::move(config));
  }
  return plants;
}

// Every (cycle, case) run is an independent task on the cores (core/parallel_tasks.hpp): the
// draws are made before, each task writes its own slot, so the result does not depend on the
// threads.
AttainedPaths simulate_cycles(const sim::Scenario& scenario,
                              const calib::RobotDescription& plant_robot,
                              const sim::NominalRobot& nominal, const sim::DesiredJointPath& path,
                              const std::vector<sim::DesiredJointPath>& commands,
                              const VerificationOptions& options) {
  const std::vector<sim::PlantConfig> plants =
      cycle_plants(scenario_plant(scenario, plant_robot), options);
  // The standstill at the start of the run: the IMS chain's first rest.
  double standstill_s = 0.0;
  for (const auto& sample : path.samples) {
    if (sample.qd_rad_s.norm() != 0.0 || sample.qdd_rad_s2.norm() != 0.0) break;
    standstill_s = sample.t_s;
  }
  const std::size_t cases = commands.size() + 1, cycle_count = plants.size();
  AttainedPaths out;
  out.measured.assign(cases, std::vector<std::vector<PathPose>>(cycle_count));
  out.truth = out.measured;
  run_parallel_tasks(cases * cycle_count, [&](std::size_t task) {
    const std::size_t j = task / cases, c = task % cases;
    const sim::DesiredJointPath& command = c == 0 ? path : commands[c - 1];
    const sim::PlantLog plant = sim::simulate_plant(plants[j], command, path.cycle_s);
    out.truth[c][j] = attained_path(plant_robot, plant);
    if (!options.measure_with_ims) {
      out.measured[c][j] = out.truth[c][j];
      return;
    }
    // The controller's log holds the interpolator's desired angles (the offset is added after
    // it): the chain finds the program's standstills there.
    const ImsJointMeasurement m =
        measure_joints_with_ims(scenario, plant_robot, nominal, path, plant, standstill_s,
                                options.ims_seed + std::uint64_t(j));
    std::vector<double> t;
    std::vector<calib::JointVector> q;
    for (std::size_t k = 0; k < m.q_rad.size(); ++k)
      if (m.valid[k]) t.push_back(plant.samples[k].t_s), q.push_back(m.q_rad[k]);
    out.measured[c][j] = flange_path(nominal.description, t, q);
  });
  return out;
}

PathFigures path_figures(const std::vector<sim::PathSegment>& segments,
                         const std::vector<sim::PathSegment>& all_segments,
                         const std::vector<PathPose>& desired,
                         const std::vector<std::vector<PathPose>>& cycles,
                         const VerificationOptions& options, PlotSeries* series) {
  PathFigures f;
  double worst_av = 0.0;
  for (const sim::PathSegment& segment : segments) {
    const PoseSeries commanded = window(desired, segment.begin_s, segment.end_s);
    std::vector<PoseSeries> attained;
    for (const auto& cycle : cycles) {
      attained.push_back(window(cycle, segment.begin_s - options.iso_time_window_s,
                                segment.end_s + options.iso_time_window_s));
    }
    // Commanded speed: the segment's top speed; the velocity characteristics over the part of
    // the segment where the command runs within 1 % of it.
    std::vector<double> s(commanded.size(), 0.0), v(commanded.size(), 0.0);
    for (std::size_t k = 1; k < commanded.size(); ++k) {
      const double ds = (commanded[k].p_m - commanded[k - 1].p_m).norm();
      s[k] = s[k - 1] + ds;
      v[k] = ds / (commanded[k].t_s - commanded[k - 1].t_s);
    }
    const double v_c = *std::max_element(v.begin(), v.end());
    Iso9283Options iso;
    iso.calculation_points = options.calculation_points;
    iso.time_window_s = options.iso_time_window_s;
    iso.velocity_from_m = s.back();
    iso.velocity_to_m = 0.0;
    for (std::size_t k = 1; k < v.size(); ++k) {
      if (v[k] < 0.99 * v_c) continue;
      iso.velocity_from_m = std::min(iso.velocity_from_m, s[k - 1]);
      iso.velocity_to_m = std::max(iso.velocity_to_m, s[k]);
    }
    const Iso9283PathResult r = iso9283_path(commanded, attained, v_c, iso);
    f.AT_p_m = std::max(f.AT_p_m, r.AT_p_m);
    f.RT_p_m = std::max(f.RT_p_m, r.RT_p_m);
    f.AT_abc_rad = f.AT_abc_rad.cwiseMax(r.AT_abc_rad);
    f.RT_abc_rad = f.RT_abc_rad.cwiseMax(r.RT_abc_rad);
    if (std::abs(r.AV_percent) >= std::abs(worst_av)) worst_av = r.AV_percent;
    f.RV_percent = std::max(f.RV_percent, r.RV_percent);
    f.FV_m_s = std::max(f.FV_m_s, r.FV_m_s);
    f.missed_crossings += r.missed_crossings;
    // Overshoot at the stop of a straight segment: how far the flange runs on beyond the end
    // point along the line, until the next motion starts (at most 0.5 s after the stop).
    if (segment.kind == sim::SegmentKind::kLinear) {
      const Eigen::Vector3d start = commanded.front().p_m, end = commanded.back().p_m;
      const Eigen::Vector3d direction = (end - start).normalized();
      double until = segment.end_s + 0.5;
      for (const sim::PathSegment& next : all_segments) {
        if (next.begin_s >= segment.end_s - 1e-9 && next.kind != sim::SegmentKind::kRest) {
          until = std::min(until, next.begin_s);
          break;
        }
      }
      for (const auto& cycle : cycles)
        for (const PathPose& p : window(cycle, segment.begin_s, until))
          f.CO_m = std::max(f.CO_m, (p.p_m - end).dot(direction));
    }
  }
  f.AV_percent = worst_av;

  // Path deviation (Fig. 6): the samples inside the evaluated segments.
  auto inside = [&](double t) {
    for (const sim::PathSegment& segment : segments)
      if (t >= segment.begin_s - 1e-9 && t <= segment.end_s + 1e-9) return true;
    return false;
  };
  std::vector<TimedPoint> desired_points;
  for (const PathPose& p : desired)
    if (inside(p.t_s)) desired_points.push_back({p.t_s, p.p_m});
  double sum_squares = 0.0;
  std::size_t count = 0;
  std::vector<PathDeviation> deviations;  // per cycle, for the scatter floor
  for (std::size_t j = 0; j < cycles.size(); ++j) {
    std::vector<TimedPoint> actual;
    for (const PathPose& p : cycles[j])
      if (inside(p.t_s)) actual.push_back({p.t_s, p.p_m});
    PathDeviation d = path_deviation(desired_points, actual, options.deviation_window_s);
    f.max_path_deviation_m = std::max(f.max_path_deviation_m, d.max_m);
    for (double e : d.deviation_m) sum_squares += e * e;
    count += d.deviation_m.size();
    if (j == 0 && series) {
      *series = {};
      double arc = 0.0;
      for (std::size_t k = 0; k < actual.size(); ++k) {
        if (k > 0) arc += (desired_points[k].p_m - desired_points[k - 1].p_m).norm();
        series->t_s.push_back(actual[k].t_s);
        series->arc_length_m.push_back(arc);
        series->desired_m.push_back(desired_points[k].p_m);
        series->attained_m.push_back(actual[k].p_m);
        series->deviation_m.push_back(d.deviation_m[k]);
      }
    }
    deviations.push_back(std::move(d));
  }
  f.rms_path_deviation_m = count ? std::sqrt(sum_squares / double(count)) : 0.0;
  const CycleSplit split = split_cycles(deviations);
  f.scatter_floor_m = split.scatter_floor_m;
  f.systematic_max_m = split.systematic_max_m;
  f.about_mean_max_m = split.about_mean_max_m;
  return f;
}

Eigen::Matrix<double, 8, 1> pose_row(const PathPose& p) {
  Eigen::Matrix<double, 8, 1> row;
  row << p.t_s, p.p_m.x(), p.p_m.y(), p.p_m.z(), p.q.w(), p.q.x(), p.q.y(), p.q.z();
  return row;
}

}  // namespace

namespace {

// The scenario's program (cut at max_duration_s) planned by the plant's controller, the plant's
// run, and the nominal robot that the joint-error log is written for.
struct ScenarioRun {
  calib::RobotDescription plant_robot;
  sim::NominalRobot nominal;
  sim::DesiredJointPath path;
  sim::PlantLog plant;
};

ScenarioRun run_scenario(const sim::Scenario& scenario, double max_duration_s) {
  ScenarioRun run;
  run.plant_robot = sim::load_plant_robot(scenario);
  run.nominal = sim::load_nominal_robot(scenario);
  run.path = sim::plan_motion(run.plant_robot, sim::load_motion_program(scenario.program_file));
  while (run.path.samples.size() > 2 && run.path.samples.back().t_s > max_duration_s) {
    run.path.samples.pop_back();
  }
  run.plant =
      sim::simulate_plant(scenario_plant(scenario, run.plant_robot), run.path, run.path.cycle_s);
  return run;
}

// The joint-error log of a run, one sample per controller cycle: q_d, the measured angles where
// measured[k] holds a value (gaps elsewhere) and the encoders (q_internal = motor angle / N).
ident::JointErrorLog joint_error_log(const ScenarioRun& run,
                                     const std::vector<std::optional<calib::JointVector>>& measured,
                                     std::string source) {
  ident::JointErrorLog log;
  log.robot = run.nominal.description.name;
  log.cycle_s = run.path.cycle_s;
  log.source = std::move(source);
  for (const auto& joint : run.nominal.description.joints) log.joint_names.push_back(joint.name);
  log.q_desired_rad.assign(calib::kJointCount, {});
  log.q_measured_rad.assign(calib::kJointCount, {});
  log.q_internal_rad.assign(calib::kJointCount, {});
  for (std::size_t k = 0; k < measured.size(); ++k) {
    if (!measured[k]) continue;
    log.time_s.push_back(run.path.samples[k].t_s);
    log.payload_kg.push_back(payload_mass(run.path, run.path.samples[k]));
    for (int j = 0; j < calib::kJointCount; ++j) {
      log.q_desired_rad[std::size_t(j)].push_back(run.path.samples[k].q_rad[j]);
      log.q_measured_rad[std::size_t(j)].push_back((*measured[k])[j]);
      log.q_internal_rad[std::size_t(j)].push_back(run.plant.samples[k].q_motor_rad[j]);
    }
  }
  ident::split_at_gaps(log);
  return log;
}

}  // namespace

ident::JointErrorLog simulate_truth_joint_errors(const sim::Scenario& scenario,
                                                 double max_duration_s) {
  const ScenarioRun run = run_scenario(scenario, max_duration_s);
  std::vector<std::optional<calib::JointVector>> link(
      std::min(run.path.samples.size(), run.plant.samples.size()));
  for (std::size_t k = 0; k < link.size(); ++k) link[k] = run.plant.samples[k].q_link_rad;
  return joint_error_log(
      run, link,
      fmt::format("simulator truth (q_measured = link-side angles) of scenario {}", scenario.name));
}

ident::JointErrorLog simulate_ims_joint_errors(const sim::Scenario& scenario, std::uint64_t seed,
                                               double max_duration_s) {
  const ScenarioRun run = run_scenario(scenario, max_duration_s);
  double standstill_s = 0.0;  // the program's initial rest: the chain's first rest
  for (const auto& sample : run.path.samples) {
    if (sample.qd_rad_s.norm() != 0.0 || sample.qdd_rad_s2.norm() != 0.0) break;
    standstill_s = sample.t_s;
  }
  const ImsJointMeasurement m = measure_joints_with_ims(scenario, run.plant_robot, run.nominal,
                                                        run.path, run.plant, standstill_s, seed);
  std::vector<std::optional<calib::JointVector>> ims(
      std::min(run.path.samples.size(), run.plant.samples.size()));
  for (std::size_t k = 0; k < ims.size(); ++k)
    if (m.valid[k]) ims[k] = m.q_rad[k];
  return joint_error_log(
      run, ims,
      fmt::format("IMS chain (simulated navigation-grade IMS, seed {}) of scenario {}", seed,
                  scenario.name));
}

ModelTorqueSource nominal_model_torque(const sim::NominalRobot& nominal,
                                       const sim::Scenario& scenario) {
  return {nominal.description, gravity_in_base(scenario)};
}

ModelTorqueSource scenario_model_torque(const sim::Scenario& scenario) {
  return nominal_model_torque(sim::load_nominal_robot(scenario), scenario);
}

CompensationOptions verification_compensation(const sim::Scenario& scenario,
                                              const VerificationOptions& options) {
  CompensationOptions compensation = options.compensation;
  if (!compensation.model_torque) compensation.model_torque = scenario_model_torque(scenario);
  return compensation;
}

namespace {

// Whether `log` lacks the model torques the config's models take; then a robot model is needed
// (std::invalid_argument naming the caller otherwise) and they are attached to a copy.
bool needs_model_torques(const ident::JointErrorLog& log, const ident::IdentificationConfig& config,
                         const ModelTorqueSource* torque_model, const char* caller) {
  if (!config.options.model_torque_input || !log.model_torque_nm.empty()) return false;
  if (torque_model == nullptr)
    throw std::invalid_argument(std::string(caller) +
                                ": the config's models take the model torque; give the robot's "
                                "rigid-body model");
  return true;
}

ident::JointErrorLog with_model_torques(ident::JointErrorLog log, const ModelTorqueSource& model,
                                        const ident::IdentificationConfig& config) {
  attach_model_torques(log, model, config.options);
  return log;
}

}  // namespace

IdentifiedTable identify_table(const ident::JointErrorLog& log,
                               const ident::IdentificationConfig& given_config,
                               const std::string& source_file,
                               const ModelTorqueSource* torque_model) {
  ident::IdentificationConfig config =
      given_config.resolved_cycle_s == log.cycle_s
          ? given_config
          : ident::resolve_for_record(given_config, log.robot, log.cycle_s, source_file);
  if (needs_model_torques(log, config, torque_model, "identify_table"))
    return identify_table(with_model_torques(log, *torque_model, config), config, source_file,
                          torque_model);
  if (torque_model != nullptr) set_transmission_error_gear_modes(config, log, *torque_model);
  if (config.max_speed_rad_s.size() != log.joint_count()) {
    throw std::invalid_argument(fmt::format("identify_table: config has {} joints, the data {}",
                                            config.max_speed_rad_s.size(), log.joint_count()));
  }
  IdentifiedTable out;
  out.table =
      ident::parameter_table_header(log, config, {source_file, "", log.sample_count(), log.source});
  for (auto& outcome : ident::identify_joints(log, config)) {
    if (!outcome.failure.empty())
      out.failed_joints.push_back(outcome.result.parameters.name + ": " + outcome.failure);
    out.table.joints.push_back(outcome.result.parameters);
    out.joints.push_back(std::move(outcome.result));
  }
  return out;
}

std::vector<double> replay_held_out_fits(const IdentifiedTable& identified,
                                         const ident::JointErrorLog& reference,
                                         const ident::IdentificationConfig& config,
                                         const ModelTorqueSource* torque_model) {
  if (needs_model_torques(reference, config, torque_model, "replay_held_out_fits"))
    return replay_held_out_fits(identified, with_model_torques(reference, *torque_model, config),
                                config);
  if (identified.joints.size() != reference.joint_count())
    throw std::invalid_argument("replay_held_out_fits: the table and the record differ in joints");
  const auto segments = reference.segments();
  std::vector<double> fits;
  for (std::size_t j = 0; j < identified.joints.size(); ++j) {
    const std::span<const double> torque = reference.model_torque_nm.empty()
                                               ? std::span<const double>()
                                               : reference.model_torque_nm[j];
    fits.push_back(ident::replay_held_out_fit(identified.joints[j], reference.q_desired_rad[j],
                                              reference.q_measured_rad[j], reference.payload_kg,
                                              segments, reference.cycle_s, config.joint_grid(j),
                                              config.joint_options(j), torque)
                       .joint_error_fit_percent);
  }
  return fits;
}

ident::IdentificationConfig with_operating_point_grid(ident::IdentificationConfig config) {
  config.speed_fraction_bounds = {0.0, 0.2, 0.8, 1.0};
  config.payload_fraction_bounds = {0.0, 0.5, 1.0};
  return config;
}

ident::IdentificationConfig single_cell(ident::IdentificationConfig config) {
  config.speed_fraction_bounds = {0.0, 1.0};
  config.payload_fraction_bounds = {0.0, 1.0};
  config.extra_dimensions.clear();
  return config;
}

ident::IdentificationConfig paper_form(ident::IdentificationConfig config) {
  ident::JointIdentificationOptions& o = config.options;
  o.form = ident::ArxModelForm::kJointError;
  o.preview_cycles = 0;
  o.model_torque_input = o.direction_input = o.torque_sign_input = false;
  o.transmission_error_input = false;
  o.identify_backlash = true;
  return with_operating_point_grid(std::move(config));
}

std::vector<AblationConfig> ablation_configs(const ident::IdentificationConfig& config) {
  std::vector<AblationConfig> out{{"paper form", paper_form(config)}};
  if (config.options.model_torque_input) {
    AblationConfig a{"without model torque", config};
    a.config.options.model_torque_input = a.config.options.torque_sign_input = false;
    // The transmission error's phase then from the link angle alone (no torque, no deflection).
    a.config.gear_stiffness_nm_per_rad.clear();
    out.push_back(std::move(a));
  }
  if (config.options.transmission_error_input) {
    AblationConfig a{"without transmission error", config};
    a.config.options.transmission_error_input = false;
    out.push_back(std::move(a));
  }
  AblationConfig backlash{
      config.options.identify_backlash ? "without backlash term" : "with backlash term", config};
  backlash.config.options.identify_backlash = !config.options.identify_backlash;
  out.push_back(std::move(backlash));
  const bool one_cell = config.speed_fraction_bounds.size() == 2 &&
                        config.payload_fraction_bounds.size() == 2 &&
                        config.extra_dimensions.empty();
  if (one_cell)
    out.push_back({"with operating-point grid", with_operating_point_grid(config)});
  else
    out.push_back({"single cell", single_cell(config)});
  return out;
}

JointFitSummary summarize_fit(const ident::JointIdentification& joint) {
  JointFitSummary s;
  double sim = 0.0, err = 0.0;
  std::size_t err_rows = 0;
  for (std::size_t c = 0; c < joint.cells.size(); ++c) {
    if (joint.cells[c].status != ident::CellStatus::kIdentified) continue;
    const ident::CellFitFigures& f = joint.parameters.cells[c].figures;
    if (!std::isfinite(f.simulation_fit_percent) || f.validation_rows == 0) continue;
    sim += f.simulation_fit_percent * double(f.validation_rows);
    s.validation_rows += f.validation_rows;
    if (std::isfinite(f.joint_error_fit_percent)) {
      err += f.joint_error_fit_percent * double(f.validation_rows);
      err_rows += f.validation_rows;
    }
  }
  if (s.validation_rows) s.simulation_fit_percent = sim / double(s.validation_rows);
  if (err_rows) s.joint_error_fit_percent = err / double(err_rows);
  return s;
}

double reduction_percent(double before, double after) {
  return 100.0 * (1.0 - after / before);
}

VerificationResult verify_scenario(const sim::Scenario& scenario,
                                   const std::vector<NamedTable>& tables,
                                   const VerificationOptions& options) {
  if (options.cycles < 1) throw std::invalid_argument("verify: at least one cycle");
  // The simulated world (the plant's controller plans, the plant runs, its link angles are the
  // truth) and the chain (the IMS chain's kinematics, the model torque and the precontrol).
  const calib::RobotDescription plant_robot = sim::load_plant_robot(scenario);
  const sim::NominalRobot nominal = sim::load_nominal_robot(scenario);
  const sim::DesiredJointPath full =
      sim::plan_motion(plant_robot, sim::load_motion_program(scenario.program_file));
  const double T = full.cycle_s;

  // The evaluated segments and the part of the program that is run.
  std::vector<sim::PathSegment> evaluated;
  for (const sim::PathSegment& s : full.segments)
    if (is_cartesian(s.kind) && s.label.find(options.segment_filter) != std::string::npos)
      evaluated.push_back(s);
  if (evaluated.empty()) {
    throw std::invalid_argument(
        fmt::format("verify: no Cartesian segment of scenario {} has '{}' in its label",
                    scenario.name, options.segment_filter));
  }
  std::size_t k0 = index_of(evaluated.front().begin_s - options.lead_in_s, T);
  const std::size_t k1 =
      std::min(full.samples.size() - 1, index_of(evaluated.back().end_s + options.lead_out_s, T));
  for (std::size_t k = k0; k <= index_of(evaluated.front().begin_s, T) && k0 > 0; ++k) {
    if (full.samples[k].qd_rad_s.norm() != 0.0 || full.samples[k].qdd_rad_s2.norm() != 0.0) {
      k0 = 0;  // not at rest there: run the program from its start
    }
  }
  const sim::DesiredJointPath path = cut_path(full, k0, k1);
  const double t0 = full.samples[k0].t_s;
  for (sim::PathSegment& s : evaluated) s.begin_s -= t0, s.end_s -= t0;

  VerificationResult result;
  result.scenario = scenario.name;
  result.cycles = options.cycles;
  result.evaluated_from_s = evaluated.front().begin_s + t0;
  result.evaluated_to_s = evaluated.back().end_s + t0;
  for (const auto& s : evaluated) result.segments.push_back(s.label);

  // The commands: one per table (the precontrol does not depend on the plant's draw). Tables
  // whose models take the model torque get it from the scenario's nominal robot unless the
  // caller gave a model.
  const CompensationOptions compensation = verification_compensation(scenario, options);
  std::vector<CompensationRun> compensations;
  std::vector<sim::DesiredJointPath> commands;
  for (const NamedTable& t : tables) {
    compensations.push_back(
        options.compensation_runner
            ? options.compensation_runner(t.table, nominal.description.name, path, compensation)
            : run_precontrol(t.table, nominal.description.name, path, compensation));
    commands.push_back(command_path(path, compensations.back().offset_rad));
  }

  std::vector<double> t_s;
  std::vector<calib::JointVector> q_d;
  for (const auto& s : path.samples) t_s.push_back(s.t_s), q_d.push_back(s.q_rad);
  const std::vector<PathPose> desired = flange_path(plant_robot, t_s, q_d);

  // Per case and cycle: the attained path as measured, and the true one.
  const AttainedPaths attained =
      simulate_cycles(scenario, plant_robot, nominal, path, commands, options);
  const auto& cycles = attained.measured;
  const auto& true_cycles = attained.truth;

  auto make_case = [&](const std::string& label, std::size_t index) {
    VerificationCase vc;
    vc.label = label;
    vc.figures =
        path_figures(evaluated, path.segments, desired, cycles[index], options, &vc.series);
    vc.true_figures = options.measure_with_ims ? path_figures(evaluated, path.segments, desired,
                                                              true_cycles[index], options, nullptr)
                                               : vc.figures;
    for (double& t : vc.series.t_s) t += t0;  // back to the scenario's clock
    return vc;
  };
  result.before = make_case("uncompensated", 0);
  for (std::size_t c = 0; c < tables.size(); ++c) {
    VerificationCase vc = make_case(tables[c].label, c + 1);
    vc.events = compensations[c].events;
    for (auto state : compensations[c].state)
      vc.inactive_cycles += state != ident::PrecontrolState::kActive;
    result.after.push_back(std::move(vc));
  }
  for (const PathPose& p : desired) {
    PathPose shifted = p;
    shifted.t_s += t0;
    result.desired_poses.push_back(pose_row(shifted));
  }
  result.attained_poses.resize(cycles.size());
  for (std::size_t c = 0; c < cycles.size(); ++c) {
    for (const auto& cycle : cycles[c]) {
      std::vector<Eigen::Matrix<double, 8, 1>> rows;
      for (PathPose p : cycle) {
        p.t_s += t0;
        rows.push_back(pose_row(p));
      }
      result.attained_poses[c].push_back(std::move(rows));
    }
  }
  return result;
}

}  // namespace imscal::eval
