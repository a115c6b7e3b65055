// The program's desired path loaded into the RSI server (online/path_follower.hpp): the follower
// waits at the start pose, follows the IPOC, notices a set-point off the path and re-arms at the
// start pose; through the sockets a table with a preview gets the path ahead of the set-point,
// and its corrections equal the in-process loop's (eval::run_closed_loop, which feeds q_d(k + P)
// from the planned path) once the start of the motion, whose preview the server cannot know, has
// left the model's memory.
#include <gtest/gtest.h>

#include <cmath>

#include "eval/closed_loop.hpp"
#include "online/controller_emulator.hpp"
#include "online/path_follower.hpp"
#include "sim/plant_config.hpp"
#include "tests/support/lag_table.hpp"
#include "tests/support/loopback_server.hpp"
#include "tests/support/seed_line_start.hpp"

namespace imscal::online {
namespace {

// Joint 0 rests for 10 samples at 0, then moves at 0.001 rad per sample; the others rest.
LoadedPath ramp_path(std::size_t n) {
  LoadedPath p;
  p.cycle_s = 0.002;
  for (std::size_t k = 0; k < n; ++k) {
    std::array<double, kPathJoints> q{};
    q[0] = k < 10 ? 0.0 : 0.001 * double(k - 9);
    p.q_rad.push_back(q);
  }
  return p;
}

TEST(PathFollower, WaitsFollowsNoticesADepartureAndReArms) {
  // RSI at 4 ms on a 2 ms path, preview 10 samples (20 ms).
  PathFollower f(ramp_path(200), 0.004, 0.020);
  PathSample s;
  std::array<double, kPathJoints> q{};
  for (int k = 0; k < 5; ++k) {
    ASSERT_TRUE(f.step(q, 1, &s));
    EXPECT_EQ(f.state(), PathFollowerState::kWaiting);
    EXPECT_EQ(s.q_rad[0], 0.0);  // the start pose while waiting
  }
  q[0] = 0.001;  // the robot leaves: the path's sample 10
  ASSERT_TRUE(f.step(q, 1, &s));
  EXPECT_EQ(f.index(), 10u);
  EXPECT_DOUBLE_EQ(s.q_rad[0], 0.011);  // 10 samples ahead
  q[0] = 0.003;                         // one RSI cycle later: 2 samples
  ASSERT_TRUE(f.step(q, 1, &s));
  EXPECT_EQ(f.index(), 12u);
  q[0] = 0.007;  // two cycles lost: 4 samples
  ASSERT_TRUE(f.step(q, 2, &s));
  EXPECT_EQ(f.index(), 16u);
  q[0] = 0.5;  // far off the path: lost until back at the start pose
  EXPECT_FALSE(f.step(q, 1, &s));
  q[0] = 0.011;
  EXPECT_FALSE(f.step(q, 1, &s));
  EXPECT_EQ(f.state(), PathFollowerState::kLost);
  q[0] = 0.0;
  EXPECT_TRUE(f.step(q, 1, &s));
  EXPECT_EQ(f.state(), PathFollowerState::kWaiting);
}

TEST(PathFollower, WithTheStreamsClockThePreviewSeesTheFirstMotionComing) {
  PathFollowerOptions options;
  options.clock_from_first_datagram = true;
  PathFollower f(ramp_path(200), 0.004, 0.020, options);
  PathSample s;
  std::array<double, kPathJoints> q{};
  ASSERT_TRUE(f.step(q, 1, &s));  // the first datagram: the path's sample 0
  EXPECT_EQ(f.state(), PathFollowerState::kFollowing);
  EXPECT_EQ(f.index(), 0u);
  EXPECT_DOUBLE_EQ(s.q_rad[0], 0.001);  // sample 10: the motion 20 ms ahead, still at rest now
  ASSERT_TRUE(f.step(q, 1, &s));
  EXPECT_EQ(f.index(), 2u);
  EXPECT_DOUBLE_EQ(s.q_rad[0], 0.003);
  q[0] = 0.5;  // off the path: lost as with the motion's clock
  EXPECT_FALSE(f.step(q, 1, &s));
}

TEST(PathFollower, RefusesCyclesThatAreNotWholeSamples) {
  EXPECT_THROW(PathFollower(ramp_path(10), 0.003, 0.0), std::invalid_argument);
  EXPECT_THROW(PathFollower(ramp_path(10), 0.004, 0.001), std::invalid_argument);
  EXPECT_THROW(PathFollower(LoadedPath{}, 0.004, 0.0), std::invalid_argument);
}

// q̂(k) = 0.5 q̂(k-1) + 0.5 x(k-1) with x = q_d(k + 20): an inverse-form table with a preview.
ident::ParameterTable preview_table() {
  ident::ParameterTable t = test_support::lag_table(-0.5, 0.5);
  t.model_form = ident::TableForm::kInverse;
  t.preview_cycles = 20;
  return t;
}

TEST(RsiPath, APreviewTableThroughSocketsGetsThePathAhead) {
  const test_support::SeedLineStart line =
      test_support::seed_line_until(test_support::seed_line_move_s());
  const sim::DesiredJointPath& path = line.path;

  ident::PrecontrolOptions precontrol;
  precontrol.offset_tolerance_rad.fill(0.05);
  precontrol.rate_tolerance_rad_s.fill(5.0);
  precontrol.auto_engage = true;
  constexpr std::size_t kWarmUp = 250;
  eval::CompensationOptions options;
  options.precontrol = precontrol;
  options.warm_up_cycles = int(kWarmUp);
  const eval::CompensationRun in_process =
      eval::run_precontrol(preview_table(), "kr16", path, options);

  LoadedPath loaded;
  loaded.cycle_s = path.cycle_s;
  std::vector<std::array<double, kRsiAxes>> setpoint(kWarmUp + path.samples.size());
  for (std::size_t k = 0; k < path.samples.size(); ++k) {
    std::array<double, kPathJoints> q{};
    for (int j = 0; j < kPathJoints; ++j) q[std::size_t(j)] = path.samples[k].q_rad[j];
    loaded.q_rad.push_back(q);
    setpoint[kWarmUp + k] = q;
  }
  for (std::size_t k = 0; k < kWarmUp; ++k) setpoint[k] = loaded.q_rad[0];
  RsiSessionOptions session;
  session.cycle_s = path.cycle_s;
  session.ipoc_per_cycle = 2;
  auto follower = std::make_unique<PathFollower>(loaded, path.cycle_s, 20 * 0.002);
  test_support::LoopbackServer server(preview_table(), precontrol, session, std::move(follower));
  UdpSocket controller("127.0.0.1", 0);
  EmulatorOptions emulator;
  emulator.cycle_s = path.cycle_s;
  emulator.ipoc_per_cycle = 2;
  emulator.answer_timeout_s = 5.0;  // a stalled server thread (loaded machine) is not a miss
  const EmulatorRun run = emulate_controller(controller, server.peer(), setpoint, emulator);
  server.finish();
  EXPECT_EQ(run.missed, 0u);
  EXPECT_TRUE(server.faults().empty());

  // Where the set-point leaves the start pose (the follower's rest tolerance).
  std::size_t moving = 0;
  while (moving < loaded.q_rad.size() &&
         std::abs(loaded.q_rad[moving][0] - loaded.q_rad[0][0]) <= 1e-4 &&
         std::abs(loaded.q_rad[moving][1] - loaded.q_rad[0][1]) <= 1e-4)
    ++moving;
  ASSERT_LT(moving + 200, loaded.q_rad.size());
  // From 100 cycles after it (the model forgets the missed start by 0.5^100), the corrections
  // equal the in-process ones within the written values' rounding (see test_interface_loopback).
  double largest = 0.0, largest_difference = 0.0;
  for (std::size_t k = moving + 100; k < path.samples.size(); ++k) {
    for (int j = 0; j < 6; ++j) {
      const double expected = in_process.offset_rad[k][j];
      largest = std::max(largest, std::abs(expected));
      largest_difference = std::max(
          largest_difference, std::abs(run.correction_rad[kWarmUp + k][std::size_t(j)] - expected));
    }
  }
  EXPECT_GT(largest, 1e-3);
  EXPECT_LT(largest_difference, 3e-8);
  std::printf(
      "motion starts at cycle %zu; from 100 cycles later: largest correction %.3g rad, "
      "sockets vs in process %.3g rad\n",
      moving, largest, largest_difference);
}

}  // namespace
}  // namespace imscal::online
