#include "eval/closed_loop.hpp"

#include <algorithm>
#include <array>
#include <limits>
#include <memory>
#include <stdexcept>

namespace imscal::eval {

namespace {

// One precontrol (one cascade stage) along `path`.
CompensationRun run_stage(const ident::ParameterTable& table, const std::string& robot_name,
                          const sim::DesiredJointPath& path, const CompensationOptions& options) {
  const std::size_t n = path.samples.size();
  // The warm-up (path at rest at its start only): cycles 0 .. W-1 at the first sample; the path's
  // cycle k is then the precontrol's cycle W + k (its counter stays consecutive). Events are
  // reported on the path's cycles: those of the warm-up on cycle 0.
  const bool starts_at_rest = n > 1 && path.samples[0].qd_rad_s.norm() == 0.0 &&
                              path.samples[0].qdd_rad_s2.norm() == 0.0 &&
                              path.samples[1].q_rad == path.samples[0].q_rad;
  const std::size_t warm_up = starts_at_rest ? std::size_t(std::max(0, options.warm_up_cycles)) : 0;
  ident::PrecontrolOptions precontrol_options = options.precontrol;
  precontrol_options.caller_cycle_s = path.cycle_s;
  if (warm_up > 0) {
    // Powered on at the start pose as the online bridges start it (auto_engage): the models
    // settle with the offset held at zero, then it fades in. Started active, the first offset
    // (the start pose's static deflection, 3.6 mrad on the UR10e's shoulder) is a step whose
    // smoothed rate the supervisor takes for a fault. A deactivation on the path stays final.
    precontrol_options.auto_engage = true;
    precontrol_options.reengage_after_s = std::numeric_limits<double>::infinity();
  }
  // The precontrol is a large fixed-size object (no heap inside its cycle): keep it on the heap.
  auto precontrol = std::make_unique<ident::Precontrol>();
  std::string why;
  if (!ident::Precontrol::create(table, robot_name, precontrol_options, precontrol.get(), &why)) {
    throw std::invalid_argument("precontrol refused the parameter table: " + why);
  }
  std::vector<calib::JointVector> torque;
  if (precontrol->needs_model_torque()) {
    if (!options.model_torque)
      throw std::invalid_argument(
          "the parameter table's models take the model torque: the robot's rigid-body model is "
          "needed (CompensationOptions::model_torque)");
    // The table's refined links, when its identification refined them.
    torque = model_torques_along(with_table_links(*options.model_torque, table, "parameters.json"),
                                 path);
  }
  CompensationRun run;
  run.offset_rad.resize(n);
  run.state.resize(n);
  run.outside_table.resize(n);
  std::array<ident::PrecontrolEvent, ident::kPrecontrolEventCapacity> events{};
  // An inverse-form table is fed q_d its preview ahead, on top of the smoother's look-ahead.
  const auto look_ahead = std::size_t(options.look_ahead_cycles + table.preview_cycles);
  for (std::size_t i = 0; i < warm_up + n; ++i) {
    const std::size_t k = i < warm_up ? 0 : i - warm_up;
    const std::size_t ahead = i < warm_up ? 0 : std::min(n - 1, k + look_ahead);
    const sim::DesiredJointSample& s = path.samples[ahead];
    std::array<double, ident::kPrecontrolJoints> q{};
    for (int j = 0; j < ident::kPrecontrolJoints; ++j) q[std::size_t(j)] = s.q_rad[j];
    const double payload_kg =
        path.payloads.empty() ? 0.0 : path.payloads[std::size_t(s.payload_index)].body.mass_kg;
    std::array<double, ident::kPrecontrolJoints> tau{};
    if (!torque.empty())
      for (int j = 0; j < ident::kPrecontrolJoints; ++j) tau[std::size_t(j)] = torque[ahead][j];
    const ident::PrecontrolOutput out = torque.empty() ? precontrol->cycle(q, payload_kg, i)
                                                       : precontrol->cycle(q, payload_kg, tau, i);
    const int read = precontrol->read_events(events.data(), int(events.size()));
    for (int e = 0; e < read; ++e) {
      const ident::PrecontrolCause cause = events[std::size_t(e)].cause;
      const bool engagement =
          cause == ident::PrecontrolCause::kEngaging || cause == ident::PrecontrolCause::kEngaged;
      if (i < warm_up && engagement) continue;  // the power-on, not an event of the run
      run.events.push_back(events[std::size_t(e)]);
      run.events.back().cycle = k;
    }
    if (i < warm_up) continue;
    for (int j = 0; j < ident::kPrecontrolJoints; ++j) {
      run.offset_rad[k][j] = out.offset_rad[std::size_t(j)];
    }
    run.state[k] = out.state;
    run.outside_table[k] = out.outside_table;
  }
  return run;
}

}  // namespace

CompensationRun run_precontrol(const ident::ParameterTable& table, const std::string& robot_name,
                               const sim::DesiredJointPath& path,
                               const CompensationOptions& options) {
  if (options.look_ahead_cycles < 0) {
    throw std::invalid_argument("run_precontrol: look-ahead must be >= 0 cycles");
  }
  if (options.inversion_iterations < 0) {
    throw std::invalid_argument("run_precontrol: inversion iterations must be >= 0");
  }
  if (options.inversion_iterations > 0 && options.look_ahead_cycles > 0) {
    // Each stage would hand out its output L cycles early, so the cascade's fixed point would no
    // longer be G(q_d + o) = q_d.
    throw std::invalid_argument(
        "run_precontrol: inversion iterations need look-ahead 0 (the cascade's fixed point is "
        "defined without it)");
  }
  if (options.inversion_iterations > 0 && table.model_form == ident::TableForm::kInverse) {
    throw std::invalid_argument(
        "run_precontrol: inversion iterations are for forward-form tables; an inverse-form "
        "table is the inversion");
  }
  CompensationRun run = run_stage(table, robot_name, path, options);
  for (int i = 0; i < options.inversion_iterations; ++i) {
    // The next stage sees q_d + o_i; its offset is o_{i+1}. A stage that deactivated hands out
    // its fade-out (at most what it had): the cascade then falls back towards no compensation.
    sim::DesiredJointPath input = path;
    for (std::size_t k = 0; k < path.samples.size(); ++k)
      input.samples[k].q_rad += run.offset_rad[k];
    CompensationRun next = run_stage(table, robot_name, input, options);
    for (std::size_t k = 0; k < path.samples.size(); ++k) {
      // A cycle is active only when every stage is.
      if (run.state[k] != ident::PrecontrolState::kActive) next.state[k] = run.state[k];
      next.outside_table[k] = next.outside_table[k] || run.outside_table[k];
    }
    run.events.insert(run.events.end(), next.events.begin(), next.events.end());
    std::stable_sort(run.events.begin(), run.events.end(),
                     [](const auto& x, const auto& y) { return x.cycle < y.cycle; });
    next.events = std::move(run.events);
    run = std::move(next);
  }
  return run;
}

sim::DesiredJointPath command_path(const sim::DesiredJointPath& desired,
                                   const std::vector<calib::JointVector>& offsets) {
  const std::size_t n = desired.samples.size();
  if (offsets.size() != n) {
    throw std::invalid_argument("command_path: one offset per desired sample needed");
  }
  sim::DesiredJointPath command = desired;
  const double T = desired.cycle_s;
  // Central differences inside, one-sided at the ends; with one sample the rates are zero.
  auto rate = [&](const std::vector<calib::JointVector>& x, std::size_t k) -> calib::JointVector {
    if (n < 2) return calib::JointVector::Zero();
    if (k == 0) return (x[1] - x[0]) / T;
    if (k + 1 == n) return (x[n - 1] - x[n - 2]) / T;
    return (x[k + 1] - x[k - 1]) / (2.0 * T);
  };
  std::vector<calib::JointVector> offset_rate(n);
  for (std::size_t k = 0; k < n; ++k) offset_rate[k] = rate(offsets, k);
  for (std::size_t k = 0; k < n; ++k) {
    sim::DesiredJointSample& s = command.samples[k];
    s.q_rad += offsets[k];
    s.qd_rad_s += offset_rate[k];
    s.qdd_rad_s2 += rate(offset_rate, k);
  }
  return command;
}

PlantRun simulator_plant(const sim::PlantConfig& config) {
  return [config](const sim::DesiredJointPath& command) {
    return sim::simulate_plant(config, command, command.cycle_s);
  };
}

ClosedLoopRun run_closed_loop(const sim::DesiredJointPath& desired,
                              const ident::ParameterTable& table, const std::string& robot_name,
                              const PlantRun& plant, const CompensationOptions& options) {
  ClosedLoopRun run;
  run.compensation = run_precontrol(table, robot_name, desired, options);
  run.command = command_path(desired, run.compensation.offset_rad);
  run.uncompensated = plant(desired);
  run.compensated = plant(run.command);
  for (const sim::PlantLog* log : {&run.uncompensated, &run.compensated}) {
    if (log->samples.size() != desired.samples.size()) {
      throw std::invalid_argument("run_closed_loop: the plant returned " +
                                  std::to_string(log->samples.size()) + " samples for " +
                                  std::to_string(desired.samples.size()) + " commanded");
    }
  }
  return run;
}

std::vector<calib::JointVector> joint_errors(const sim::DesiredJointPath& desired,
                                             const sim::PlantLog& attained) {
  const std::size_t n = std::min(desired.samples.size(), attained.samples.size());
  std::vector<calib::JointVector> errors(n);
  for (std::size_t k = 0; k < n; ++k) {
    errors[k] = desired.samples[k].q_rad - attained.samples[k].q_link_rad;
  }
  return errors;
}

}  // namespace imscal::eval
