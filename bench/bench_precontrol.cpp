// One precontrol cycle (ident/precontrol.hpp) for 6 joints with order-32 ARX models (na = nb =
// 32, dead time 2) in a 3 x 2 operating-point table (joint speed x payload) with blending and a
// backlash term, and the same table with the default identification's three further inputs in
// every cell (60 coefficients each for torque and direction): the time of each of 10^6
// consecutive cycles is measured (steady_clock around the call, ~20 ns of its own), and the
// median, the 99.9th percentile and the maximum are reported.
// Goal: 99.9th percentile < 2 us (the cycle is 2 ms). Each case also runs on the all-cells
// reference (tests/support/reference_precontrol.hpp) in the same process: the machine is shared,
// so compare the runtime with the reference of the same run rather than with older figures.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>
#include <vector>

#include "ident/precontrol.hpp"
#include "tests/support/arx_systems.hpp"
#include "tests/support/reference_precontrol.hpp"

namespace {

using namespace imscal::ident;

// The default identification's coefficients per torque and direction input
// (datasets/identification/ident-default.yaml, model.input_taps: 60) and
// per input of the transmission-error pair (model.transmission_error_taps: 32).
constexpr int kDefaultInputTaps = 60;
constexpr int kDefaultTransmissionErrorTaps = 32;

// inputs: 0, or every cell also takes the first 3 or all 5 further inputs of the default
// identification (model torque and direction with kDefaultInputTaps coefficients each, the
// torque's sign with one, the transmission-error pair with kDefaultTransmissionErrorTaps each;
// 3: the default without the transmission-error pair).
ParameterTable order_32_table(int inputs) {
  const bool with_inputs = inputs > 0, transmission_error = inputs == 5;
  std::mt19937_64 rng(32);
  ParameterTable t;
  t.robot = "kr16";
  t.sample_time_s = 0.002;
  if (with_inputs)
    t.extra_inputs = {TableInput::kModelTorque, TableInput::kDirection, TableInput::kTorqueSign};
  if (transmission_error) {
    t.extra_inputs.push_back(TableInput::kTransmissionErrorSin);
    t.extra_inputs.push_back(TableInput::kTransmissionErrorCos);
  }
  for (int j = 0; j < 6; ++j) {
    JointParameters joint;
    joint.name = std::string(1, 'A').append(std::to_string(j + 1));
    joint.dimensions = {CellDimension{OperatingQuantity::kSpeed, {0.0, 0.5, 1.5, 3.0}},
                        CellDimension{OperatingQuantity::kPayload, {0.0, 8.0, 16.0}}};
    joint.backlash_l_rad = 1e-4;
    if (with_inputs) joint.torque_sign_scale_nm = 1.0;
    if (transmission_error) {
      joint.transmission_error_rad_per_rad = 160.0;           // harmonic 1 x gear ratio 160
      joint.transmission_error_compliance_rad_per_nm = 2e-6;  // 1 / (5e5 N m/rad)
    }
    for (int c = 0; c < 6; ++c) {
      CellParameters cell;
      cell.bands = {c / 2, c % 2};
      cell.structure = {32, 32, 2};
      const Eigen::VectorXd a =
          imscal::test_support::polynomial_from_poles(imscal::test_support::random_poles(32, rng));
      const double a_sum = 1.0 + a.sum();
      cell.a.assign(a.data(), a.data() + a.size());
      cell.b.assign(32, a_sum / 32.0);  // static gain 1
      if (with_inputs) {
        cell.structure.extra_inputs = inputs;
        cell.structure.nx = {kDefaultInputTaps, kDefaultInputTaps, 1, kDefaultTransmissionErrorTaps,
                             kDefaultTransmissionErrorTaps};
        // A small response to torque, direction, side and the transmission error.
        cell.c.assign(std::size_t(cell.structure.extra_coefficient_count()), 1e-7);
      }
      joint.cells.push_back(cell);
    }
    t.joints.push_back(joint);
  }
  return t;
}

// Times each of kCycles consecutive cycles of `precontrol` (Precontrol or the all-cells
// reference, same interface) and reports median, 99th and 99.9th percentile and maximum in ns,
// the cycles slower than the goal and those slower than 20 us (per 10^6), and the fraction of
// cycles that ended active (the supervisor must not switch the work off). A cycle of 20 us or
// more was preempted (the work is < 2 us): on a shared machine these and the cycles hit by an
// interrupt or by a neighbour's cache traffic number some 10^2..10^3 per 10^6, so the 99.9th
// percentile is the machine's as much as the cycle's once `over_2us` nears 1000.
template <class Runtime>
void time_cycles(benchmark::State& state, int inputs) {
  const bool with_inputs = inputs > 0;
  const ParameterTable table = order_32_table(inputs);
  PrecontrolOptions options;
  options.offset_tolerance_rad.fill(1.0);  // keep it active: measure the full work
  options.rate_tolerance_rad_s.fill(1e9);
  static Runtime precontrol;  // ~540 kB of fixed state: not on the stack
  std::string why;
  if (!Runtime::create(table, "kr16", options, &precontrol, &why)) {
    state.SkipWithError(why.c_str());
    return;
  }
  constexpr int kCycles = 1000000;
  std::vector<double> ns(kCycles);
  std::array<double, 6> q{}, torque{};
  int active = 0;
  for (auto _ : state) {
    for (int k = 0; k < kCycles; ++k) {
      const double t = k * 0.002;
      for (int j = 0; j < 6; ++j) q[j] = 0.8 * std::sin(0.5 * t + j);  // sweeps the speed cells
      for (int j = 0; j < 6; ++j) torque[j] = 100.0 * std::sin(0.5 * t + j);  // N m
      const double payload = 8.0 + 6.0 * std::sin(0.01 * t);
      const auto begin = std::chrono::steady_clock::now();
      const PrecontrolOutput out =
          with_inputs ? precontrol.cycle(q, payload, torque, k) : precontrol.cycle(q, payload, k);
      const auto end = std::chrono::steady_clock::now();
      benchmark::DoNotOptimize(out);
      active += out.state == PrecontrolState::kActive;
      ns[k] = std::chrono::duration<double, std::nano>(end - begin).count();
    }
  }
  std::sort(ns.begin(), ns.end());
  auto slower_than = [&](double limit_ns) {
    return double(ns.end() - std::upper_bound(ns.begin(), ns.end(), limit_ns));
  };
  state.counters["median_ns"] = ns[kCycles / 2];
  state.counters["p99_ns"] = ns[static_cast<std::size_t>(kCycles * 0.99)];
  state.counters["p99.9_ns"] = ns[static_cast<std::size_t>(kCycles * 0.999)];
  state.counters["max_ns"] = ns.back();
  state.counters["over_2us"] = slower_than(2000.0);
  state.counters["over_20us"] = slower_than(20000.0);
  state.counters["active"] = double(active) / kCycles;
}

void BM_PrecontrolCycle6JointsOrder32(benchmark::State& state) {
  time_cycles<Precontrol>(state, 0);
}
BENCHMARK(BM_PrecontrolCycle6JointsOrder32)->Unit(benchmark::kMillisecond)->Iterations(1);

// The same table with the default identification's five further inputs in every cell (the
// model torque fed by the caller): the heaviest table the default config can produce per cell.
void BM_PrecontrolCycle6JointsOrder32FurtherInputs(benchmark::State& state) {
  time_cycles<Precontrol>(state, 5);
}
BENCHMARK(BM_PrecontrolCycle6JointsOrder32FurtherInputs)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);

// The default without the transmission-error pair: what the pair costs, in
// the same run.
void BM_PrecontrolCycle6JointsOrder32ThreeFurtherInputs(benchmark::State& state) {
  time_cycles<Precontrol>(state, 3);
}
BENCHMARK(BM_PrecontrolCycle6JointsOrder32ThreeFurtherInputs)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);

// The same with the runtime as it was before the precontrol's speed work (every cell runs every
// cycle): the before/after comparison in one run, on the same machine load.
void BM_AllCellsReferenceCycle6JointsOrder32(benchmark::State& state) {
  time_cycles<imscal::test_support::AllCellsPrecontrol>(state, 0);
}
BENCHMARK(BM_AllCellsReferenceCycle6JointsOrder32)->Unit(benchmark::kMillisecond)->Iterations(1);

void BM_AllCellsReferenceCycle6JointsOrder32FurtherInputs(benchmark::State& state) {
  time_cycles<imscal::test_support::AllCellsPrecontrol>(state, 5);
}
BENCHMARK(BM_AllCellsReferenceCycle6JointsOrder32FurtherInputs)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
