// Faults through the sockets: the controller emulator (online/controller_emulator.hpp) injects
// each fault of the stream into a 4 ms lock-step run (a dropped, duplicated, swapped, malformed,
// NaN, jumping, late datagram, a wrong robot), for KUKA RSI in absolute and increment mode and
// for ABB EGM (position guidance: the server plays the same path, NaN and the jump are in the
// measured joints).
// Checked from the controller's side: the corrections fade out to exactly zero after each fault,
// come back after it (equal to those of an undisturbed run), and the commanded correction never
// steps by more than the rate limit per cycle; from the server's side: each fault is logged with
// its kind.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "online/controller_emulator.hpp"
#include "tests/support/lag_table.hpp"
#include "tests/support/loopback_server.hpp"

namespace imscal::online {
namespace {

constexpr double kCycle = 0.004;
constexpr double kRateLimit = 0.2;          // rad/s
constexpr std::size_t kFaultSpacing = 400;  // 1.6 s: fade 0.2 + wait 0.5 + engage 0.4, and more

// q̂(k) = 0.9 q̂(k-1) + 0.1 q_d(k-1) at 2 ms (the RSI cycle runs two model steps per call).
ident::ParameterTable lag_table() {
  return test_support::lag_table(-0.9, 0.1);
}

ident::PrecontrolOptions precontrol_options() {
  ident::PrecontrolOptions o;
  o.offset_tolerance_rad.fill(0.05);
  o.rate_tolerance_rad_s.fill(5.0);
  o.rate_limit_rad_s.fill(kRateLimit);
  o.max_input_speed_rad_s = 5.0;  // the 5 degree jump in 4 ms is 22 rad/s
  return o;
}

// Joint j swings sinusoidally (amplitude 0.1 rad, period 2 + j/2 s): offsets of ~1..2 mrad
// changing sign, so a held or stuck correction would show.
std::vector<std::array<double, kRsiAxes>> swinging_path(std::size_t cycles) {
  std::vector<std::array<double, kRsiAxes>> q(cycles);
  for (std::size_t k = 0; k < cycles; ++k)
    for (int j = 0; j < kRsiAxes; ++j)
      q[k][std::size_t(j)] = 0.1 * std::sin(2.0 * M_PI * double(k) * kCycle / (2.0 + 0.5 * j));
  return q;
}

struct FaultRun {
  EmulatorRun run;
  std::vector<SessionFaultEvent> faults;
  std::vector<ident::PrecontrolEvent> events;
};

struct Case {
  ControllerProtocol protocol;
  RsiCorrectionMode mode;
};

// The server of the case's protocol. Lock-step datagrams come every ~0.1 ms; the late one 0.6 s
// late. A threshold far above any scheduling stall of a loaded (sanitizer) machine: no false late
// datagram in the clean run.
std::unique_ptr<test_support::LoopbackServer> server_for(const Case& c, std::size_t cycles) {
  if (c.protocol == ControllerProtocol::kEgm) {
    EgmSessionOptions session;
    session.cycle_s = kCycle;
    session.late_after_s = 0.3;
    LoadedPath path;
    path.cycle_s = kCycle;
    path.q_rad = swinging_path(cycles);
    return std::make_unique<test_support::LoopbackServer>(lag_table(), precontrol_options(),
                                                          session, std::move(path), 0.0);
  }
  RsiSessionOptions session;
  session.mode = c.mode;
  session.cycle_s = kCycle;
  session.robot_type = "KUKA";
  session.late_after_s = 0.3;
  return std::make_unique<test_support::LoopbackServer>(lag_table(), precontrol_options(), session);
}

FaultRun run_with(const std::map<std::size_t, InjectedFault>& faults, const Case& c,
                  std::size_t cycles) {
  const std::unique_ptr<test_support::LoopbackServer> owned = server_for(c, cycles);
  test_support::LoopbackServer& server = *owned;
  UdpSocket controller("127.0.0.1", 0);
  EmulatorOptions emulator;
  emulator.protocol = c.protocol;
  if (c.protocol == ControllerProtocol::kEgm) emulator.ipoc_per_cycle = 1;
  emulator.mode = c.mode;
  emulator.cycle_s = kCycle;
  emulator.faults = faults;
  emulator.late_delay_s = 0.6;
  emulator.answer_timeout_s = 5.0;  // a stalled server thread is not a missed answer here
  FaultRun out;
  out.run = emulate_controller(controller, server.peer(), swinging_path(cycles), emulator);
  server.finish();
  out.faults = server.faults();
  out.events = server.events();
  return out;
}

class InterfaceFaults : public ::testing::TestWithParam<Case> {};

TEST_P(InterfaceFaults, EachFaultFadesOutIsLoggedAndTheCorrectionComesBack) {
  const std::vector<InjectedFault> kinds{
      InjectedFault::kDrop,      InjectedFault::kDuplicate,   InjectedFault::kSwapWithNext,
      InjectedFault::kMalformed, InjectedFault::kNaN,         InjectedFault::kJump,
      InjectedFault::kLate,      InjectedFault::kUnknownRobot};
  std::map<std::size_t, InjectedFault> faults;
  for (std::size_t i = 0; i < kinds.size(); ++i) faults[(i + 1) * kFaultSpacing] = kinds[i];
  const std::size_t cycles = (kinds.size() + 1) * kFaultSpacing;
  const FaultRun disturbed = run_with(faults, GetParam(), cycles);
  const FaultRun clean = run_with({}, GetParam(), cycles);
  EXPECT_EQ(disturbed.run.missed, 0u);  // every datagram sent was answered (malformed: re-sent)
  EXPECT_EQ(clean.run.missed, 0u);

  const auto& c = disturbed.run.correction_rad;
  // Never a step of the commanded correction above the rate limit: 0.2 rad/s x 4 ms, plus the
  // written values' rounding (1e-6 degree each side).
  const double step_limit = kRateLimit * kCycle + 2e-6 * M_PI / 180.0;
  double largest_step = 0.0;
  for (std::size_t k = 1; k < c.size(); ++k)
    for (int j = 0; j < kRsiAxes; ++j)
      largest_step =
          std::max(largest_step, std::abs(c[k][std::size_t(j)] - c[k - 1][std::size_t(j)]));
  EXPECT_LE(largest_step, step_limit);

  for (const auto& [at, kind] : faults) {
    SCOPED_TRACE("fault " + std::to_string(int(kind)) + " at cycle " + std::to_string(at));
    // Before: as the undisturbed run (within the rounding of the written values).
    for (int j = 0; j < kRsiAxes; ++j)
      EXPECT_NEAR(c[at - 1][std::size_t(j)], clean.run.correction_rad[at - 1][std::size_t(j)],
                  1e-7);
    // Faded out: zero 0.2 s (50 cycles) after the fault, and a few cycles beyond (1e-12 rad:
    // the controller's floating-point sum of the written increments returns to 0 within ulps).
    for (std::size_t k = at + 55; k < at + 60; ++k)
      for (int j = 0; j < kRsiAxes; ++j) ASSERT_NEAR(c[k][std::size_t(j)], 0.0, 1e-12) << k;
    // Back: re-engaged (0.5 s + 0.4 s after the fade) and equal to the undisturbed run again.
    for (int j = 0; j < kRsiAxes; ++j) {
      double largest = 0.0;
      for (std::size_t k = at + kFaultSpacing - 100; k < at + kFaultSpacing; ++k) {
        largest = std::max(largest, std::abs(c[k][std::size_t(j)]));
        ASSERT_NEAR(c[k][std::size_t(j)], clean.run.correction_rad[k][std::size_t(j)], 1e-7) << k;
      }
      EXPECT_GT(largest, 1e-4);  // not compared at zero
    }
  }

  // The server's log names every fault (the precontrol logs NaN and the jump itself).
  // EGM: the server's own path feeds the precontrol; NaN and the jump are in the measured joints,
  // which the session judges.
  const bool egm = GetParam().protocol == ControllerProtocol::kEgm;
  std::set<SessionFault> logged;
  for (const SessionFaultEvent& f : disturbed.faults) logged.insert(f.fault);
  std::vector<SessionFault> expected{SessionFault::kMalformed, SessionFault::kLate,
                                     SessionFault::kLost,      SessionFault::kDuplicated,
                                     SessionFault::kReordered, SessionFault::kUnknownRobot};
  if (egm) expected.push_back(SessionFault::kBadFeedback);
  for (SessionFault f : expected) EXPECT_TRUE(logged.count(f)) << to_string(f);
  std::set<ident::PrecontrolCause> causes;
  for (const ident::PrecontrolEvent& e : disturbed.events) causes.insert(e.cause);
  std::vector<ident::PrecontrolCause> expected_causes{ident::PrecontrolCause::kLostCycles,
                                                      ident::PrecontrolCause::kCallerFault};
  if (!egm) {
    expected_causes.push_back(ident::PrecontrolCause::kInvalidInput);
    expected_causes.push_back(ident::PrecontrolCause::kInputJump);
  }
  for (ident::PrecontrolCause cause : expected_causes)
    EXPECT_TRUE(causes.count(cause)) << ident::to_string(cause);
  EXPECT_TRUE(clean.faults.empty());
}

TEST_P(InterfaceFaults, AnUnknownRobotIsNeverCorrected) {
  std::map<std::size_t, InjectedFault> faults;
  for (std::size_t k = 0; k < 600; ++k) faults[k] = InjectedFault::kUnknownRobot;
  const FaultRun run = run_with(faults, GetParam(), 600);
  EXPECT_EQ(run.run.missed, 0u);
  // RSI: exactly zero; EGM: the target minus the path, each through degrees (a few ulps).
  for (const auto& c : run.run.correction_rad)
    for (double v : c) ASSERT_NEAR(v, 0.0, 1e-15);
}

INSTANTIATE_TEST_SUITE_P(
    Protocols, InterfaceFaults,
    ::testing::Values(Case{ControllerProtocol::kRsi, RsiCorrectionMode::kAbsolute},
                      Case{ControllerProtocol::kRsi, RsiCorrectionMode::kIncrement},
                      Case{ControllerProtocol::kEgm, RsiCorrectionMode::kAbsolute}),
    [](const ::testing::TestParamInfo<Case>& info) {
      if (info.param.protocol == ControllerProtocol::kEgm) return std::string("Egm");
      return std::string(info.param.mode == RsiCorrectionMode::kAbsolute ? "RsiAbsolute"
                                                                         : "RsiIncrement");
    });

}  // namespace
}  // namespace imscal::online
