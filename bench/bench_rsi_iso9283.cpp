// The closed loop through the RSI and EGM servers against `imscal verify`'s in-process loop, on the
// paper's line (seed-line) and the ISO 9283 set: the default table (identified from the
// identification scenario's truth, as tests/eval/test_verification.cpp) is served with the
// program's path loaded (online/path_follower.hpp: the preview and the model torque along it,
// look-ahead 4 cycles as verify), the controller emulator plays the set-points over loopback UDP
// in lock-step, and eval::verify_scenario runs the plant on the corrections received
// (VerificationOptions::compensation_runner). Reported: the maximum path deviation's reduction
// in process and through the sockets, on the true path over 3 friction cycles, and their
// difference in percentage points (goal: within 0.5), with the path's clock started at the
// motion (the server cannot know the path ahead at the start of the first motion) and with the
// stream (the path recorded from the stream's first datagram); and through the EGM server, which
// plays the loaded path itself (online/egm_session.hpp: its clock is the stream's).
#include <benchmark/benchmark.h>

#include <filesystem>

#include "core/config_node.hpp"
#include "eval/model_torque.hpp"
#include "eval/verification.hpp"
#include "ident/identification_config.hpp"
#include "online/controller_emulator.hpp"
#include "online/egm_session.hpp"
#include "online/path_follower.hpp"
#include "sim/scenario.hpp"
#include "tests/support/loopback_server.hpp"

namespace {

using namespace imscal;
namespace fs = std::filesystem;

const eval::IdentifiedTable& default_table() {
  static const eval::IdentifiedTable table = [] {
    const sim::Scenario identification =
        sim::load_scenario(sim::resolve_scenario("identification"));
    const ident::JointErrorLog log = eval::simulate_truth_joint_errors(identification);
    const ident::IdentificationConfig config =
        ident::load_identification_config(ConfigNode::load_file(
            fs::path(IMSCAL_SOURCE_DIR) / "datasets/identification/ident-default.yaml"));
    const eval::ModelTorqueSource torque = eval::scenario_model_torque(identification);
    return eval::identify_table(log, config, "simulator truth", &torque);
  }();
  return table;
}

enum class Served { kRsiClockAtMotion, kRsiClockWithStream, kEgm };

// The offsets of `table` along `path` as the RSI server answers them (the path loaded, its clock
// started at the motion or, with the path recorded from the stream's start, with the stream), or
// as the EGM server does (the path, with the warm-up's rest first, played by the server).

eval::CompensationRun through_sockets(const ident::ParameterTable& table,
                                      const sim::DesiredJointPath& path,
                                      const eval::CompensationOptions& options, Served served) {
  const bool clock_from_stream = served != Served::kRsiClockAtMotion;
  online::LoadedPath loaded;
  loaded.cycle_s = path.cycle_s;
  std::vector<calib::JointVector> torque;
  if (options.model_torque) torque = eval::model_torques_along(*options.model_torque, path);
  for (std::size_t k = 0; k < path.samples.size(); ++k) {
    std::array<double, online::kPathJoints> q{}, tau{};
    for (int j = 0; j < online::kPathJoints; ++j) {
      q[std::size_t(j)] = path.samples[k].q_rad[j];
      if (!torque.empty()) tau[std::size_t(j)] = torque[k][j];
    }
    loaded.q_rad.push_back(q);
    if (!torque.empty()) loaded.torque_nm.push_back(tau);
    loaded.payload_kg.push_back(
        path.payloads.empty()
            ? 0.0
            : path.payloads[std::size_t(path.samples[k].payload_index)].body.mass_kg);
  }
  const double ahead_s = (table.preview_cycles + options.look_ahead_cycles) * table.sample_time_s;
  // The warm-up as in process: the start pose for warm_up_cycles, then the path.
  const std::size_t warm_up = std::size_t(std::max(0, options.warm_up_cycles));
  std::vector<std::array<double, online::kRsiAxes>> setpoint(warm_up, loaded.q_rad.front());
  setpoint.insert(setpoint.end(), loaded.q_rad.begin(), loaded.q_rad.end());
  online::PathFollowerOptions follow;
  follow.clock_from_first_datagram = clock_from_stream;
  if (clock_from_stream) {  // the recording starts with the stream: the warm-up's rest first
    loaded.q_rad = setpoint;
    if (!loaded.torque_nm.empty())
      loaded.torque_nm.insert(loaded.torque_nm.begin(), warm_up, loaded.torque_nm.front());
    loaded.payload_kg.insert(loaded.payload_kg.begin(), warm_up, loaded.payload_kg.front());
  }
  std::unique_ptr<test_support::LoopbackServer> server;
  online::EmulatorOptions emulator;
  emulator.cycle_s = path.cycle_s;
  if (served == Served::kEgm) {
    online::EgmSessionOptions session;
    session.cycle_s = path.cycle_s;
    server = std::make_unique<test_support::LoopbackServer>(table, options.precontrol, session,
                                                            loaded, ahead_s);
    emulator.protocol = online::ControllerProtocol::kEgm;
    emulator.ipoc_per_cycle = 1;
  } else {
    auto follower = std::make_unique<online::PathFollower>(loaded, path.cycle_s, ahead_s, follow);
    online::RsiSessionOptions session;
    session.cycle_s = path.cycle_s;
    session.ipoc_per_cycle = 2;
    server = std::make_unique<test_support::LoopbackServer>(table, options.precontrol, session,
                                                            std::move(follower));
    emulator.ipoc_per_cycle = 2;
  }
  online::UdpSocket controller("127.0.0.1", 0);
  const online::EmulatorRun run =
      online::emulate_controller(controller, server->peer(), setpoint, emulator);
  server->finish();
  eval::CompensationRun out;
  for (std::size_t k = 0; k < path.samples.size(); ++k) {
    const auto& c = run.correction_rad[warm_up + k];
    out.offset_rad.push_back(Eigen::Map<const Eigen::VectorXd>(c.data(), 6));
    out.state.push_back(ident::PrecontrolState::kActive);
    out.outside_table.push_back(false);
  }
  if (run.missed > 0) std::printf("through sockets: %zu datagrams not answered\n", run.missed);
  return out;
}

void compare(benchmark::State& state, const char* scenario_name) {
  const sim::Scenario scenario = sim::load_scenario(sim::resolve_scenario(scenario_name));
  eval::VerificationOptions options;
  options.cycles = 3;
  options.measure_with_ims = false;
  const std::vector<eval::NamedTable> tables{{"default", default_table().table}};
  auto reduction = [](const eval::VerificationResult& r) {
    return eval::reduction_percent(r.before.true_figures.max_path_deviation_m,
                                   r.after[0].true_figures.max_path_deviation_m);
  };
  double in_process = 0.0, at_motion = 0.0, with_stream = 0.0, egm = 0.0;
  for (auto _ : state) {
    in_process = reduction(eval::verify_scenario(scenario, tables, options));
    for (const Served served :
         {Served::kRsiClockAtMotion, Served::kRsiClockWithStream, Served::kEgm}) {
      options.compensation_runner = [served](const ident::ParameterTable& table, const std::string&,
                                             const sim::DesiredJointPath& path,
                                             const eval::CompensationOptions& compensation) {
        return through_sockets(table, path, compensation, served);
      };
      const double r = reduction(eval::verify_scenario(scenario, tables, options));
      (served == Served::kEgm                  ? egm
       : served == Served::kRsiClockWithStream ? with_stream
                                               : at_motion) = r;
    }
  }
  state.counters["in_process_reduction_percent"] = in_process;
  state.counters["sockets_clock_at_motion_reduction_percent"] = at_motion;
  state.counters["sockets_clock_with_stream_reduction_percent"] = with_stream;
  state.counters["at_motion_difference_pp"] = at_motion - in_process;
  state.counters["with_stream_difference_pp"] = with_stream - in_process;
  state.counters["sockets_egm_reduction_percent"] = egm;
  state.counters["egm_difference_pp"] = egm - in_process;
}

void BM_RsiSeedLineInProcessVsSockets(benchmark::State& state) {
  compare(state, "seed-line");
}
BENCHMARK(BM_RsiSeedLineInProcessVsSockets)->Unit(benchmark::kSecond)->Iterations(1);

void BM_RsiIso9283InProcessVsSockets(benchmark::State& state) {
  compare(state, "iso9283");
}
BENCHMARK(BM_RsiIso9283InProcessVsSockets)->Unit(benchmark::kSecond)->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
