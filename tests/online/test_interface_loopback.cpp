// The RSI and EGM servers through real sockets and real serialisation, against the in-process
// closed loop (eval/closed_loop.hpp) as truth: the controller emulator
// (online/controller_emulator.hpp) plays the seed-line program over loopback UDP in lock-step
// (RSI: its set-points; EGM: the robot following the targets of the server, which plays the same
// program path), the robot simulator runs on q_d + the corrections it received, and the attained
// joints equal those of eval::run_closed_loop with the same precontrol; every datagram is
// answered.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "eval/closed_loop.hpp"
#include "online/controller_emulator.hpp"
#include "sim/plant_config.hpp"
#include "sim/scenario.hpp"
#include "tests/support/lag_table.hpp"
#include "tests/support/loopback_server.hpp"
#include "tests/support/seed_line_start.hpp"

namespace imscal::online {
namespace {

// Every joint: q̂(k) = 0.5 q̂(k-1) + 0.5 q_d(k-1), one cell: the joint lags its command by about
// two cycles, a few mrad on the program's moves.
ident::ParameterTable lag_table() {
  return test_support::lag_table(-0.5, 0.5);
}

ident::PrecontrolOptions precontrol_options() {
  ident::PrecontrolOptions o;
  o.offset_tolerance_rad.fill(0.05);  // the lag on the program's fastest moves stays below
  o.rate_tolerance_rad_s.fill(5.0);
  o.auto_engage = true;  // as the server runs it
  return o;
}

class Loopback : public ::testing::TestWithParam<ControllerProtocol> {};

TEST_P(Loopback, ClosedLoopThroughSocketsEqualsTheInProcessLoop) {
  const bool egm = GetParam() == ControllerProtocol::kEgm;
  const test_support::SeedLineStart line =
      test_support::seed_line_until(test_support::seed_line_move_s());
  const sim::Scenario& scenario = line.scenario;
  const calib::RobotDescription& robot = line.robot;
  const sim::DesiredJointPath& path = line.path;
  ASSERT_EQ(path.cycle_s, 0.002);

  // In process: the precontrol settled at the start pose over the engagement (0.4 s) first.
  constexpr int kWarmUp = 250;
  eval::CompensationOptions options;
  options.precontrol = precontrol_options();
  options.warm_up_cycles = kWarmUp;
  const sim::PlantConfig config = sim::make_plant_config(robot, scenario);
  const eval::ClosedLoopRun in_process =
      eval::run_closed_loop(path, lag_table(), "kr16", eval::simulator_plant(config), options);

  // Through the sockets: the same warm-up at the first set-point, then the path.
  std::vector<std::array<double, kRsiAxes>> setpoint(kWarmUp + path.samples.size());
  for (std::size_t k = 0; k < setpoint.size(); ++k) {
    const Eigen::VectorXd& q = path.samples[k < kWarmUp ? 0 : k - kWarmUp].q_rad;
    for (int a = 0; a < kRsiAxes; ++a) setpoint[k][std::size_t(a)] = q[a];
  }
  std::unique_ptr<test_support::LoopbackServer> owned;
  if (egm) {
    EgmSessionOptions session;
    session.cycle_s = path.cycle_s;
    LoadedPath played;
    played.cycle_s = path.cycle_s;
    played.q_rad = setpoint;
    owned = std::make_unique<test_support::LoopbackServer>(lag_table(), precontrol_options(),
                                                           session, std::move(played), 0.0);
  } else {
    RsiSessionOptions session;
    session.cycle_s = path.cycle_s;
    session.ipoc_per_cycle = 2;
    owned =
        std::make_unique<test_support::LoopbackServer>(lag_table(), precontrol_options(), session);
  }
  test_support::LoopbackServer& server = *owned;
  UdpSocket controller("127.0.0.1", 0);
  EmulatorOptions emulator;
  emulator.protocol = GetParam();
  emulator.cycle_s = path.cycle_s;
  emulator.ipoc_per_cycle = egm ? 1 : 2;
  emulator.answer_timeout_s = 5.0;  // a stalled server thread (loaded machine) is not a miss
  const EmulatorRun run = emulate_controller(controller, server.peer(), setpoint, emulator);
  server.finish();
  EXPECT_EQ(run.missed, 0u);
  EXPECT_EQ(server.stats().answered, setpoint.size());

  // The corrections: RSI's set-points travel with 6 decimals of a degree (8.7e-9 rad) and so do
  // the answers; through this two-cycle model that is < 3e-8 rad. EGM's travel as doubles.
  std::vector<calib::JointVector> offsets(path.samples.size());
  double largest_offset = 0.0, largest_difference = 0.0;
  for (std::size_t k = 0; k < path.samples.size(); ++k) {
    offsets[k].resize(6);
    for (int j = 0; j < 6; ++j) {
      offsets[k][j] = run.correction_rad[k + kWarmUp][std::size_t(j)];
      largest_offset = std::max(largest_offset, std::abs(in_process.compensation.offset_rad[k][j]));
      largest_difference = std::max(
          largest_difference, std::abs(offsets[k][j] - in_process.compensation.offset_rad[k][j]));
    }
  }
  EXPECT_GT(largest_offset, 1e-3);  // the comparison is not between zeros
  EXPECT_LT(largest_difference, 3e-8);

  // The robot on the corrections it received: the attained joints as in process (the plant is
  // smooth in its command: differences of the order of the corrections' 3e-8 rad).
  const sim::PlantLog through_sockets =
      eval::simulator_plant(config)(eval::command_path(path, offsets));
  const auto errors_sockets = eval::joint_errors(path, through_sockets);
  const auto errors_in_process = eval::joint_errors(path, in_process.compensated);
  double largest_gap = 0.0;
  for (std::size_t k = 0; k < errors_sockets.size(); ++k) {
    largest_gap =
        std::max(largest_gap, (errors_sockets[k] - errors_in_process[k]).cwiseAbs().maxCoeff());
  }
  EXPECT_LT(largest_gap, 1e-7);
  std::printf(
      "largest correction %.3g rad; sockets vs in process: %.3g rad (corrections), "
      "%.3g rad (attained joints)\n",
      largest_offset, largest_difference, largest_gap);
}

INSTANTIATE_TEST_SUITE_P(Protocols, Loopback,
                         ::testing::Values(ControllerProtocol::kRsi, ControllerProtocol::kEgm),
                         [](const ::testing::TestParamInfo<ControllerProtocol>& info) {
                           return std::string(info.param == ControllerProtocol::kEgm ? "Egm"
                                                                                     : "Rsi");
                         });

}  // namespace
}  // namespace imscal::online
