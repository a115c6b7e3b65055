// The RSI and EGM servers (online/): 6 joints, order-32 ARX models (na = nb = 32, dead time 2) in a
// 3 x 2 operating-point table with blending and backlash (bench_precontrol.cpp's table without
// further inputs: the default identification's table takes a preview and the model torque,
// which RSI does not feed, docs/decisions/0024), at the 4 ms RSI cycle (two model steps per
// datagram).
//  - BM_RsiSessionDatagram: the server's work per datagram, from the received bytes to the
//    answer's bytes (parse, precontrol, serialise: RsiSession::handle), timed for each of 10^6
//    consecutive datagrams (steady_clock around the call, ~20 ns of its own): median, 99.9th
//    percentile, maximum, and the heap allocations inside the calls (counted by replacing
//    operator new). Goal: p99.9 < 50 us.
//  - BM_RsiLockStepLoopback: 10^6 datagrams through loopback UDP in lock-step (the emulator of
//    online/controller_emulator.hpp against the server loop in a thread): missed answers
//    (goal 0) and the round trip.
//  - BM_RsiPaced4ms: the controller's real pacing, one datagram every 4 ms for 30 s: the share of
//    answers later than 1 ms after their datagram was sent, and the latency's percentiles.
//  - BM_Egm*: the same three for ABB EGM (online/egm_session.hpp: protocol buffers, the server
//    playing the path of the set-points above plus the correction); the allocation count
//    excludes the first datagram, whose shape sizes the codec's reused messages.
// The machine is shared: a preempted call shows in the maximum and, when frequent, in p99.9.
// GCC 12 flags the malloc/free pair of the counting operator new (tests/support/
// allocation_counter.hpp) at every inlined std::allocator use in this file (a false positive).
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <random>
#include <string_view>
#include <vector>

#include "core/units.hpp"
#include "ident/precontrol.hpp"
#include "online/controller_emulator.hpp"
#include "online/egm_session.hpp"
#include "online/rsi_session.hpp"
#include "tests/support/allocation_counter.hpp"
#include "tests/support/arx_systems.hpp"
#include "tests/support/loopback_server.hpp"

namespace {

using namespace imscal;
using namespace imscal::online;

constexpr double kCycle = 0.004;

ident::ParameterTable order_32_table() {
  std::mt19937_64 rng(32);
  ident::ParameterTable t;
  t.robot = "kr16";
  t.sample_time_s = 0.002;
  for (int j = 0; j < 6; ++j) {
    ident::JointParameters joint;
    joint.name = std::string(1, 'A').append(std::to_string(j + 1));
    joint.dimensions = {
        ident::CellDimension{ident::OperatingQuantity::kSpeed, {0.0, 0.5, 1.5, 3.0}},
        ident::CellDimension{ident::OperatingQuantity::kPayload, {0.0, 8.0, 16.0}}};
    joint.backlash_l_rad = 1e-4;
    for (int c = 0; c < 6; ++c) {
      ident::CellParameters cell;
      cell.bands = {c / 2, c % 2};
      cell.structure = {32, 32, 2};
      const Eigen::VectorXd a =
          test_support::polynomial_from_poles(test_support::random_poles(32, rng));
      cell.a.assign(a.data(), a.data() + a.size());
      cell.b.assign(32, (1.0 + a.sum()) / 32.0);  // static gain 1
      joint.cells.push_back(cell);
    }
    t.joints.push_back(joint);
  }
  return t;
}

ident::PrecontrolOptions keep_active() {  // measure the full work: the supervisor stays quiet
  ident::PrecontrolOptions o;
  o.offset_tolerance_rad.fill(1.0);
  o.rate_tolerance_rad_s.fill(1e9);
  return o;
}

// The joints' set-points at cycle k [rad]: sweeps of the speed cells.
std::array<double, kRsiAxes> setpoint(std::size_t k) {
  std::array<double, kRsiAxes> q{};
  for (int j = 0; j < kRsiAxes; ++j)
    q[std::size_t(j)] = 0.8 * std::sin(0.5 * double(k) * kCycle + j);
  return q;
}

void percentiles(benchmark::State& state, std::vector<double>& values, const char* unit) {
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  state.counters[std::string("median_") + unit] = values[n / 2];
  state.counters[std::string("p99.9_") + unit] = values[std::size_t(double(n) * 0.999)];
  state.counters[std::string("max_") + unit] = values.back();
}

// Datagrams handed to a session one by one: the time of each handle() call, the allocations
// made inside it (where counted) and the answers written.
struct TimedDatagrams {
  std::vector<double> ns;
  long allocations = 0, answered = 0;
  std::array<char, 1024> out{};

  void handle(DatagramSession& session, std::string_view datagram, std::size_t k,
              bool count_allocations) {
    const long before = test_support::g_allocations.load(std::memory_order_relaxed);
    const auto begin = std::chrono::steady_clock::now();
    const int bytes = session.handle(datagram, double(k) * kCycle, out.data(), int(out.size()));
    const auto end = std::chrono::steady_clock::now();
    if (count_allocations)
      allocations += test_support::g_allocations.load(std::memory_order_relaxed) - before;
    answered += bytes > 0;
    benchmark::DoNotOptimize(out);
    ns[k] = std::chrono::duration<double, std::nano>(end - begin).count();
  }

  void report(benchmark::State& state, bool active_at_end) {
    percentiles(state, ns, "ns");
    state.counters["allocations"] = double(allocations);
    state.counters["answered"] = double(answered);
    state.counters["active_at_end"] = active_at_end;
  }
};

void BM_RsiSessionDatagram(benchmark::State& state) {
  RsiSessionOptions options;
  options.payload_kg = 8.0;
  std::string why;
  auto session = RsiSession::create(order_32_table(), "kr16", keep_active(), options, &why);
  if (!session) {
    state.SkipWithError(why.c_str());
    return;
  }
  constexpr std::size_t kDatagrams = 1000000;
  TimedDatagrams timed;
  timed.ns.resize(kDatagrams);
  std::array<char, 1024> in{};
  for (auto _ : state) {
    for (std::size_t k = 0; k < kDatagrams; ++k) {
      std::array<double, kRsiAxes> q_deg = setpoint(k);
      for (double& v : q_deg) v *= kDegPerRad;
      const int n = write_rsi_robot_datagram("KUKA", q_deg, 4 * k, in.data(), int(in.size()));
      timed.handle(*session, std::string_view(in.data(), std::size_t(n)), k, true);
    }
  }
  timed.report(state, session->state() == ident::PrecontrolState::kActive);
}
BENCHMARK(BM_RsiSessionDatagram)->Unit(benchmark::kMillisecond)->Iterations(1);

// The set-points of `datagrams` cycles as the path an EGM server plays.
online::LoadedPath setpoint_path(std::size_t datagrams) {
  online::LoadedPath path;
  path.cycle_s = kCycle;
  path.q_rad.resize(datagrams);
  for (std::size_t k = 0; k < datagrams; ++k) path.q_rad[k] = setpoint(k);
  return path;
}

void BM_EgmSessionDatagram(benchmark::State& state) {
  constexpr std::size_t kDatagrams = 1000000;
  EgmSessionOptions options;
  options.payload_kg = 8.0;
  std::string why;
  auto session = EgmSession::create(order_32_table(), "kr16", keep_active(), options,
                                    setpoint_path(kDatagrams), 0.0, &why);
  if (!session) {
    state.SkipWithError(why.c_str());
    return;
  }
  TimedDatagrams timed;
  timed.ns.resize(kDatagrams);
  std::array<char, 1024> in{};
  EgmCodec controller;
  for (auto _ : state) {
    for (std::size_t k = 0; k < kDatagrams; ++k) {
      EgmRobotDatagram d;  // the robot at its target: the path's joints of the cycle
      d.seqno = std::uint32_t(k + 1);
      d.tm_ms = std::uint32_t(4 * k);
      d.feedback_joints = d.planned_joints = kEgmAxes;
      const std::array<double, kRsiAxes> q = setpoint(k);
      for (int a = 0; a < kEgmAxes; ++a)
        d.feedback_deg[std::size_t(a)] = d.planned_deg[std::size_t(a)] =
            q[std::size_t(a)] * kDegPerRad;
      d.motors = EgmMotors::kOn;
      const int n = controller.write_robot(d, in.data(), int(in.size()));
      // The first datagram sets the session up (its codec's messages): not in the cycle's count.
      timed.handle(*session, std::string_view(in.data(), std::size_t(n)), k, k > 0);
    }
  }
  timed.report(state, session->state() == ident::PrecontrolState::kActive);
}
BENCHMARK(BM_EgmSessionDatagram)->Unit(benchmark::kMillisecond)->Iterations(1);

EmulatorRun run_over_loopback(std::size_t datagrams, bool paced, ControllerProtocol protocol) {
  std::unique_ptr<test_support::LoopbackServer> server;
  if (protocol == ControllerProtocol::kEgm) {
    EgmSessionOptions options;
    options.payload_kg = 8.0;
    server = std::make_unique<test_support::LoopbackServer>(order_32_table(), keep_active(),
                                                            options, setpoint_path(datagrams), 0.0);
  } else {
    RsiSessionOptions options;
    options.payload_kg = 8.0;
    server =
        std::make_unique<test_support::LoopbackServer>(order_32_table(), keep_active(), options);
  }
  std::vector<std::array<double, kRsiAxes>> q(datagrams);
  for (std::size_t k = 0; k < datagrams; ++k) q[k] = setpoint(k);
  UdpSocket controller("127.0.0.1", 0);
  EmulatorOptions emulator;
  emulator.protocol = protocol;
  if (protocol == ControllerProtocol::kEgm) emulator.ipoc_per_cycle = 1;
  emulator.paced = paced;
  emulator.answer_timeout_s = paced ? 0.004 : 0.5;  // paced: an answer after the cycle is missed
  return emulate_controller(controller, server->peer(), q, emulator);
}

void lock_step_loopback(benchmark::State& state, ControllerProtocol protocol) {
  constexpr std::size_t kDatagrams = 1000000;
  EmulatorRun run;
  for (auto _ : state) run = run_over_loopback(kDatagrams, false, protocol);
  state.counters["datagrams"] = double(kDatagrams);
  state.counters["missed"] = double(run.missed);
  std::vector<double> us;
  for (double s : run.latency_s) us.push_back(s * 1e6);
  percentiles(state, us, "round_trip_us");
}
void BM_RsiLockStepLoopback(benchmark::State& state) {
  lock_step_loopback(state, ControllerProtocol::kRsi);
}
BENCHMARK(BM_RsiLockStepLoopback)->Unit(benchmark::kSecond)->Iterations(1);

void BM_EgmLockStepLoopback(benchmark::State& state) {
  lock_step_loopback(state, ControllerProtocol::kEgm);
}
BENCHMARK(BM_EgmLockStepLoopback)->Unit(benchmark::kSecond)->Iterations(1);

void paced_4ms(benchmark::State& state, ControllerProtocol protocol) {
  constexpr std::size_t kDatagrams = 7500;  // 30 s
  EmulatorRun run;
  for (auto _ : state) run = run_over_loopback(kDatagrams, true, protocol);
  std::vector<double> us;
  std::size_t late = 0;
  for (std::size_t k = 0; k < run.latency_s.size(); ++k) {
    const bool answered = run.answered[k];
    late += !answered || run.latency_s[k] > 1e-3;
    if (answered) us.push_back(run.latency_s[k] * 1e6);
  }
  state.counters["datagrams"] = double(kDatagrams);
  state.counters["missed"] = double(run.missed);
  state.counters["later_than_1ms_percent"] = 100.0 * double(late) / double(kDatagrams);
  percentiles(state, us, "latency_us");
}
void BM_RsiPaced4ms(benchmark::State& state) {
  paced_4ms(state, ControllerProtocol::kRsi);
}
BENCHMARK(BM_RsiPaced4ms)->Unit(benchmark::kSecond)->Iterations(1);

void BM_EgmPaced4ms(benchmark::State& state) {
  paced_4ms(state, ControllerProtocol::kEgm);
}
BENCHMARK(BM_EgmPaced4ms)->Unit(benchmark::kSecond)->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
