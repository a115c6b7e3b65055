// The precontrol (ident/precontrol.hpp) under faults: 10^7 cycles (3·10^6 when the
// environment variable IMSCAL_SANITIZED is set: ASan/UBSan run 5-10x slower) of random valid
// and invalid inputs: smooth motions, NaN bursts, Inf, skipped and repeated cycle counters,
// jumps of the desired values (up to 1e300 rad, so that models overflow), operating points
// outside the table (too fast, payload out of range), payload steps, and re-activations at
// random times; for the 2 ms, 4 ms and 1 ms callers. Checked in every cycle: all offsets finite,
// no offset step above the rate limit. The supervisor's transitions are counted here from the
// returned states and compared with the event log (read every cycle; a deliberate overflow of
// the event ring checks that the lost events are counted). The counts are printed.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <random>
#include <string>

#include "ident/precontrol.hpp"
#include "tests/support/arx_systems.hpp"

namespace imscal::ident {
namespace {

bool sanitized() {
  return std::getenv("IMSCAL_SANITIZED") != nullptr;
}

constexpr double kSpeedUpper = 1.2;   // rad/s, the grid's upper speed bound
constexpr double kPayloadUpper = 16;  // kg

// 6 joints, 3 speed x 2 payload cells of random stable models (orders 4..8, dead time 0..3)
// whose static gains are 1 ± 0.3 %: the offsets reach the 5 mrad tolerance on large moves.
ParameterTable fault_table(std::mt19937_64& rng) {
  ParameterTable t;
  t.robot = "kr16";
  t.sample_time_s = 0.002;
  std::uniform_real_distribution<double> gain_error(-0.003, 0.003);
  for (int j = 0; j < 6; ++j) {
    JointParameters joint;
    joint.name = std::string(1, 'A').append(std::to_string(j + 1));
    joint.dimensions = {CellDimension{OperatingQuantity::kSpeed, {0.0, 0.2, 0.6, kSpeedUpper}},
                        CellDimension{OperatingQuantity::kPayload, {0.0, 8.0, kPayloadUpper}}};
    joint.backlash_l_rad = 2e-4;
    joint.backlash_lag_samples = static_cast<std::size_t>(j % 3);
    for (int c = 0; c < 6; ++c) {
      CellParameters cell;
      cell.bands = {c / 2, c % 2};
      const int na = 4 + (c + j) % 5, nb = 2 + c % 4;
      cell.structure = {na, nb, (c + 2 * j) % 4};
      const Eigen::VectorXd a =
          test_support::polynomial_from_poles(test_support::random_poles(na, rng));
      cell.a.assign(a.data(), a.data() + na);
      cell.b.assign(static_cast<std::size_t>(nb), (1.0 + a.sum()) * (1.0 + gain_error(rng)) / nb);
      joint.cells.push_back(cell);
    }
    t.joints.push_back(joint);
  }
  return t;
}

bool is_deactivation(PrecontrolCause cause) {
  return cause == PrecontrolCause::kOffsetTolerance || cause == PrecontrolCause::kRateTolerance ||
         cause == PrecontrolCause::kInvalidInput || cause == PrecontrolCause::kLostCycles;
}

struct Counts {
  long cycles = 0, active_cycles = 0, invalid_cycles = 0, skipped = 0, repeated = 0, jumps = 0,
       payload_steps = 0;
  long deactivations_seen = 0;   // Active -> FadingOut/Inactive, from the returned states
  long deactivation_events = 0;  // logged in a cycle that started active
  long events_while_inactive = 0;
  std::array<long, 8> by_cause{};
  long reactivations = 0, reactivation_events = 0;
  long outside_entries_seen = 0, outside_events = 0;
  long events_read = 0;
  double worst_step_ratio = 0.0;  // largest |Δ offset| / (rate limit · cycle)
};

// One random run of `cycles` calls of a precontrol with caller cycle `caller_s`.
void run(double caller_s, long cycles, std::uint64_t seed, Counts& n) {
  std::mt19937_64 rng(seed);
  const ParameterTable table = fault_table(rng);
  PrecontrolOptions options;  // defaults: 5 mrad, 0.5 rad/s, rate limit 0.2 rad/s, fade 0.2 s
  options.caller_cycle_s = caller_s;
  options.max_lost_cycles = 2;
  static Precontrol p;  // fixed state of a few 100 kB: not on the stack
  std::string why;
  ASSERT_TRUE(Precontrol::create(table, "kr16", options, &p, &why)) << why;
  const double step_limit = 0.2 * caller_s;

  std::uniform_real_distribution<double> unit(0.0, 1.0);
  auto chance = [&](double probability) { return unit(rng) < probability; };
  std::array<double, 6> centre{}, amplitude{}, omega{}, phase{};
  double payload = 5.0, jump = 0.0;
  long episode_left = 0;
  std::uint64_t counter = 0;
  int nan_burst = 0;
  PrecontrolState state = PrecontrolState::kActive;
  bool outside = false;
  std::array<double, 6> last{};
  PrecontrolEvent events[64];
  long inactive_for = 0;

  for (long k = 0; k < cycles; ++k) {
    if (episode_left-- <= 0) {  // a new motion: sines, some fast enough to leave the grid
      episode_left = 20 + static_cast<long>(unit(rng) * 3000);
      const double speed_scale = chance(0.2) ? 2.0 : 0.7;  // rad/s: 2 leaves the grid
      for (int j = 0; j < 6; ++j) {
        centre[j] = -1.0 + 2.0 * unit(rng);
        amplitude[j] = 0.5 * unit(rng);
        omega[j] = speed_scale * unit(rng) / std::max(amplitude[j], 0.05);
        phase[j] = 6.28 * unit(rng);
      }
      jump = 0.0;
    }
    if (chance(2e-4)) {  // payload step, sometimes outside [0, 16] kg
      payload = -4.0 + 24.0 * unit(rng);
      ++n.payload_steps;
    }
    if (chance(2e-4)) {  // a jump of the desired values: small, large, or overflowing
      const double size[] = {1e-3, 0.1, 3.0, 1e6, 1e300};
      // Two draws in two statements: the operands of one expression are evaluated in an order
      // that differs between compilers, and the run must be the same sequence everywhere.
      const double magnitude = size[static_cast<int>(unit(rng) * 5)];
      jump = magnitude * (chance(0.5) ? 1.0 : -1.0);
      ++n.jumps;
    }
    const double t = static_cast<double>(k) * caller_s;
    std::array<double, 6> q;
    for (int j = 0; j < 6; ++j)
      q[j] = centre[j] + jump + amplitude[j] * std::sin(omega[j] * t + phase[j]);
    double payload_in = payload;
    if (nan_burst == 0 && chance(1e-4)) nan_burst = 1 + static_cast<int>(unit(rng) * 50);
    if (nan_burst > 0) {
      --nan_burst;
      const int which = static_cast<int>(unit(rng) * 8);  // a joint, the payload, or all
      const double bad = chance(0.7) ? std::numeric_limits<double>::quiet_NaN()
                                     : (chance(0.5) ? 1.0 : -1.0) * HUGE_VAL;
      if (which < 6) q[which] = bad;
      if (which == 6) payload_in = bad;
      if (which == 7) q.fill(bad);
      ++n.invalid_cycles;
    }
    counter += 1;
    if (chance(2e-4)) {  // skipped cycles: 1..5 lost (<= 2 bridged), or a repeated counter
      if (chance(0.2)) {
        counter -= 1;
        ++n.repeated;
      } else {
        counter += 1 + static_cast<std::uint64_t>(unit(rng) * 5);
        ++n.skipped;
      }
    }
    // Re-activation by the caller at a random time once the compensation is off.
    if (state != PrecontrolState::kActive && inactive_for > 10 && chance(0.002)) {
      p.reactivate();
      ++n.reactivations;
      state = PrecontrolState::kActive;
      inactive_for = 0;
    }

    const PrecontrolOutput out = p.cycle(q, payload_in, counter);
    ++n.cycles;
    for (int j = 0; j < 6; ++j) {
      ASSERT_TRUE(std::isfinite(out.offset_rad[j])) << "cycle " << k << " joint " << j;
      const double step = std::abs(out.offset_rad[j] - last[j]);
      // The limiter adds at most rate_limit · cycle to the last output; rounding of that sum is
      // an ulp of the offset (< 1e-18 rad at these 1e-3 rad offsets).
      ASSERT_LE(step, step_limit + 1e-15) << "cycle " << k << " joint " << j;
      n.worst_step_ratio = std::max(n.worst_step_ratio, step / step_limit);
      last[j] = out.offset_rad[j];
    }
    const bool deactivated =
        state == PrecontrolState::kActive && out.state != PrecontrolState::kActive;
    n.deactivations_seen += deactivated;
    n.active_cycles += out.state == PrecontrolState::kActive;
    n.outside_entries_seen += out.outside_table && !outside;

    const int read = p.read_events(events, 64);
    n.events_read += read;
    int deactivation_events = 0;
    for (int i = 0; i < read; ++i) {
      const PrecontrolCause cause = events[i].cause;
      ++n.by_cause[static_cast<int>(cause)];
      if (cause == PrecontrolCause::kReactivated) {
        ++n.reactivation_events;
        continue;
      }
      if (cause == PrecontrolCause::kOutsideTable) {
        ++n.outside_events;
        ASSERT_EQ(events[i].cycle, counter);
        continue;
      }
      ASSERT_TRUE(is_deactivation(cause)) << to_string(cause);
      ASSERT_EQ(events[i].cycle, counter) << "cycle " << k;
      if (state == PrecontrolState::kActive) {
        ++deactivation_events;
      } else {
        ++n.events_while_inactive;
      }
    }
    // A cycle that starts active logs exactly one deactivation event iff it deactivates.
    ASSERT_EQ(deactivation_events, deactivated ? 1 : 0) << "cycle " << k;
    n.deactivation_events += deactivation_events;
    ASSERT_EQ(out.state, p.state());
    state = out.state;
    outside = out.outside_table;
    inactive_for = state == PrecontrolState::kActive ? 0 : inactive_for + 1;
    // Faded out completely: 0.2 s of fade plus the rate-limited way down from <= 5 mrad.
    if (inactive_for > static_cast<long>((0.2 + 5e-3 / 0.2) / caller_s) + 2) {
      for (int j = 0; j < 6; ++j) ASSERT_EQ(out.offset_rad[j], 0.0) << "cycle " << k;
    }
  }
  EXPECT_EQ(p.dropped_events(), 0u);  // read every cycle: nothing lost
}

TEST(PrecontrolFaults, RandomFaultsNeverStepAboveTheRateLimitAndEveryDeactivationIsLogged) {
  const long total = sanitized() ? 3'000'000 : 10'000'000;
  Counts n;
  // 80 % of the cycles with the 2 ms caller, 10 % each with 4 ms and 1 ms callers.
  run(0.002, total * 8 / 10, 1, n);
  if (HasFatalFailure()) return;
  run(0.004, total / 10, 2, n);
  if (HasFatalFailure()) return;
  run(0.001, total / 10, 3, n);
  if (HasFatalFailure()) return;
  std::printf(
      "cycles %ld (%ld active): invalid-input cycles %ld, skipped %ld, repeated counters %ld, "
      "jumps %ld, "
      "payload steps %ld\n"
      "deactivations seen %ld = logged %ld (offset %ld, rate %ld, invalid %ld, lost %ld events in "
      "all; %ld while already off)\n"
      "re-activations %ld = logged %ld; outside-table entries %ld = logged %ld; events read %ld; "
      "largest step %.6f x the rate limit\n",
      n.cycles, n.active_cycles, n.invalid_cycles, n.skipped, n.repeated, n.jumps, n.payload_steps,
      n.deactivations_seen, n.deactivation_events,
      n.by_cause[static_cast<int>(PrecontrolCause::kOffsetTolerance)],
      n.by_cause[static_cast<int>(PrecontrolCause::kRateTolerance)],
      n.by_cause[static_cast<int>(PrecontrolCause::kInvalidInput)],
      n.by_cause[static_cast<int>(PrecontrolCause::kLostCycles)], n.events_while_inactive,
      n.reactivations, n.reactivation_events, n.outside_entries_seen, n.outside_events,
      n.events_read, n.worst_step_ratio);
  EXPECT_EQ(n.deactivations_seen, n.deactivation_events);
  EXPECT_EQ(n.reactivations, n.reactivation_events);
  EXPECT_EQ(n.outside_entries_seen, n.outside_events);
  // Every fault kind happened (the run exercises what it claims), and the limiter was reached.
  for (PrecontrolCause cause : {PrecontrolCause::kOffsetTolerance, PrecontrolCause::kRateTolerance,
                                PrecontrolCause::kInvalidInput, PrecontrolCause::kLostCycles}) {
    EXPECT_GT(n.by_cause[static_cast<int>(cause)], 0) << to_string(cause);
  }
  EXPECT_GT(n.outside_events, 0);
  EXPECT_GT(n.reactivations, 10);
  EXPECT_GT(n.worst_step_ratio, 0.99);
  EXPECT_GT(n.active_cycles, n.cycles / 4);  // the compensation did run most of the time
}

TEST(PrecontrolFaults, EventRingOverflowCountsTheLostEvents) {
  // Nobody reads the events during a NaN burst longer than the ring: each invalid cycle logs
  // one event, the ring keeps the newest kPrecontrolEventCapacity, the rest are counted.
  std::mt19937_64 rng(9);
  static Precontrol p;
  std::string why;
  ASSERT_TRUE(Precontrol::create(fault_table(rng), "kr16", PrecontrolOptions{}, &p, &why)) << why;
  std::array<double, 6> q{};
  p.cycle(q, 5.0, 0);
  const long burst = 3 * kPrecontrolEventCapacity + 17;
  q[4] = std::numeric_limits<double>::quiet_NaN();
  for (long k = 1; k <= burst; ++k) p.cycle(q, 5.0, static_cast<std::uint64_t>(k));
  PrecontrolEvent events[2 * kPrecontrolEventCapacity];
  const int read = p.read_events(events, 2 * kPrecontrolEventCapacity);
  std::printf("burst of %ld invalid cycles: %d events kept, %llu dropped\n", burst, read,
              static_cast<unsigned long long>(p.dropped_events()));
  ASSERT_EQ(read, kPrecontrolEventCapacity);
  EXPECT_EQ(static_cast<long>(p.dropped_events()), burst - kPrecontrolEventCapacity);
  for (int i = 0; i < read; ++i) {  // the newest, oldest first
    EXPECT_EQ(events[i].cause, PrecontrolCause::kInvalidInput);
    EXPECT_EQ(static_cast<long>(events[i].cycle), burst - kPrecontrolEventCapacity + 1 + i);
  }
}

}  // namespace
}  // namespace imscal::ident
