// The online precontrol (ident/precontrol.hpp) against an independent truth: with one cell, no
// smoothing and no backlash its offsets equal the offline free-run prediction of the same ARX
// model (ArxModel::predict_joint_error); blending is continuous; backlash does not chatter; the
// supervisor and every fault of the runtime list have their defined reaction; no heap
// allocation happens inside a cycle.
// GCC 12 flags the malloc/free pair of the counting operator new (tests/support/
// allocation_counter.hpp) at every inlined std::allocator use in this file (a false positive).
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"

#include "ident/joint_identification.hpp"
#include "ident/precontrol.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <new>
#include <random>
#include <vector>

#include "ident/arx_model.hpp"
#include "tests/support/allocation_counter.hpp"
#include "tests/support/arx_systems.hpp"
#include "tests/support/reference_precontrol.hpp"

namespace imscal::ident {
namespace {

constexpr double kCycle = 0.002;

// A stable second-order ARX with static gain 1 (poles 0.9 ± 0.05i), nb = 2, dead time 3.
CellParameters cell(double gain_error = 0.0) {
  CellParameters c;
  c.structure = {2, 2, 3};
  c.a = {-1.8, 0.8125};  // A(z) = z^2 - 1.8 z + 0.8125
  const double a_sum = 1.0 - 1.8 + 0.8125;
  c.b = {0.6 * a_sum * (1.0 + gain_error), 0.4 * a_sum * (1.0 + gain_error)};
  return c;
}

// Every joint: the given cells along joint speed with the given band bounds [rad/s].
ParameterTable table(const std::vector<CellParameters>& cells, std::vector<double> bounds,
                     double backlash = 0.0) {
  ParameterTable t;
  t.robot = "kr16";
  t.sample_time_s = kCycle;
  for (int j = 0; j < 6; ++j) {
    JointParameters joint;
    joint.name = "A" + std::to_string(j + 1);
    joint.dimensions = {CellDimension{OperatingQuantity::kSpeed, bounds}};
    joint.cells = cells;
    for (std::size_t c = 0; c < cells.size(); ++c) joint.cells[c].bands = {static_cast<int>(c)};
    joint.backlash_l_rad = backlash;
    t.joints.push_back(joint);
  }
  return t;
}

PrecontrolOptions raw_options() {  // no smoothing, no supervisor limits: the model's output
  PrecontrolOptions o;
  o.smoothing_time_constant_s = 1e-9;
  o.offset_tolerance_rad.fill(1.0);
  o.rate_tolerance_rad_s.fill(1e9);
  o.rate_limit_rad_s.fill(1e9);
  return o;
}

Precontrol make(const ParameterTable& t, const PrecontrolOptions& o) {
  Precontrol p;
  std::string why;
  EXPECT_TRUE(Precontrol::create(t, "kr16", o, &p, &why)) << why;
  return p;
}

// A smooth move of joint j: rest, then q = 0.3 (1 - cos(pi t / 1.5)) / 2 rad, then rest.
std::vector<double> move(int samples) {
  std::vector<double> q(samples);
  for (int k = 0; k < samples; ++k) {
    const double t = std::clamp((k - 100) * kCycle, 0.0, 1.5);
    q[k] = 0.1 + 0.3 * 0.5 * (1.0 - std::cos(M_PI * t / 1.5));
  }
  return q;
}

TEST(Precontrol, OneCellEqualsTheOfflineFreeRunPrediction) {
  // Static gain 1: at rest the model output equals its input, so the runtime's start (model
  // outputs from the first cycle) and the offline start (measured outputs) coincide.
  Precontrol p = make(table({cell(0.0)}, {0.0, 10.0}), raw_options());
  const std::vector<double> q = move(1200);
  std::vector<double> expected(q.size());
  ArxModel model(cell(0.0).structure, Eigen::Map<const Eigen::VectorXd>(cell(0.0).a.data(), 2),
                 Eigen::Map<const Eigen::VectorXd>(cell(0.0).b.data(), 2), kCycle);
  model.predict_joint_error(q, q, expected);
  double worst = 0.0, largest = 0.0;
  for (std::size_t k = 0; k < q.size(); ++k) {
    std::array<double, 6> qd;
    qd.fill(q[k]);
    const PrecontrolOutput out = p.cycle(qd, 5.0, k);
    if (k < 4) continue;  // max_lag: the offline prediction starts there
    worst = std::max(worst, std::abs(out.offset_rad[2] - expected[k]));
    largest = std::max(largest, std::abs(expected[k]));
  }
  // Same recursion, same start (at rest, y = u): equal to rounding of ~1e-16 rad per step.
  EXPECT_LT(worst, 1e-13);
  EXPECT_GT(largest, 1e-5);  // the model does predict a real error on this move
}

// A joint that could not be identified gets ident::neutral_joint_parameters: the
// precontrol must then add exactly zero on any motion, from the first cycle on (a garbage table
// once produced a 2.9 rad "offset" at cycle 0 and deactivated the whole compensation).
TEST(Precontrol, NeutralJointModelAddsExactlyZero) {
  ParameterTable t = table({cell(0.0)}, {0.0, 10.0}, 1e-3);
  t.joints[4] = neutral_joint_parameters("A5", 5.76, "no cell could be identified: test");
  t.joints[5] = neutral_joint_parameters("A6", 10.7, "no cell could be identified: test");
  EXPECT_EQ(t.joints[4].backlash_l_rad, 0.0);
  EXPECT_NE(t.joints[4].cells[0].reason.find("no cell could be identified"), std::string::npos);
  Precontrol p = make(t, raw_options());
  const std::vector<double> q = move(1200);
  double largest_identified = 0.0;
  for (std::size_t k = 0; k < q.size(); ++k) {
    std::array<double, 6> qd;
    qd.fill(2.9 + q[k]);  // far from 0 rad: a model without static gain 1 would show it
    const PrecontrolOutput out = p.cycle(qd, 5.0, k);
    ASSERT_EQ(out.state, PrecontrolState::kActive) << k;
    // Exact: q̂ = 1 · q_d and Δq̂ = q_d - q̂ = 0 in floating point, no backlash term.
    ASSERT_EQ(out.offset_rad[4], 0.0) << k;
    ASSERT_EQ(out.offset_rad[5], 0.0) << k;
    largest_identified = std::max(largest_identified, std::abs(out.offset_rad[0]));
  }
  EXPECT_GT(largest_identified, 1e-4);  // the identified joints do compensate on this move
}

TEST(Precontrol, BlendingIsContinuousAcrossCellBoundaries) {
  // Two cells (slow, fast) whose models differ by 5 % in gain: a hard switch would jump.
  const ParameterTable t = table({cell(0.0), cell(0.05)}, {0.0, 0.2, 0.4});
  PrecontrolOptions o = raw_options();
  Precontrol p = make(t, o);
  double q = 0.0, speed = 0.0, max_step = 0.0, spread = 0.0;
  std::array<double, 6> qd{};
  for (int k = 0; k < 3000; ++k) {  // speed ramps 0 -> 0.6 rad/s: crosses both cell centres
    speed = std::min(0.6, k * 0.0002);
    q += speed * kCycle;
    qd.fill(q);
    const double before = p.cycle(qd, 0.0, k).offset_rad[0];
    (void)before;
  }
  Precontrol hard = make(t, o);
  Precontrol soft = make(t, o);
  q = 0.0;
  double last = 0.0;
  for (int k = 0; k < 3000; ++k) {
    speed = std::min(0.6, k * 0.0002);
    q += speed * kCycle;
    qd.fill(q);
    const double offset = soft.cycle(qd, 0.0, k).offset_rad[0];
    if (k > 10) max_step = std::max(max_step, std::abs(offset - last));
    spread = std::max(spread, std::abs(offset));
    last = offset;
  }
  // The offset grows smoothly with the speed; its largest change per cycle stays far below the
  // 5 % model difference (~5 % of the offset) that a hard switch would produce at once.
  EXPECT_LT(max_step, 0.01 * spread);
  (void)hard;
}

TEST(Precontrol, BacklashTermHasNoChatterAtReversals) {
  const double l = 2e-4;
  Precontrol with = make(table({cell(0.0)}, {0.0, 10.0}, l), raw_options());
  Precontrol without = make(table({cell(0.0)}, {0.0, 10.0}, 0.0), raw_options());
  std::array<double, 6> qd{};
  double moving = 0.0, resting_max = 0.0;
  for (int k = 0; k < 2000; ++k) {
    double q;
    if (k < 1000) {
      q = 0.1 * k * kCycle;  // 0.1 rad/s: tanh(0.1 / 0.002) = 1 - 4e-22: the term is +l
    } else {  // standing still with 1e-9 rad of encoder-like jitter on the desired value
      q = 0.1 * 1000 * kCycle + ((k % 2) ? 1e-9 : -1e-9);
    }
    qd.fill(q);
    const double difference =
        with.cycle(qd, 0.0, k).offset_rad[0] - without.cycle(qd, 0.0, k).offset_rad[0];
    if (k == 999) moving = difference;
    if (k > 1500) resting_max = std::max(resting_max, std::abs(difference));
  }
  EXPECT_NEAR(moving, l, 1e-15);  // exactly +l moving + (rounding only)
  // Jitter of ±1e-9 rad is ±5e-7 rad/s: the tanh gives ±l * 2.5e-4 = ±5e-8 rad, not ±l.
  EXPECT_LT(resting_max, 1e-7);
}

TEST(Precontrol, ToleranceViolationDeactivatesWithinOneCycleAndFadesOutWithoutStep) {
  PrecontrolOptions o;  // the defaults: 5 mrad, 0.5 rad/s, rate limit 0.2 rad/s, 4 ms, 0.2 s
  o.offset_tolerance_rad.fill(2e-3);
  Precontrol p = make(table({cell(0.02)}, {0.0, 10.0}), o);  // 2 % gain error: offset grows
  std::array<double, 6> qd{};
  int deactivated_at = -1, violation_at = -1;
  double last = 0.0, max_step = 0.0;
  for (int k = 0; k < 1000; ++k) {
    qd.fill(0.2 * k * kCycle);  // offset ~ 2 % of q: crosses 2 mrad near q = 0.1 rad
    const PrecontrolOutput out = p.cycle(qd, 0.0, k);
    if (violation_at < 0 && std::abs(0.02 * qd[0]) > 2e-3 * 1.05) violation_at = k;
    if (deactivated_at < 0 && out.state != PrecontrolState::kActive) deactivated_at = k;
    max_step = std::max(max_step, std::abs(out.offset_rad[0] - last));
    last = out.offset_rad[0];
  }
  ASSERT_GE(deactivated_at, 0);
  EXPECT_LE(deactivated_at, violation_at);    // no later than the cycle the violation shows
  EXPECT_LE(max_step, 0.2 * kCycle + 1e-15);  // never a step above the rate limit
  EXPECT_EQ(p.state(), PrecontrolState::kInactive);
  EXPECT_EQ(last, 0.0);  // faded out completely
  PrecontrolEvent events[8];
  const int n = p.read_events(events, 8);
  ASSERT_GE(n, 1);
  EXPECT_EQ(events[0].cause, PrecontrolCause::kOffsetTolerance);
  EXPECT_EQ(events[0].cycle, static_cast<std::uint64_t>(deactivated_at));
  p.reactivate();
  EXPECT_EQ(p.state(), PrecontrolState::kActive);
}

TEST(Precontrol, FaultsHaveTheirDefinedReactions) {
  const ParameterTable t = table({cell(0.0)}, {0.0, 0.5});
  std::array<double, 6> qd{};
  {  // NaN input: deactivation with the cause, then a fade
    Precontrol p = make(t, PrecontrolOptions{});
    p.cycle(qd, 0.0, 0);
    qd[3] = std::nan("");
    EXPECT_EQ(p.cycle(qd, 0.0, 1).state, PrecontrolState::kFadingOut);
    PrecontrolEvent e[4];
    ASSERT_EQ(p.read_events(e, 4), 1);
    EXPECT_EQ(e[0].cause, PrecontrolCause::kInvalidInput);
    qd[3] = 0.0;
  }
  {  // a lost cycle without bridging allowed: deactivation
    Precontrol p = make(t, PrecontrolOptions{});
    p.cycle(qd, 0.0, 0);
    EXPECT_EQ(p.cycle(qd, 0.0, 2).state, PrecontrolState::kFadingOut);
    PrecontrolEvent e[4];
    ASSERT_EQ(p.read_events(e, 4), 1);
    EXPECT_EQ(e[0].cause, PrecontrolCause::kLostCycles);
    EXPECT_EQ(e[0].value, 1.0);
  }
  {  // a lost cycle with bridging: stays active, no event
    PrecontrolOptions o;
    o.max_lost_cycles = 2;
    Precontrol p = make(t, o);
    p.cycle(qd, 0.0, 0);
    EXPECT_EQ(p.cycle(qd, 0.0, 2).state, PrecontrolState::kActive);
    PrecontrolEvent e[4];
    EXPECT_EQ(p.read_events(e, 4), 0);
  }
  {  // operating point outside the table: one event, flag set, compensation continues
    PrecontrolOptions o = raw_options();  // (the jump to 1 rad/s would trip the tolerances)
    Precontrol p = make(t, o);
    PrecontrolOutput out;
    for (int k = 0; k < 100; ++k) {
      qd.fill(1.0 * k * kCycle);  // 1 rad/s > 0.5 rad/s grid end
      out = p.cycle(qd, 0.0, k);
    }
    EXPECT_TRUE(out.outside_table);
    EXPECT_EQ(out.state, PrecontrolState::kActive);
    PrecontrolEvent e[4];
    ASSERT_EQ(p.read_events(e, 4), 1);
    EXPECT_EQ(e[0].cause, PrecontrolCause::kOutsideTable);
  }
  {  // a table for another robot, and cycle times
    Precontrol p;
    std::string why;
    EXPECT_FALSE(Precontrol::create(t, "kr6", PrecontrolOptions{}, &p, &why));
    EXPECT_NE(why.find("kr16"), std::string::npos);
    PrecontrolOptions o;
    for (double c : {0.004, 0.001, 0.002}) {
      o.caller_cycle_s = c;
      EXPECT_TRUE(Precontrol::create(t, "kr16", o, &p, &why)) << c << ": " << why;
    }
    o.caller_cycle_s = 0.003;
    EXPECT_FALSE(Precontrol::create(t, "kr16", o, &p, &why));
    ParameterTable bad = t;
    bad.joints[1].cells[0].a[0] = std::nan("");
    EXPECT_FALSE(Precontrol::create(bad, "kr16", PrecontrolOptions{}, &p, &why));
  }
}

TEST(Precontrol, A4msCallerGetsTheSameOffsetsAsA2msCaller) {
  const ParameterTable t = table({cell(2e-3)}, {0.0, 10.0});
  PrecontrolOptions o2 = raw_options(), o4 = raw_options();
  o4.caller_cycle_s = 0.004;
  Precontrol p2 = make(t, o2), p4 = make(t, o4);
  const std::vector<double> q = move(1200);
  double worst = 0.0, largest = 0.0;
  std::array<double, 6> qd{};
  for (std::size_t k = 0; k < q.size(); ++k) {
    qd.fill(q[k]);
    const double a = p2.cycle(qd, 0.0, k).offset_rad[0];
    if (k % 2 == 0) {
      const double b = p4.cycle(qd, 0.0, k / 2).offset_rad[0];
      worst = std::max(worst, std::abs(a - b));
      largest = std::max(largest, std::abs(a));
    }
  }
  // The 4 ms caller's model sees the 2 ms samples by linear interpolation of a smooth move:
  // interpolation error ~ q'' T^2 / 8 = 0.66 * (0.004)^2 / 8 ~ 1e-6 rad times the model's
  // sensitivity (~0.1): well below 1 % of the offset.
  EXPECT_LT(worst, 0.01 * largest);
}

TEST(Precontrol, SameOffsetsAsTheAllCellsReferenceWithBlendingAndFaults) {
  // The runtime before the precontrol's speed work (tests/support/reference_precontrol.hpp: Eigen
  // dot products) against the current one (padded SIMD partial sums, ident/arx_step_kernel.hpp) on
  // a 3 x 2 table of random order-8 models, dead times 0..3, with blending in both dimensions,
  // backlash, smoothing, a NaN, a lost cycle and a re-activation.
  std::mt19937_64 rng(6);
  ParameterTable t;
  t.robot = "kr16";
  t.sample_time_s = kCycle;
  for (int j = 0; j < 6; ++j) {
    JointParameters joint;
    joint.name = "A" + std::to_string(j + 1);
    joint.dimensions = {CellDimension{OperatingQuantity::kSpeed, {0.0, 0.1, 0.3, 0.6}},
                        CellDimension{OperatingQuantity::kPayload, {0.0, 5.0, 10.0}}};
    joint.backlash_l_rad = 1e-4;
    joint.backlash_lag_samples = static_cast<std::size_t>(j);
    for (int c = 0; c < 6; ++c) {
      CellParameters cp;
      cp.bands = {c / 2, c % 2};
      const int na = 5 + (c + j) % 4, nb = 3 + c % 6;  // unequal orders: padding exercised
      cp.structure = {na, nb, (c + j) % 4};
      const Eigen::VectorXd a =
          test_support::polynomial_from_poles(test_support::random_poles(na, rng));
      cp.a.assign(a.data(), a.data() + na);
      cp.b.assign(static_cast<std::size_t>(nb), (1.0 + a.sum()) * (1.0 + 0.01 * c) / nb);
      joint.cells.push_back(cp);
    }
    t.joints.push_back(joint);
  }
  PrecontrolOptions o;
  o.offset_tolerance_rad.fill(0.05);
  // The offset's rate reaches the joint speed when a move starts (the models lag the command):
  // above the 0.5 rad/s default on this motion, which switched the runtime off from cycle 1 on
  // and left only a third of the cycles compared while running.
  o.rate_tolerance_rad_s.fill(5.0);
  Precontrol p = make(t, o);
  test_support::AllCellsPrecontrol reference;
  std::string why;
  ASSERT_TRUE(test_support::AllCellsPrecontrol::create(t, "kr16", o, &reference, &why)) << why;
  double worst = 0.0, largest = 0.0;
  int active = 0;
  std::uint64_t counter = 0;
  std::array<double, 6> qd{};
  for (int k = 0; k < 6000; ++k, ++counter) {
    for (int j = 0; j < 6; ++j) qd[j] = 0.2 * std::sin(0.0015 * k * (j + 1)) + 0.1 * j;
    const double payload = 5.0 + 4.0 * std::sin(0.001 * k);
    if (k == 2500) qd[1] = std::nan("");
    if (k == 3500) counter += 3;  // lost cycles
    if (k == 3000 || k == 4000) {
      p.reactivate();
      reference.reactivate();
    }
    const PrecontrolOutput a = p.cycle(qd, payload, counter);
    const PrecontrolOutput b = reference.cycle(qd, payload, counter);
    ASSERT_EQ(a.state, b.state) << k;
    ASSERT_EQ(a.outside_table, b.outside_table) << k;
    active += a.state == PrecontrolState::kActive;
    for (int j = 0; j < 6; ++j) {
      worst = std::max(worst, std::abs(a.offset_rad[j] - b.offset_rad[j]));
      largest = std::max(largest, std::abs(b.offset_rad[j]));
    }
  }
  // Same recursions, sums added in another order: a few ulp (~1e-16 rad) per step, carried by
  // stable models with sum |a_i| <= 2^8 (poles inside |z| < 0.9): far below 1e-12 rad, while the
  // offsets themselves are ~1e-4..1e-3 rad.
  EXPECT_LT(worst, 1e-12);
  EXPECT_GT(largest, 1e-4);
  EXPECT_GT(active, 4000);  // compared while running, not only while off
  PrecontrolEvent ea[32], eb[32];
  const int na = p.read_events(ea, 32), nb = reference.read_events(eb, 32);
  ASSERT_EQ(na, nb);
  for (int i = 0; i < na; ++i) {
    EXPECT_EQ(ea[i].cycle, eb[i].cycle);
    EXPECT_EQ(ea[i].cause, eb[i].cause);
  }
  EXPECT_GE(na, 4);  // invalid input, 2 re-activations, lost cycles
}

TEST(Precontrol, NoHeapAllocationInsideTheCycle) {
  Precontrol p = make(table({cell(0.0), cell(0.01)}, {0.0, 0.2, 0.4}, 1e-4), PrecontrolOptions{});
  std::array<double, 6> qd{};
  const long before = test_support::g_allocations.load();
  for (int k = 0; k < 20000; ++k) {
    qd.fill(0.1 * std::sin(k * 0.001));
    if (k == 5000) qd[2] = std::nan("");  // faults too
    p.cycle(qd, 3.0, k == 7000 ? k + 5 : k);
    if (k == 6000) p.reactivate();
  }
  EXPECT_EQ(test_support::g_allocations.load() - before, 0);
}

}  // namespace
}  // namespace imscal::ident
