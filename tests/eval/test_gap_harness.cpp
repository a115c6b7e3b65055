// The withheld-effect harness of the gap diagnosis: for effects the simulator can
// switch (backlash, Coulomb friction, elastic gear, transmission error) and effects injected into
// the "real" data another way (time offset of the measurement stream, joint zero offset, payload
// mismatch via the path's payload, thermal drift and a structural resonance added to the
// measurement; errors of the IMS chain: DH parameters, sensor mounting, gyro scale factor and
// bias, through the kinematics), on several joints and seeds, "real" = the simulator with the
// effect on (+ noise), "sim" = without. The diagnosis runs blind; scored: the withheld effect
// ranked first, its joint located, the predicted shrinkage of the held-out gap against the
// shrinkage obtained with the true effect switched on (the noise is then all that remains), false
// alarms on controls, and two-effect cases. "Ranked first" accepts the withheld effect inside the
// leading ambiguity group (candidates whose modelled gaps the data cannot tell apart,
// eval/gap_ambiguity.hpp: e.g. a backlash held on one flank and a zero offset of A3, whose torque
// never changes sign here); the group's size is printed and bounded. Prints the confusion matrix
// and the figures. Under
// IMSCAL_SANITIZED a subset of the cases runs (each case is one plant simulation of ~8.5 s of
// motion).
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <map>

#include "eval/gap_diagnosis.hpp"
#include "tests/eval/gap_harness_scoring.hpp"
#include "tests/support/record_figure.hpp"

namespace imscal::eval {
namespace {

using test::HarnessCase;
using test::sanitized;
using test::Score;
using test::score_case;

TEST(GapHarness, WithheldEffectsAreFoundLocatedAndSized) {
  const test::GapWorld world;
  // Every effect of the library on several joints (or, for effects that spread over the joints,
  // several random sizes and directions), each case its own seed; controls; two-effect cases.
  std::vector<HarnessCase> cases = {
      {{{"backlash", 0}}, 1},
      {{{"backlash", 1}}, 2},
      {{{"backlash", 3}}, 3},
      {{{"backlash", 2}}, 40},
      {{{"backlash", 5}}, 41},
      {{{"coulomb", 0}}, 4},
      {{{"coulomb", 2}}, 5},
      {{{"coulomb", 4}}, 6},
      {{{"coulomb", 1}}, 42},
      {{{"elastic", 1}}, 7},
      {{{"elastic", 2}}, 8},
      {{{"elastic", 4}}, 9},
      {{{"elastic", 0}}, 43},
      {{{"transmission", 0}}, 10},
      {{{"transmission", 3}}, 11},
      {{{"transmission", 1}}, 44},
      {{{"transmission", 5}}, 45},
      {{{"time_offset", 1}}, 12},
      {{{"time_offset", 4}}, 13},
      {{{"time_offset", 0}}, 46},
      {{{"zero_offset", 2}}, 14},
      {{{"zero_offset", 5}}, 15},
      {{{"zero_offset", 0}}, 47},
      {{{"payload", 0}}, 16},
      {{{"payload", 0}}, 48},
      {{{"drift", 0}}, 17},
      {{{"drift", 3}}, 18},
      {{{"drift", 5}}, 49},
      {{{"resonance", 1}}, 35},
      {{{"resonance", 4}}, 36},
      {{{"resonance", 2}}, 50},
      {{{"operating_point", 0}}, 55},
      {{{"operating_point", 1}}, 56},
      {{{"operating_point", 2}}, 57},
      {{{"kinematic", 1}}, 26},
      {{{"kinematic", 2}}, 27},
      {{{"kinematic", 4}}, 28},
      {{{"kinematic", 3}}, 51},
      {{{"mounting", 0}}, 29},
      {{{"mounting", 0}}, 30},
      {{{"mounting", 0}}, 52},
      {{{"ims_scale", 0}}, 31},
      {{{"ims_scale", 0}}, 32},
      {{{"ims_scale", 0}}, 53},
      {{{"ims_bias", 0}}, 33},
      {{{"ims_bias", 0}}, 34},
      {{{"ims_bias", 0}}, 54},
      {{}, 19},
      {{}, 20},
      {{}, 21},
      {{}, 22},
      {{}, 23},
      {{}, 58},
      {{}, 59},
      {{}, 63},
      {{{"backlash", 0}, {"transmission", 3}}, 24},
      {{{"zero_offset", 1}, {"time_offset", 3}}, 25},
      {{{"coulomb", 2}, {"backlash", 1}}, 60},
      {{{"mounting", 0}, {"drift", 1}}, 61},
      {{{"payload", 0}, {"time_offset", 4}}, 62},
  };
  if (sanitized())  // seven families (one a two-effect case, one a control): ~8x fewer runs
    cases = {cases[0], cases[14], cases[23], cases[31], cases[38], cases[47], cases[57]};

  std::vector<Score> scores;
  std::map<std::string, std::map<std::string, int>> confusion;
  for (const auto& hc : cases) scores.push_back(score_case(world, hc, confusion));

  // Confusion matrix: withheld effect (first of a pair) x top-ranked candidate kind.
  std::vector<std::string> cols;
  for (int k = 0; k < kEffectKindCount; ++k) cols.push_back(to_string(effect_kind_from_index(k)));
  cols.push_back("none");
  fmt::print("\nconfusion matrix (rows: withheld, columns: ranked first)\n{:<16}", "");
  for (const auto& c : cols) fmt::print("{:>6.6}", c);
  fmt::print("\n");
  for (const auto& [row, counts] : confusion) {
    fmt::print("{:<16}", row);
    for (const auto& c : cols) fmt::print("{:>6}", counts.count(c) ? counts.at(c) : 0);
    fmt::print("\n");
  }
  int effect_cases = 0, first = 0, located = 0, within = 0, controls = 0, alarms = 0;
  std::size_t largest_group = 0, grouped = 0;
  for (const auto& s : scores) {
    largest_group = std::max(largest_group, s.group_size);
    grouped += s.group_size > 1;
    if (s.name == "control") {
      ++controls;
      alarms += s.alarm;
      continue;
    }
    ++effect_cases;
    first += s.ranked_first;
    located += s.joint_located;
    within += std::abs(s.predicted - s.truth) <= 20.0;
  }
  const auto pct = [](int a, int b) { return b ? 100.0 * a / b : 0.0; };
  fmt::print(
      "\nwithheld effect ranked first {}/{} ({:.0f} %), joint located {}/{} ({:.0f} %), predicted "
      "shrinkage within ±20 pp of the true one {}/{} ({:.0f} %), false alarms {}/{} controls\n"
      "leading ambiguity groups of two or more: {} cases, largest {}\n",
      first, effect_cases, pct(first, effect_cases), located, effect_cases,
      pct(located, effect_cases), within, effect_cases, pct(within, effect_cases), alarms, controls,
      grouped, largest_group);

  // The goals, all met and asserted: ranked first >= 90 % (the withheld effect first or
  // in the leading ambiguity group, which must stay small: at most 3 members, measured at most 2),
  // joint located >= 90 %, false alarms <= 10 % of the controls, predicted shrinkage within
  // ±20 pp of the true one >= 90 % (measured 52/52 with the joint model refined on the nominal
  // model; linear only 49/52, the transmission errors of A1 and A2 and the payload ~21 pp under the
  // truth: the Laguerre bases follow their response through the loop only in part).
  test_support::record_figure("ranked_first_percent", pct(first, effect_cases));
  test_support::record_figure("joint_located_percent", pct(located, effect_cases));
  test_support::record_figure("shrinkage_within_20pp_percent", pct(within, effect_cases));
  test_support::record_figure("false_alarm_percent", pct(alarms, controls));
  EXPECT_LE(alarms, controls / 10) << "false alarms on controls";
  EXPECT_GE(pct(first, effect_cases), 90.0);
  EXPECT_GE(pct(located, effect_cases), 90.0);
  EXPECT_LE(largest_group, 3u);
  if (!sanitized()) {  // a figure of the whole set: the subset's few cases say little
    EXPECT_GE(pct(within, effect_cases), 90.0);
  }
}

// Cases apart from the figures above (Release only: ~0.6 s each): effects resized rather than
// switched (Coulomb friction x1.5 and x0.5, a transmission error of the 2nd or 3rd harmonic) and
// two and three effects at once. Scored: the predicted shrinkage of the resized effects, and in
// every case with several effects (these and the two-effect cases above) whether every withheld
// effect is in the model whose shrinkage is predicted.
TEST(GapHarness, ResizedAndSimultaneousEffectsAreAllFound) {
  if (sanitized()) GTEST_SKIP() << "Release-only figures";
  const test::GapWorld world;
  const std::vector<HarnessCase> cases = {
      {{{"coulomb", 0, 1.5}}, 70},
      {{{"coulomb", 2, 0.5}}, 71},
      {{{"coulomb", 1, 0.5}}, 72},
      {{{"coulomb", 4, 1.5}}, 80},
      {{{"transmission", 0, 2.0}}, 73},
      {{{"transmission", 2, 3.0}}, 74},
      {{{"backlash", 0}, {"transmission", 3}}, 24},
      {{{"zero_offset", 1}, {"time_offset", 3}}, 25},
      {{{"coulomb", 2}, {"backlash", 1}}, 60},
      {{{"mounting", 0}, {"drift", 1}}, 61},
      {{{"payload", 0}, {"time_offset", 4}}, 62},
      {{{"coulomb", 2, 0.5}, {"backlash", 1}}, 75},
      {{{"clock_offset", 0}, {"backlash", 3}}, 76},
      {{{"backlash", 0}, {"transmission", 3}, {"zero_offset", 2}}, 77},
      {{{"coulomb", 1}, {"elastic", 4}, {"time_offset", 5}}, 78},
      {{{"payload", 0}, {"backlash", 5}, {"drift", 2}}, 79},
  };
  std::map<std::string, std::map<std::string, int>> confusion;
  int resized = 0, resized_within = 0, multi = 0, multi_found = 0;
  for (const auto& hc : cases) {
    const Score s = score_case(world, hc, confusion);
    if (s.effects > 1) {
      ++multi;
      multi_found += s.all_found;
    } else {
      ++resized;
      resized_within += std::abs(s.predicted - s.truth) <= 20.0;
    }
  }
  const auto pct = [](int a, int b) { return b ? 100.0 * a / b : 0.0; };
  fmt::print(
      "\nresized effects: predicted shrinkage within ±20 pp of the true one {}/{} ({:.0f} %)\n"
      "several effects at once: every withheld effect found {}/{} ({:.0f} %)\n",
      resized_within, resized, pct(resized_within, resized), multi_found, multi,
      pct(multi_found, multi));
  test_support::record_figure("resized_within_20pp_percent", pct(resized_within, resized));
  test_support::record_figure("multi_effect_all_found_percent", pct(multi_found, multi));
  // At the measured level (8/10 and 6/6 with the joint model refined on the nominal model; 8/10
  // and 2/6 linear only, measured before decision 0065): a fall shows here.
  EXPECT_GE(pct(multi_found, multi), 80.0);
  EXPECT_GE(pct(resized_within, resized), 500.0 / 6.0 - 1e-9);
}

// Resized effects of other sizes, orders and joints than the cases above (Release only): Coulomb
// friction x0.6..x2 on other joints, transmission errors of orders 1.5..4 and other amplitudes,
// payloads of 2 and 8 kg added. Scored as the resized effects above.
TEST(GapHarness, ResizedEffectsOfOtherSizesAreSized) {
  if (sanitized()) GTEST_SKIP() << "Release-only figures";
  const test::GapWorld world;
  const std::vector<HarnessCase> cases = {
      {{{"coulomb", 1, 1.3}}, 90},
      {{{"coulomb", 3, 0.7}}, 91},
      {{{"coulomb", 5, 2.0}}, 92},
      {{{"coulomb", 0, 0.6}}, 93},
      {{{"transmission", 1, 1.5, 30.0}}, 94},
      {{{"transmission", 3, 2.5}}, 95},
      {{{"transmission", 4, 4.0, 45.0}}, 96},
      {{{"transmission", 5, 2.0, 15.0}}, 97},
      {{{"payload", 0, 0.0, 2.0}}, 98},
      {{{"payload", 0, 0.0, 8.0}}, 99},
  };
  std::map<std::string, std::map<std::string, int>> confusion;
  int within = 0, first = 0;
  for (const auto& hc : cases) {
    const Score s = score_case(world, hc, confusion);
    within += std::abs(s.predicted - s.truth) <= 20.0;
    first += s.ranked_first;
  }
  const double n = double(cases.size());
  fmt::print(
      "\nresized effects of other sizes: ranked first {}/{}, shrinkage within ±20 pp {}/{}\n",
      first, cases.size(), within, cases.size());
  test_support::record_figure("resized_heldout_within_20pp_percent", 100.0 * within / n);
  // The goal (>= 85 % within ±20 pp); measured 10/10, ranked first 9/10 (the Coulomb
  // friction of A1 and A2 raised or lowered ranks a backlash first; the re-simulation finds it).
  EXPECT_GE(100.0 * within / n, 85.0);
}

}  // namespace
}  // namespace imscal::eval
