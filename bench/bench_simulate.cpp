// Speed of `imscal simulate` (goal: 60 s of the `identification` scenario with every
// effect on in < 10 s wall time on one core): the whole run_simulation (plan, plant with RK4 at
// 0.5 ms, FK of every 1 ms sample, spline, IMS synthesis at 1 kHz, sensor errors and noise),
// without the file writing. Reported as real time per simulated 60 s.
#include <benchmark/benchmark.h>

#include <filesystem>

#include "sim/scenario.hpp"
#include "sim/simulation.hpp"

namespace {

void BM_Simulate60sIdentification(benchmark::State& state) {
  const imscal::sim::Scenario scenario = imscal::sim::load_scenario(
      std::filesystem::path(IMSCAL_SOURCE_DIR) / "datasets" / "scenarios" / "identification.yaml");
  double simulated_s = 0.0;
  for (auto _ : state) {
    const imscal::sim::SimulationResult result = imscal::sim::run_simulation(scenario, 1, {}, 60.0);
    simulated_s = result.path.samples.back().t_s;
    benchmark::DoNotOptimize(result.imu_raw.samples.data());
  }
  state.counters["simulated_s"] = simulated_s;
  state.counters["imu_samples"] = simulated_s * 1000.0;
}
BENCHMARK(BM_Simulate60sIdentification)->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
