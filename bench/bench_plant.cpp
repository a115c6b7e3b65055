// Speed of the plant simulator: 60 s of a multi-joint motion of the KR 16 with all effects on
// (elastic gears with backlash and damping, motor inertias, Coulomb + viscous friction,
// transmission error, 4 ms dead time), RK4 at 0.5 ms, 1 ms output. Goal: <= 4 s wall time per
// simulated 60 s on one core (the whole `imscal simulate` should stay below 10 s).
#include <benchmark/benchmark.h>

#include <cmath>

#include "sim/plant_config.hpp"
#include "sim/plant_simulator.hpp"

namespace {

using imscal::calib::JointVector;
using namespace imscal::sim;
constexpr double kDeg = M_PI / 180.0;

const imscal::calib::RobotDescription& kr16() {
  static const auto robot =
      imscal::calib::load_robot_description(IMSCAL_SOURCE_DIR "/datasets/robots/kr16.yaml");
  return robot;
}

// Six joints oscillating smoothly (incommensurate periods 2.7-7.9 s) around a mid pose, with a
// 5 kg payload: every joint moves, accelerates and reverses throughout the 60 s.
DesiredJointPath sixty_second_motion() {
  DesiredJointPath path;
  path.cycle_s = kr16().controller_cycle_s;
  path.payloads.push_back({"none", {}});
  Payload load{"5 kg", {}};
  load.body.mass_kg = 5.0;
  load.body.com_m = Eigen::Vector3d(0.0, 0.0, 0.1);
  path.payloads.push_back(load);
  JointVector centre, amplitude, period;
  centre << 0.0, -70 * kDeg, 80 * kDeg, 0.0, 40 * kDeg, 0.0;
  amplitude << 60 * kDeg, 25 * kDeg, 30 * kDeg, 90 * kDeg, 40 * kDeg, 120 * kDeg;
  period << 7.9, 6.1, 5.3, 4.1, 3.3, 2.7;
  const long count = std::lround(60.0 / path.cycle_s) + 1;
  for (long k = 0; k < count; ++k) {
    DesiredJointSample s;
    s.t_s = static_cast<double>(k) * path.cycle_s;
    s.payload_index = 1;
    for (int i = 0; i < 6; ++i) {
      const double w = 2.0 * M_PI / period(i);
      // (1 - cos) phase: starts at rest.
      const double phase = w * s.t_s;
      s.q_rad(i) = centre(i) + amplitude(i) * (1.0 - std::cos(phase)) * 0.5;
      s.qd_rad_s(i) = amplitude(i) * 0.5 * w * std::sin(phase);
      s.qdd_rad_s2(i) = amplitude(i) * 0.5 * w * w * std::cos(phase);
    }
    path.samples.push_back(s);
  }
  path.segments.push_back({SegmentKind::kPtp, "oscillation", 0.0, path.samples.back().t_s});
  return path;
}

void BM_Plant60sAllEffects(benchmark::State& state) {
  PlantConfig config = make_plant_config(kr16(), nullptr);
  for (JointEffects& e : config.effects) {
    e.transmission_error = true;
    e.dead_time_s = 0.004;
  }
  const DesiredJointPath path = sixty_second_motion();
  std::size_t samples = 0;
  for (auto _ : state) {
    const PlantLog log = simulate_plant(config, path, 0.001);
    samples = log.samples.size();
    benchmark::DoNotOptimize(log.samples.back().q_link_rad(0));
  }
  state.counters["samples"] = static_cast<double>(samples);
  state.counters["simulated_s"] = 60.0;
}
BENCHMARK(BM_Plant60sAllEffects)->Unit(benchmark::kSecond)->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
