// The precontrol's engagement (ident/precontrol.hpp, PrecontrolOptions::auto_engage) on a stream
// that starts in the middle of a motion, and its re-engagement after a fault. Truth: a
// precontrol that saw the same motion from standstill; a stable model forgets its start state,
// so once engaged the offsets of the two agree.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <vector>

#include "ident/precontrol.hpp"

namespace imscal::ident {
namespace {

constexpr double kCycle = 0.002;
constexpr double kPole = 0.9;  // q̂(k) = 0.9 q̂(k-1) + 0.1 q_d(k-1): a lag of 9 cycles

ParameterTable lag_table() {
  ParameterTable t;
  t.robot = "kr16";
  t.sample_time_s = kCycle;
  for (int j = 0; j < 6; ++j) {
    JointParameters joint;
    joint.name = std::string(1, 'A').append(std::to_string(j + 1));
    joint.dimensions = {CellDimension{OperatingQuantity::kSpeed, {0.0, 2.0}}};
    CellParameters cell;
    cell.structure = {1, 1, 1};
    cell.a = {-kPole};
    cell.b = {1.0 - kPole};
    cell.bands = {0};
    joint.cells = {cell};
    t.joints.push_back(joint);
  }
  return t;
}

// The tolerances of a table identified on slow motions: offsets to 5 mrad and their rate to
// 0.05 rad/s (the restart transient mid-motion rises faster than that); rate limit 0.2 rad/s.
PrecontrolOptions options(bool auto_engage) {
  PrecontrolOptions o;
  o.caller_cycle_s = kCycle;
  o.offset_tolerance_rad.fill(5e-3);
  o.rate_tolerance_rad_s.fill(0.05);
  o.rate_limit_rad_s.fill(0.2);
  o.auto_engage = auto_engage;
  return o;
}

std::unique_ptr<Precontrol> make(const PrecontrolOptions& o) {
  auto p = std::make_unique<Precontrol>();
  std::string why;
  EXPECT_TRUE(Precontrol::create(lag_table(), "kr16", o, p.get(), &why)) << why;
  return p;
}

// Joint j accelerates from rest at cycle 100 to 0.02 (j + 1) rad/s within 0.5 s and keeps that
// speed: 0.4 .. 2.4 mrad of lag, reached slowly enough (< 0.005 rad/s) for the rate tolerance.
std::array<double, 6> desired(int k) {
  const double t = std::max(0, k - 100) * kCycle, ramp_s = 0.5;
  const double travel_s = t < ramp_s ? t * t / (2.0 * ramp_s) : t - ramp_s / 2.0;
  std::array<double, 6> q{};
  for (int j = 0; j < 6; ++j) q[std::size_t(j)] = 0.1 + 0.02 * (j + 1) * travel_s;
  return q;
}

struct Stream {
  std::vector<std::array<double, 6>> offset;
  std::vector<PrecontrolState> state;
  double largest_step_rad = 0.0;
};

// Cycles [first, last) into p; `nan_at` (if >= 0) gets a NaN set-point.
Stream run(Precontrol& p, int first, int last, int nan_at = -1) {
  Stream s;
  std::array<double, 6> previous{};
  for (int k = first; k < last; ++k) {
    std::array<double, 6> q = desired(k);
    if (k == nan_at) q[2] = std::numeric_limits<double>::quiet_NaN();
    const PrecontrolOutput out = p.cycle(q, 0.0, std::uint64_t(k));
    for (int j = 0; j < 6; ++j) {
      const double step = std::abs(out.offset_rad[std::size_t(j)] - previous[std::size_t(j)]);
      s.largest_step_rad = std::max(s.largest_step_rad, step);
    }
    previous = out.offset_rad;
    s.offset.push_back(out.offset_rad);
    s.state.push_back(out.state);
  }
  return s;
}

TEST(PrecontrolEngagement, WithoutEngagementAMidMotionStartSwitchesOffForGood) {
  // The behaviour `imscal compensate` had on logs that start mid-motion: the models restart at
  // rest, their transient trips the rate tolerance at once, and nothing brings them back.
  auto p = make(options(false));
  const Stream s = run(*p, 1000, 2000);
  const auto first_off = std::find_if(s.state.begin(), s.state.end(),
                                      [](auto st) { return st != PrecontrolState::kActive; });
  ASSERT_NE(first_off, s.state.end());
  EXPECT_LT(first_off - s.state.begin(), 10);  // within 20 ms
  EXPECT_EQ(s.state.back(), PrecontrolState::kInactive);
}

TEST(PrecontrolEngagement, MidMotionStartEngagesSmoothlyAndMatchesAStartFromRest) {
  auto reference = make(options(false));
  const Stream truth = run(*reference, 0, 2000);
  ASSERT_EQ(truth.state.back(), PrecontrolState::kActive);  // from rest it never trips

  auto p = make(options(true));
  const Stream s = run(*p, 1000, 2000);
  // Settle 0.2 s + fade-in 0.2 s = 200 cycles; active from then on, never off.
  EXPECT_EQ(s.state[10], PrecontrolState::kEngaging);
  for (std::size_t k = 201; k < s.state.size(); ++k)
    ASSERT_EQ(s.state[k], PrecontrolState::kActive) << k;
  // Never a step above the rate limit (0.2 rad/s x 2 ms; 1e-15: rounding of the clamp).
  EXPECT_LE(s.largest_step_rad, 0.2 * kCycle + 1e-15);
  // After engagement the offsets equal those of the precontrol that saw the whole motion: the
  // models' start states differ by 0.9^300 ~ 2e-14 of the lag (~1.7e-3 rad) after 300 cycles.
  for (std::size_t k = 300; k < s.offset.size(); ++k)
    for (int j = 0; j < 6; ++j)
      ASSERT_NEAR(s.offset[k][std::size_t(j)], truth.offset[k + 1000][std::size_t(j)], 1e-12) << k;
}

TEST(PrecontrolEngagement, ReEngagesAfterAFaultOnceTheInputIsValidAgain) {
  auto reference = make(options(false));
  const Stream truth = run(*reference, 0, 3000);
  auto p = make(options(true));
  const Stream s = run(*p, 0, 3000, /*nan_at=*/1000);
  EXPECT_EQ(s.state[999], PrecontrolState::kActive);
  EXPECT_EQ(s.state[1000], PrecontrolState::kFadingOut);
  // Fade-out 0.2 s (100 cycles), inactive for reengage_after_s = 0.5 s (250 cycles), engaging
  // 0.4 s (200 cycles): active again from cycle ~1550.
  EXPECT_EQ(s.state[1200], PrecontrolState::kInactive);
  EXPECT_EQ(s.state[1400], PrecontrolState::kEngaging);
  for (std::size_t k = 1560; k < s.state.size(); ++k)
    ASSERT_EQ(s.state[k], PrecontrolState::kActive) << k;
  EXPECT_LE(s.largest_step_rad, 0.2 * kCycle + 1e-15);
  for (std::size_t k = 2000; k < s.offset.size(); ++k)
    for (int j = 0; j < 6; ++j)
      ASSERT_NEAR(s.offset[k][std::size_t(j)], truth.offset[k][std::size_t(j)], 1e-12) << k;
  // The log tells the story: engaged, NaN, the counter's gap it left, engaging again, engaged.
  std::array<PrecontrolEvent, kPrecontrolEventCapacity> events{};
  const int n = p->read_events(events.data(), int(events.size()));
  std::vector<PrecontrolCause> causes;
  for (int i = 0; i < n; ++i) causes.push_back(events[std::size_t(i)].cause);
  const std::vector<PrecontrolCause> expected{
      PrecontrolCause::kEngaging,   PrecontrolCause::kEngaged,  PrecontrolCause::kInvalidInput,
      PrecontrolCause::kLostCycles, PrecontrolCause::kEngaging, PrecontrolCause::kEngaged};
  EXPECT_EQ(causes, expected);
}

TEST(PrecontrolEngagement, CallerFaultsKeepItOffAndAJumpIsAFault) {
  PrecontrolOptions o = options(true);
  o.max_input_speed_rad_s = 1.0;
  auto p = make(o);
  run(*p, 0, 600);
  ASSERT_EQ(p->state(), PrecontrolState::kActive);
  // A set-point jump of 10 mrad in one cycle (5 rad/s) fades out.
  std::array<double, 6> q = desired(600);
  q[0] += 0.01;
  EXPECT_EQ(p->cycle(q, 0.0, 600).state, PrecontrolState::kFadingOut);
  // A caller reporting a fault every cycle keeps it from re-engaging.
  for (int k = 601; k < 1500; ++k) {
    p->fault(std::uint64_t(k), 7.0);
    ASSERT_NE(p->cycle(desired(k), 0.0, std::uint64_t(k)).state, PrecontrolState::kEngaging) << k;
  }
  EXPECT_EQ(p->state(), PrecontrolState::kInactive);
}

}  // namespace
}  // namespace imscal::ident
