#pragma once
// Cases of the withheld-effect harness (tests/eval/test_gap_harness.cpp, test_diagnose_cli.cpp):
// the simulator runs tests/data/scenarios/gap-program.yaml with a base set of effects ("sim") and
// with one or two effects added or injected ("real", plus measurement noise). The base is the
// robot's default plant with backlash off on every joint (so that backlash can be withheld on
// its own; an elastic gear without its play is then a clean second effect).
#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "calib/robot_description.hpp"
#include "eval/gap_candidates.hpp"
#include "ident/joint_error_io.hpp"
#include "sim/motion_planner.hpp"
#include "sim/motion_program.hpp"
#include "sim/plant_config.hpp"
#include "sim/plant_simulator.hpp"

namespace imscal::eval::test {

struct WithheldEffect {
  std::string name;  // backlash, coulomb, elastic, transmission, time_offset, zero_offset,
                     // payload, drift
  int joint = 0;
};

inline EffectKind expected_kind(const std::string& name) {
  if (name == "backlash") return EffectKind::kBacklash;
  if (name == "coulomb") return EffectKind::kCoulombFriction;
  if (name == "elastic") return EffectKind::kGearCompliance;
  if (name == "transmission") return EffectKind::kTransmissionError;
  if (name == "time_offset") return EffectKind::kTimeOffset;
  if (name == "zero_offset") return EffectKind::kZeroOffset;
  if (name == "payload") return EffectKind::kPayloadMismatch;
  return EffectKind::kThermalDrift;
}

struct GapWorld {
  calib::RobotDescription robot =
      calib::load_robot_description(IMSCAL_SOURCE_DIR "/datasets/robots/kr16.yaml");
  sim::DesiredJointPath path = sim::plan_motion(
      robot, sim::load_motion_program(IMSCAL_TEST_DATA_DIR "/scenarios/gap-program.yaml"));
  sim::PlantConfig base = [this] {
    sim::PlantConfig c = sim::make_plant_config(robot, nullptr);
    for (auto& e : c.effects) e.backlash = false;
    return c;
  }();
  sim::PlantLog base_log = sim::simulate_plant(base, path, path.cycle_s);

  // Joint errors of a plant log (q_measured = link side, q_internal = motor / N).
  ident::JointErrorLog log_of(const sim::PlantLog& plant) const {
    ident::JointErrorLog log;
    log.robot = robot.name;
    log.cycle_s = path.cycle_s;
    for (const auto& j : robot.joints) log.joint_names.push_back(j.name);
    const std::size_t n = path.samples.size();
    log.q_desired_rad.assign(6, std::vector<double>(n));
    log.q_measured_rad = log.q_desired_rad;
    log.q_internal_rad = log.q_desired_rad;
    for (std::size_t k = 0; k < n; ++k) {
      log.time_s.push_back(path.samples[k].t_s);
      log.payload_kg.push_back(
          path.payloads[std::size_t(path.samples[k].payload_index)].body.mass_kg);
      for (int j = 0; j < 6; ++j) {
        log.q_desired_rad[std::size_t(j)][k] = path.samples[k].q_rad[j];
        log.q_measured_rad[std::size_t(j)][k] = plant.samples[k].q_link_rad[j];
        log.q_internal_rad[std::size_t(j)][k] = plant.samples[k].q_motor_rad[j];
      }
    }
    return log;
  }

  // A case: "real" = the plant with the effects on (plus injected ones and IMS-chain-like noise
  // on q_measured: white 3e-6 rad plus a first-order 50 ms coloured part of 3e-6 rad, ~3 um at
  // 1 m), "sim" = the plant with them off. Backlash and the transmission error are off in the
  // base (real: switched on); Coulomb friction and the elastic gear are on in the base (sim:
  // switched off). Effect sizes vary with the seed (x0.7..1.3).
  struct Case {
    ident::JointErrorLog real;             // with noise
    ident::JointErrorLog real_noise_free;  // = "the sim re-run with the true effects on"
    std::vector<std::vector<double>> sim_joint_error_rad;
  };
  Case make_case(const std::vector<WithheldEffect>& effects, std::uint64_t seed) const {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> size(0.7, 1.3);
    sim::PlantConfig real_config = base, sim_config = base;
    sim::DesiredJointPath real_path = path;
    bool real_changed = false, sim_changed = false;
    for (const auto& e : effects) {
      auto& re = real_config.effects[std::size_t(e.joint)];
      auto& se = sim_config.effects[std::size_t(e.joint)];
      if (e.name == "backlash") re.backlash = real_changed = true;
      if (e.name == "transmission") {
        re.transmission_error = real_changed = true;
        re.transmission_error_shape.amplitude_rad *= 2.0 * size(rng);  // 28..52 arcsec
      }
      if (e.name == "coulomb") se.coulomb_friction = false, sim_changed = true;
      if (e.name == "elastic") se.elastic_gear = se.gear_damping = false, sim_changed = true;
      if (e.name == "payload") {
        for (auto& p : real_path.payloads) p.body.mass_kg += 4.0 * size(rng);
        real_changed = true;
      }
    }
    Case c;
    const sim::PlantLog real_plant =
        real_changed ? sim::simulate_plant(real_config, real_path, path.cycle_s) : base_log;
    const sim::PlantLog sim_plant =
        sim_changed ? sim::simulate_plant(sim_config, path, path.cycle_s) : base_log;
    c.sim_joint_error_rad.assign(6, std::vector<double>(path.samples.size()));
    for (std::size_t k = 0; k < path.samples.size(); ++k)
      for (int j = 0; j < 6; ++j)
        c.sim_joint_error_rad[std::size_t(j)][k] =
            path.samples[k].q_rad[j] - sim_plant.samples[k].q_link_rad[j];
    ident::JointErrorLog log = log_of(real_plant);
    const std::size_t n = log.sample_count();
    for (const auto& e : effects) {
      auto& qm = log.q_measured_rad[std::size_t(e.joint)];
      if (e.name == "time_offset") {
        // The measurement stream lags by dt: q_m(t) = q_link(t - dt), linear interpolation.
        const double dt = 0.004 * size(rng);
        const std::vector<double> q = qm;
        for (std::size_t k = 0; k < n; ++k) {
          const double x = std::clamp((log.time_s[k] - dt) / log.cycle_s, 0.0, double(n - 1));
          const std::size_t i = std::min(std::size_t(x), n - 2);
          qm[k] = q[i] + (x - double(i)) * (q[i + 1] - q[i]);
        }
      }
      if (e.name == "zero_offset") {
        const double offset = 1.5e-4 * size(rng);
        for (double& v : qm) v -= offset;
      }
      if (e.name == "drift") {
        const double a = 2e-4 * size(rng), duration = log.time_s.back();
        for (std::size_t k = 0; k < n; ++k) {
          const double x = log.time_s[k] / duration;
          qm[k] -= a * (x + 0.5 * x * x);
        }
      }
    }
    c.real_noise_free = log;
    std::normal_distribution<double> white(0.0, 3e-6);
    const double phi = std::exp(-log.cycle_s / 0.05);
    for (auto& qm : log.q_measured_rad) {
      double ar = 0.0;
      for (double& v : qm) {
        ar = phi * ar + std::sqrt(1.0 - phi * phi) * white(rng);
        v += white(rng) + ar;
      }
    }
    c.real = std::move(log);
    return c;
  }
};

}  // namespace imscal::eval::test
