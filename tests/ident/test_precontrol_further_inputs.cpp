// The precontrol (ident/precontrol.hpp) with the multi-input models of the default
// identification (model torque, direction of motion, torque sign, the transmission-error pair;
// ident/arx_structure.hpp):
// its offsets against the all-cells reference (tests/support/reference_precontrol.hpp: every
// sum an Eigen dot product over exactly its nx_e coefficients) on a 3 x 2 grid with blending and
// the runtime's faults, and no heap allocation in the torque-fed cycle of an order-32 grid.
// GCC 12 flags the malloc/free pair of the counting operator new (tests/support/
// allocation_counter.hpp) at every inlined std::allocator use in this file (a false positive).
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <new>
#include <numbers>
#include <random>
#include <string>

#include "ident/precontrol.hpp"
#include "tests/support/allocation_counter.hpp"
#include "tests/support/arx_systems.hpp"
#include "tests/support/reference_precontrol.hpp"

namespace imscal::ident {
namespace {

constexpr double kCycle = 0.002;

// Static responses of the cells' further inputs: rad per N m of model torque, rad at full
// direction, rad at full torque sign, rad per unit of the transmission-error pair. Offsets of
// ~1e-4 rad each, like the shipped table's (its transmission error: 10 arcsec = 4.8e-5 rad).
constexpr double kTorqueGain = 1e-5, kDirectionGain = 1e-4, kSignGain = 5e-5, kTeGain = 1e-4;
// The pair's phase rate (harmonic 1 x gear ratio 160) and the gear's compliance (1 / 4.5e5 N m
// per rad, the KR 16's A2): the test motion's 0.2 rad swings turn the phase by 32 rad.
constexpr double kTeRadPerRad = 160.0, kTeCompliance = 1.0 / 4.5e5;

// 6 joints, 3 speed x 2 payload cells of random stable models (na 5..8, nb 3..8, dead time
// 0..3), each with the three further inputs in the default identification's order (and the
// transmission-error pair with transmission_error); the taps per input vary between cells
// (1..12 for torque and direction, 1 for the torque sign, 1..8 for the pair), so that every sum
// has its own length. with_inputs = false: the same table with zero further coefficients.
// second_pair: also the second transmission-error pair (f_2 = 2.5 x 160 rad/rad). gear_mode: the
// pairs through a 15 Hz, 5 % gear mode (ident/gear_mode_filter.hpp, a filter with state).
ParameterTable multi_input_table(bool with_inputs, bool transmission_error = false,
                                 bool second_pair = false, bool gear_mode = false) {
  std::mt19937_64 rng(61);
  ParameterTable t;
  t.robot = "kr16";
  t.sample_time_s = kCycle;
  t.extra_inputs = {TableInput::kModelTorque, TableInput::kDirection, TableInput::kTorqueSign};
  if (transmission_error) {
    t.extra_inputs.push_back(TableInput::kTransmissionErrorSin);
    t.extra_inputs.push_back(TableInput::kTransmissionErrorCos);
  }
  if (second_pair) {
    t.extra_inputs.push_back(TableInput::kTransmissionError2Sin);
    t.extra_inputs.push_back(TableInput::kTransmissionError2Cos);
  }
  if (gear_mode) {  // the gear-mode pairs beside the plain ones
    t.extra_inputs.push_back(TableInput::kTransmissionErrorModeSin);
    t.extra_inputs.push_back(TableInput::kTransmissionErrorModeCos);
    if (second_pair) {
      t.extra_inputs.push_back(TableInput::kTransmissionError2ModeSin);
      t.extra_inputs.push_back(TableInput::kTransmissionError2ModeCos);
    }
  }
  const int inputs = static_cast<int>(t.extra_inputs.size());
  for (int j = 0; j < 6; ++j) {
    JointParameters joint;
    joint.name = "A" + std::to_string(j + 1);
    joint.dimensions = {CellDimension{OperatingQuantity::kSpeed, {0.0, 0.1, 0.3, 0.6}},
                        CellDimension{OperatingQuantity::kPayload, {0.0, 5.0, 10.0}}};
    joint.backlash_l_rad = 1e-4;
    joint.backlash_lag_samples = static_cast<std::size_t>(j);
    joint.torque_sign_scale_nm = 3.0;
    if (transmission_error) {
      joint.transmission_error_rad_per_rad = kTeRadPerRad;
      joint.transmission_error_compliance_rad_per_nm = kTeCompliance;
    }
    if (second_pair) joint.transmission_error_2_rad_per_rad = 2.5 * kTeRadPerRad;
    if (gear_mode) {
      joint.transmission_error_mode_rad_s = 2.0 * std::numbers::pi * 15.0;
      joint.transmission_error_mode_damping = 0.05;
    }
    for (int c = 0; c < 6; ++c) {
      CellParameters cp;
      cp.bands = {c / 2, c % 2};
      const int na = 5 + (c + j) % 4, nb = 3 + c % 6;
      cp.structure = {na, nb, (c + j) % 4};
      cp.structure.extra_inputs = inputs;
      cp.structure.nx = {1 + (5 * c + j) % 12, 1 + (7 * c + 3 * j) % 12, 1,
                         1 + (3 * c + j) % 8,  1 + (c + 5 * j) % 8,      1 + (2 * c + j) % 8,
                         1 + (c + 3 * j) % 8,  1 + (c + j) % 4,          1 + (2 * c + j) % 4,
                         1 + (c + 2 * j) % 4,  1 + (3 * c + j) % 4};
      for (int e = inputs; e < kMaxExtraInputs; ++e) cp.structure.nx[std::size_t(e)] = 0;
      const Eigen::VectorXd a =
          test_support::polynomial_from_poles(test_support::random_poles(na, rng));
      const double a_sum = 1.0 + a.sum();  // A(1): coefficients / A(1) give the static gains
      cp.a.assign(a.data(), a.data() + na);
      cp.b.assign(static_cast<std::size_t>(nb), a_sum * (1.0 + 0.002 * c) / nb);  // gains 1..1.01
      const std::array<double, 11> gain{kTorqueGain, kDirectionGain, kSignGain, kTeGain,
                                        kTeGain,     kTeGain,        kTeGain,   kTeGain,
                                        kTeGain,     kTeGain,        kTeGain};
      for (int e = 0; e < inputs; ++e) {
        const int nx = cp.structure.nx[std::size_t(e)];
        for (int i = 0; i < nx; ++i)
          cp.c.push_back(with_inputs ? a_sum * gain[std::size_t(e)] * (1.0 + 0.1 * i) / nx : 0.0);
      }
      joint.cells.push_back(cp);
    }
    t.joints.push_back(joint);
  }
  return t;
}

void expect_same_offsets_as_the_reference(bool transmission_error, bool second_pair = false,
                                          bool gear_mode = false) {
  const ParameterTable t = multi_input_table(true, transmission_error, second_pair, gear_mode);
  PrecontrolOptions o;
  o.offset_tolerance_rad.fill(0.05);
  // The offset's rate reaches the joint speed when a move starts (the models lag the command):
  // above the 0.5 rad/s default on this test's motion, which would keep the runtime off.
  o.rate_tolerance_rad_s.fill(5.0);
  o.max_lost_cycles = 2;
  static Precontrol p;  // ~540 kB each: not on the stack
  static test_support::AllCellsPrecontrol reference, without_inputs;
  std::string why;
  ASSERT_TRUE(Precontrol::create(t, "kr16", o, &p, &why)) << why;
  ASSERT_TRUE(test_support::AllCellsPrecontrol::create(t, "kr16", o, &reference, &why)) << why;
  ASSERT_TRUE(test_support::AllCellsPrecontrol::create(
      multi_input_table(false, transmission_error, second_pair, gear_mode), "kr16", o,
      &without_inputs, &why))
      << why;
  ASSERT_TRUE(p.needs_model_torque());
  ASSERT_TRUE(reference.needs_model_torque());
  double worst = 0.0, largest = 0.0, input_effect = 0.0;
  int active = 0;
  std::uint64_t counter = 0;
  std::array<double, 6> qd{}, torque{};
  for (int k = 0; k < 6000; ++k, ++counter) {
    for (int j = 0; j < 6; ++j) {
      qd[j] = 0.2 * std::sin(0.0015 * k * (j + 1)) + 0.1 * j;      // reversals: direction flips
      torque[j] = 30.0 * std::sin(0.002 * k * (j + 2)) + 5.0 * j;  // N m, crosses zero
    }
    const double payload = 5.0 + 4.0 * std::sin(0.001 * k);
    if (k == 1800) counter += 2;  // lost cycles, bridged (the last torque held)
    if (k == 2500) qd[1] = std::nan("");
    if (k == 2700) torque[4] = std::nan("");
    if (k == 3500) counter += 4;  // more lost cycles than bridged: deactivation
    if (k == 3000 || k == 4000 || k == 5000) {
      p.reactivate();
      reference.reactivate();
      without_inputs.reactivate();
    }
    PrecontrolOutput a, b, c;
    if (k == 4500) {  // a caller that forgets the torque: deactivation
      a = p.cycle(qd, payload, counter);
      b = reference.cycle(qd, payload, counter);
      c = without_inputs.cycle(qd, payload, counter);
    } else {
      a = p.cycle(qd, payload, torque, counter);
      b = reference.cycle(qd, payload, torque, counter);
      c = without_inputs.cycle(qd, payload, torque, counter);
    }
    ASSERT_EQ(a.state, b.state) << k;
    active += a.state == PrecontrolState::kActive;
    ASSERT_EQ(a.outside_table, b.outside_table) << k;
    for (int j = 0; j < 6; ++j) {
      worst = std::max(worst, std::abs(a.offset_rad[j] - b.offset_rad[j]));
      largest = std::max(largest, std::abs(b.offset_rad[j]));
      if (b.state == c.state)
        input_effect = std::max(input_effect, std::abs(b.offset_rad[j] - c.offset_rad[j]));
    }
  }
  std::printf(
      "worst %.3g rad, largest offset %.3g rad, further inputs' effect %.3g rad, "
      "%d of 6000 cycles active\n",
      worst, largest, input_effect, active);
  // Same recursions, sums added in another order: a few ulp (~1e-16 rad) per step, carried by
  // stable models (poles inside |z| < 0.9): far below 1e-12 rad, while the offsets are
  // ~1e-4..1e-3 rad and the further inputs alone move them by more than 1e-4 rad.
  EXPECT_LT(worst, 1e-12);
  EXPECT_GT(largest, 1e-4);
  EXPECT_GT(input_effect, 1e-4);
  EXPECT_GT(active, 4000);  // compared while running, not only while off
  PrecontrolEvent ea[32], eb[32];
  const int na = p.read_events(ea, 32), nb = reference.read_events(eb, 32);
  ASSERT_EQ(na, nb);
  int missing_torque = 0;
  for (int i = 0; i < na; ++i) {
    EXPECT_EQ(ea[i].cycle, eb[i].cycle);
    EXPECT_EQ(ea[i].cause, eb[i].cause);
    missing_torque += ea[i].cause == PrecontrolCause::kMissingTorque;
  }
  EXPECT_EQ(missing_torque, 1);
  EXPECT_GE(na, 7);  // 2 invalid inputs, lost cycles, missing torque, 3 re-activations
}

TEST(PrecontrolFurtherInputs, SameOffsetsAsTheAllCellsReferenceWithBlendingAndFaults) {
  expect_same_offsets_as_the_reference(false);
}

// The transmission-error pair sin/cos(f (x + τ / k)) as the reference computes it from its
// definition (tests/support/reference_precontrol.hpp): the same offsets, the same faults.
TEST(PrecontrolFurtherInputs, TheTransmissionErrorPairGivesTheReferenceOffsets) {
  expect_same_offsets_as_the_reference(true);
}

// The second pair sin/cos(f_2 (x + τ / k)) likewise.
TEST(PrecontrolFurtherInputs, TheSecondTransmissionErrorPairGivesTheReferenceOffsets) {
  expect_same_offsets_as_the_reference(true, true);
}

// Both pairs through the gear mode's filter, beside the plain pairs: the filter's state restarts
// with the models (start, each re-activation) and advances once per model step, as in the
// reference.
TEST(PrecontrolFurtherInputs, TheGearModeFilterGivesTheReferenceOffsets) {
  expect_same_offsets_as_the_reference(true, true, true);
}

// A table with the pair needs each joint's phase rate (> 0), and the compliance the model torque.
TEST(PrecontrolFurtherInputs, TransmissionErrorWithoutAPhaseRateIsRefused) {
  PrecontrolOptions o;
  static Precontrol p;
  std::string why;
  ParameterTable t = multi_input_table(true, true);
  t.joints[2].transmission_error_rad_per_rad = 0.0;
  EXPECT_FALSE(Precontrol::create(t, "kr16", o, &p, &why));
  EXPECT_NE(why.find("joint A3: the transmission-error inputs need a phase rate > 0"),
            std::string::npos)
      << why;
  t = multi_input_table(true, true);
  t.joints[4].transmission_error_compliance_rad_per_nm = -1e-6;
  EXPECT_FALSE(Precontrol::create(t, "kr16", o, &p, &why));
  EXPECT_NE(why.find("joint A5: the transmission error's compliance must be finite and >= 0"),
            std::string::npos)
      << why;
}

// The heaviest table of the precontrol's benchmark (bench/bench_precontrol.cpp, the same motion):
// order 32 in every cell of a 3 x 2 grid, the model torque and direction with 32 taps, the
// torque sign with one and the transmission-error pair with 32 each, the gear-mode pair beside it
// with 4 each; the odd joints have a mode (the filter with state runs inside the cycle too).
ParameterTable order_32_grid_table() {
  std::mt19937_64 rng(32);
  ParameterTable t;
  t.robot = "kr16";
  t.sample_time_s = kCycle;
  t.extra_inputs = {TableInput::kModelTorque,
                    TableInput::kDirection,
                    TableInput::kTorqueSign,
                    TableInput::kTransmissionErrorSin,
                    TableInput::kTransmissionErrorCos,
                    TableInput::kTransmissionErrorModeSin,
                    TableInput::kTransmissionErrorModeCos};
  for (int j = 0; j < 6; ++j) {
    JointParameters joint;
    joint.name = "A" + std::to_string(j + 1);
    joint.dimensions = {CellDimension{OperatingQuantity::kSpeed, {0.0, 0.5, 1.5, 3.0}},
                        CellDimension{OperatingQuantity::kPayload, {0.0, 8.0, 16.0}}};
    joint.backlash_l_rad = 1e-4;
    joint.torque_sign_scale_nm = 1.0;
    joint.transmission_error_rad_per_rad = kTeRadPerRad;
    joint.transmission_error_compliance_rad_per_nm = kTeCompliance;
    if (j % 2 == 1) {
      joint.transmission_error_mode_rad_s = 2.0 * std::numbers::pi * 15.0;
      joint.transmission_error_mode_damping = 0.05;
    }
    for (int c = 0; c < 6; ++c) {
      CellParameters cell;
      cell.bands = {c / 2, c % 2};
      cell.structure = {32, 32, 2};
      cell.structure.extra_inputs = 7;
      cell.structure.nx = {32, 32, 1, 32, 32, 4, 4};
      const Eigen::VectorXd a =
          test_support::polynomial_from_poles(test_support::random_poles(32, rng));
      cell.a.assign(a.data(), a.data() + a.size());
      cell.b.assign(32, (1.0 + a.sum()) / 32.0);  // static gain 1
      cell.c.assign(137, 1e-7);
      joint.cells.push_back(cell);
    }
    t.joints.push_back(joint);
  }
  return t;
}

TEST(PrecontrolFurtherInputs, NoHeapAllocationInsideTheTorqueFedCycle) {
  PrecontrolOptions o;
  o.offset_tolerance_rad.fill(1.0);  // as the benchmark: keep it active, the full work
  o.rate_tolerance_rad_s.fill(1e9);
  static Precontrol p;
  std::string why;
  ASSERT_TRUE(Precontrol::create(order_32_grid_table(), "kr16", o, &p, &why)) << why;
  std::array<double, 6> qd{}, torque{};
  int active = 0;
  const long before = test_support::g_allocations.load();
  for (int k = 0; k < 20000; ++k) {
    const double t = k * kCycle;
    for (int j = 0; j < 6; ++j) qd[j] = 0.8 * std::sin(0.5 * t + j);  // sweeps the speed cells
    for (int j = 0; j < 6; ++j) torque[j] = 100.0 * std::sin(0.5 * t + j);  // N m
    const double payload = 8.0 + 6.0 * std::sin(0.01 * t);
    if (k == 5000) qd[2] = std::nan("");  // faults too
    if (k == 6000 || k == 10000) p.reactivate();
    const PrecontrolOutput out = k == 9000 ? p.cycle(qd, payload, k)  // torque missing
                                           : p.cycle(qd, payload, torque, k == 7000 ? k + 5 : k);
    active += out.state == PrecontrolState::kActive;
  }
  EXPECT_EQ(test_support::g_allocations.load() - before, 0);
  EXPECT_GT(active, 15000);  // the work was done, not switched off
}

}  // namespace
}  // namespace imscal::ident
