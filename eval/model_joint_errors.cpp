#include "eval/model_joint_errors.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "ims/earth_model.hpp"
#include "sim/motion_program.hpp"
#include "sim/plant_simulator.hpp"

namespace imscal::eval {
namespace {

void check_log_fits(const ident::JointErrorLog& log, const calib::RobotDescription& robot) {
  if (log.sample_count() < 2)
    throw std::invalid_argument("the measured joint errors have fewer than two samples");
  if (log.robot != robot.name)
    throw std::invalid_argument(
        fmt::format("the joint errors are of robot '{}', the nominal "
                    "robot is '{}'",
                    log.robot, robot.name));
  std::vector<std::string> names;
  for (const auto& j : robot.joints) names.push_back(j.name);
  if (log.joint_names != names)
    throw std::invalid_argument(fmt::format("the joint errors have joints {}, the nominal robot {}",
                                            fmt::join(log.joint_names, ","),
                                            fmt::join(names, ",")));
  if (std::abs(log.cycle_s - robot.controller_cycle_s) > 1e-9)
    throw std::invalid_argument(
        fmt::format("the joint errors' cycle is {} s, the nominal robot's "
                    "controller cycle {} s",
                    log.cycle_s, robot.controller_cycle_s));
}

// Grid index of every logged sample (cycles from the first one).
std::vector<std::size_t> grid_indices(const ident::JointErrorLog& log) {
  std::vector<std::size_t> index;
  for (double t : log.time_s)
    index.push_back(std::size_t(std::max(0L, std::lround((t - log.time_s.front()) / log.cycle_s))));
  return index;
}

// The desired joints on the whole grid: the logged ones, linear between them across gaps.
std::vector<calib::JointVector> desired_on_grid(const ident::JointErrorLog& log,
                                                const std::vector<std::size_t>& index) {
  const auto at = [&](std::size_t k) {
    calib::JointVector q;
    for (int j = 0; j < calib::kJointCount; ++j) q[j] = log.q_desired_rad[std::size_t(j)][k];
    return q;
  };
  std::vector<calib::JointVector> q(index.back() + 1);
  for (std::size_t k = 0; k + 1 < index.size(); ++k) {
    const std::size_t a = index[k], b = index[k + 1];
    for (std::size_t i = a; i < b; ++i)
      q[i] = at(k) + (at(k + 1) - at(k)) * (double(i - a) / double(b - a));
  }
  q.back() = at(index.size() - 1);
  return q;
}

// The payload a logged mass stands for: the known one of that mass, else a point mass at the tool
// frame's origin.
sim::Payload payload_of_mass(double mass_kg, const std::vector<sim::Payload>& known) {
  for (const sim::Payload& p : known)
    if (std::abs(p.body.mass_kg - mass_kg) <= 1e-9 * std::max(1.0, mass_kg)) return p;
  sim::Payload p;
  p.name = fmt::format("logged {} kg", mass_kg);
  p.body.mass_kg = mass_kg;
  return p;
}

// The payloads a scenario's program carries (its mass properties beyond the logged mass).
std::vector<sim::Payload> program_payloads(const sim::Scenario* scenario) {
  if (!scenario) return {};
  const sim::MotionProgram program = sim::load_motion_program(scenario->program_file);
  std::vector<sim::Payload> payloads = {program.initial_payload};
  for (const sim::ProgramStep& step : program.steps)
    if (step.kind == sim::ProgramStepKind::kPayload) payloads.push_back(step.payload);
  return payloads;
}

// The path: q_d on the grid with central-difference derivatives, one point-mass payload per
// distinct logged mass (the value of the logged sample at or before each grid point).
sim::DesiredJointPath desired_path(const ident::JointErrorLog& log,
                                   const std::vector<std::size_t>& index,
                                   const std::vector<sim::Payload>& known) {
  const std::vector<calib::JointVector> q = desired_on_grid(log, index);
  const std::size_t n = q.size();
  const double h = log.cycle_s;
  sim::DesiredJointPath path;
  path.cycle_s = h;
  std::size_t logged = 0;
  for (std::size_t i = 0; i < n; ++i) {
    while (logged + 1 < index.size() && index[logged + 1] <= i) ++logged;
    const double mass = log.payload_kg.empty() ? 0.0 : log.payload_kg[logged];
    const auto same_mass = [&](const sim::Payload& p) { return p.body.mass_kg == mass; };
    auto it = std::find_if(path.payloads.begin(), path.payloads.end(), same_mass);
    if (it == path.payloads.end()) {
      path.payloads.push_back(payload_of_mass(mass, known));
      it = path.payloads.end() - 1;
    }
    sim::DesiredJointSample s;
    s.t_s = double(i) * h;
    s.q_rad = q[i];
    const std::size_t a = i == 0 ? 0 : i - 1, b = std::min(i + 1, n - 1);
    s.qd_rad_s = (q[b] - q[a]) / (double(b - a) * h);
    if (i > 0 && i + 1 < n) s.qdd_rad_s2 = (q[i + 1] - 2.0 * q[i] + q[i - 1]) / (h * h);
    s.payload_index = int(it - path.payloads.begin());
    path.samples.push_back(s);
  }
  path.segments.push_back(
      {sim::SegmentKind::kPtp, "measured desired path", 0.0, path.samples.back().t_s});
  return path;
}

sim::PlantConfig nominal_plant(const sim::NominalRobot& nominal, const sim::Scenario* scenario) {
  if (!scenario) return sim::make_plant_config(nominal.description, nullptr);
  sim::PlantConfig config = sim::make_plant_config(nominal.description, *scenario);
  // The site's normal gravity in the base R, as the simulator's run computes it.
  const ims::EarthModel earth(scenario->site);
  config.gravity_in_base_m_s2 =
      scenario->T_W_R.linear().transpose() * earth.gravity_W(scenario->T_W_R.translation());
  return config;
}

}  // namespace

ident::JointErrorLog nominal_model_joint_errors(const ident::JointErrorLog& measured,
                                                const sim::NominalRobot& nominal,
                                                const sim::Scenario* scenario) {
  check_log_fits(measured, nominal.description);
  const std::vector<std::size_t> index = grid_indices(measured);
  const sim::DesiredJointPath path = desired_path(measured, index, program_payloads(scenario));
  const sim::PlantLog plant =
      sim::simulate_plant(nominal_plant(nominal, scenario), path, path.cycle_s);
  ident::JointErrorLog out = measured;
  out.source = fmt::format("nominal model of robot {} ({}) along the measured desired path",
                           nominal.description.name,
                           scenario ? "effects and gravity of scenario " + scenario->name
                                    : std::string("the simulator's default effects"));
  out.metadata.clear();
  out.model_torque_nm.clear();
  for (std::size_t k = 0; k < index.size(); ++k) {
    const sim::PlantSample& p = plant.samples[std::min(index[k], plant.samples.size() - 1)];
    for (int j = 0; j < calib::kJointCount; ++j) {
      out.q_measured_rad[std::size_t(j)][k] = p.q_link_rad[j];
      out.q_internal_rad[std::size_t(j)][k] = p.q_motor_rad[j];
    }
  }
  return out;
}

NominalPlant nominal_plant_along(const ident::JointErrorLog& measured,
                                 const sim::NominalRobot& nominal, const sim::Scenario* scenario) {
  check_log_fits(measured, nominal.description);
  NominalPlant out;
  out.samples = grid_indices(measured);
  out.path = desired_path(measured, out.samples, program_payloads(scenario));
  out.config = nominal_plant(nominal, scenario);
  return out;
}

}  // namespace imscal::eval
