#pragma once
// Scoring of the withheld-effect harness of the gap diagnosis (tests/eval/test_gap_harness.cpp,
// test_gap_harness_wide.cpp): one case made (tests/eval/gap_cases.hpp), diagnosed blind and
// scored: the withheld effect ranked first (in the leading ambiguity group), its joint located,
// the predicted held-out shrinkage against the true one, a false alarm on a control, and whether
// every withheld effect of a multi-effect case is in the model.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cstdlib>
#include <map>
#include <string>
#include <vector>

#include "eval/gap_diagnosis.hpp"
#include "tests/eval/gap_cases.hpp"

namespace imscal::eval::test {

inline bool sanitized() {
  return std::getenv("IMSCAL_SANITIZED") != nullptr;
}

struct HarnessCase {
  std::vector<WithheldEffect> effects;  // empty: control
  std::uint64_t seed = 1;
  NoiseLevel noise = NoiseLevel::kLow;
};

struct Score {
  std::string name;
  std::string top;  // "A2 backlash" or "none"; with its ambiguity group "A3 backlash / A3 ..."
  bool ranked_first = false, joint_located = false, alarm = false;
  bool all_found = false;  // every withheld effect in the model whose shrinkage is predicted
  std::size_t effects = 0;
  std::size_t group_size = 0;  // members of the leading ambiguity group
  double predicted = 0.0, truth = 0.0;
};

// One case run blind and scored (see the file's head); its row of the confusion matrix counted.
inline Score score_case(const GapWorld& world, const HarnessCase& hc,
                        std::map<std::string, std::map<std::string, int>>& confusion) {
  const auto c = world.make_case(hc.effects, hc.seed, hc.noise);
  GapSignals signals =
      make_gap_signals(c.real, c.sim_joint_error_rad, world.robot, c.table ? &*c.table : nullptr);
  // The noise floor from the case's header where it has one, as `imscal diagnose` reads it.
  signals.measurement.noise_floor_rad = noise_floor_from_log(c.real, "the case's joint errors");
  if (signals.measurement.known()) signals.measurement.source = "the case's noise floor";
  // The joint model refined on the simulator of the nominal model, as the lab has it
  // (eval/gap_refinement.hpp); linear only under the sanitizers (~10 more plant runs a case).
  const Diagnosis d = diagnose_gap(signals, DiagnosisOptions{}, sanitized() ? nullptr : &c.nominal);
  Score s;
  for (const auto& e : hc.effects)
    s.name +=
        (s.name.empty() ? "" : " + ") +
        (spreads_over_joints(e.name)
             ? (e.name == "kinematic" ? fmt::format("link {} kinematic", e.joint + 1) : e.name)
             : fmt::format("{} {}", world.robot.joints[std::size_t(e.joint)].name, e.name)) +
        (e.scale > 0.0 ? fmt::format(" x{:g}", e.scale) : std::string());
  if (s.name.empty()) s.name = "control";
  s.alarm = d.significant_gap;
  s.top = "none";
  if (d.significant_gap) {
    // Ranked first: the withheld effect is the top candidate or one of those the data cannot
    // tell apart from it (the leading ambiguity group: modelled gaps within 10 % of the
    // residual, no more parameters; eval/gap_ambiguity.hpp). Its size is printed and bounded
    // below, so that a large group cannot buy a hit.
    const std::vector<std::size_t> lead = leading_group(d);
    s.group_size = lead.size();
    s.top.clear();
    for (std::size_t m : lead)
      s.top += (s.top.empty() ? "" : " / ") + candidate_label(signals, d.candidates[m].fit);
    const auto& top = d.candidates.front().fit;
    for (const auto& e : hc.effects) {
      // An effect that spreads over the joints (the IMS chain's errors, the payload): its kind
      // ranked first counts on any joint, located is the joint where the gap has the most
      // energy. The others: kind and source joint.
      const bool spread = spreads_over_joints(e.name);
      const int joint = spread ? c.spread_joint : e.joint;
      for (std::size_t m : lead) {
        const auto& f = d.candidates[m].fit;
        s.ranked_first |= f.kind == expected_kind(e.name) && (spread || int(f.joint) == joint);
      }
      s.joint_located |= int(top.joint) == joint;
    }
    s.predicted = d.combination.empty() ? d.candidates.front().shrinkage_percent
                                        : d.combination.back().shrinkage_percent;
    // Found: each withheld effect's kind (and joint, unless it spreads over the joints) in the
    // model whose shrinkage is predicted or in the leading ambiguity group.
    std::vector<const CandidateFit*> model;
    for (std::size_t m : lead) model.push_back(&d.candidates[m].fit);
    for (const CombinationStep& step : d.combination) model.push_back(&step.fit);
    s.all_found = true;
    for (const auto& e : hc.effects) {
      const bool spread = spreads_over_joints(e.name);
      bool found = false;
      for (const CandidateFit* f : model)
        found |= f->kind == expected_kind(e.name) && (spread || int(f->joint) == e.joint);
      s.all_found = s.all_found && found;
    }
  }
  s.effects = hc.effects.size();
  s.truth = true_heldout_shrinkage_percent(c, signals);
  const std::string row = hc.effects.empty() ? "control" : hc.effects.front().name;
  // The confusion matrix counts the top candidate (the first of its group).
  const std::string col = d.significant_gap ? to_string(d.candidates.front().fit.kind) : "none";
  ++confusion[row][col];
  fmt::print(
      "{:<32} top {:<34} first {:d} joint {:d}  shrinkage predicted {:6.1f} % true {:6.1f} %"
      "  gap {:.3g} rad  all found {:d}\n  {}\n",
      s.name, s.top, s.ranked_first, s.joint_located, s.predicted, s.truth, d.heldout_rms_rad,
      s.all_found, d.verdict);
  std::vector<std::string> members;
  for (const CombinationStep& step : d.combination) members.push_back(step.label);
  fmt::print("  model: {}; re-simulated {:d} ({} runs, {:.1f} %): {}\n", fmt::join(members, " + "),
             d.refinement.applied, d.refinement.simulations, d.refinement.shrinkage_percent,
             fmt::join(d.refinement.changes, "; "));
  return s;
}

}  // namespace imscal::eval::test
