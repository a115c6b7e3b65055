// The paper's own remaining-error diagnosis (section 4, last paragraph) reproduced by the tool:
// the error model is identified on the `identification` runs of a robot whose joint 2 has no
// play there (tests/data/scenarios/identification-a2-no-backlash.yaml: the model cannot learn
// it), then tested on `seed-line`, the paper's 800 mm line at the outer limits of the
// workspace, where A2's backlash is on. "sim" = that identified error model (forward form,
// ident::ArxModelForm::kJointError) run on seed-line's desired joints; "real" = the plant's
// joint errors. The diagnosis must name what the paper names by hand: that the test path lies at
// operating points the identification did not cover, and joint 2 backlash. On seed-line A2
// carries the arm against gravity, so its gear torque never changes sign (checked below): the
// play holds the link on one flank and shows only as a constant offset of half its width, which
// these data cannot tell from a zero offset of A2. The diagnosis must say exactly that: A2's
// leading explanation is the ambiguity group {zero offset, backlash held on one flank}, with the
// measurement that separates them (a path on which A2's torque changes sign).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "core/config_node.hpp"
#include "eval/gap_diagnosis.hpp"
#include "eval/verification.hpp"
#include "ident/identification_config.hpp"

namespace imscal::eval {
namespace {

namespace fs = std::filesystem;

TEST(GapPaperCase, NamesTheOperatingPointMismatchAndJoint2Backlash) {
  // Identification: the whole program, under sanitizers too (a shorter part identifies another
  // model, whose gap on A2 is no longer led by the play's constant: the assertions below are
  // about the paper's setting, so CI runs that).
  const ident::JointErrorLog identification = simulate_truth_joint_errors(
      sim::load_scenario(fs::path(IMSCAL_TEST_DATA_DIR) /
                         "scenarios/identification-a2-no-backlash.yaml"),
      1e9);
  ident::IdentificationConfig config = ident::load_identification_config(ConfigNode::load_file(
      fs::path(IMSCAL_SOURCE_DIR) / "datasets/identification/ident-paper.yaml"));
  config.options.form = ident::ArxModelForm::kJointError;  // the forward error model
  // The operating point includes the joint position (the paper's Table 2 extended "to take also
  // into account ... the position of the axes"): bands below -0.5 rad, -0.5..0.5, above 0.5 rad.
  config.extra_dimensions.push_back({ident::OperatingQuantity::kPosition, {-3.5, -0.5, 0.5, 3.5}});
  const IdentifiedTable identified = identify_table(identification, config);
  for (const auto& failed : identified.failed_joints) fmt::print("not identified: {}\n", failed);

  const sim::Scenario seed_line =
      sim::load_scenario(fs::path(IMSCAL_SOURCE_DIR) / "datasets/scenarios/seed-line.yaml");
  const ident::JointErrorLog real = simulate_truth_joint_errors(seed_line);
  const auto sim_errors = predict_table_joint_errors(identified.table, real);
  const calib::RobotDescription robot = sim::load_nominal_robot(seed_line).description;
  const GapSignals signals = make_gap_signals(real, sim_errors, robot, &identified.table);
  const Diagnosis d = diagnose_gap(signals);

  fmt::print("{}\n", d.verdict);
  for (const auto& m : d.measure_next) fmt::print("  measure next: {}\n", m);
  for (std::size_t i = 0; i < std::min<std::size_t>(8, d.candidates.size()); ++i) {
    const auto& c = d.candidates[i];
    fmt::print("  {:<36} {:6.1f} % (own joint {:6.1f} %) p {:.3f} {} — {}\n",
               candidate_label(signals, c.fit), c.shrinkage_percent, c.joint_shrinkage_percent,
               c.p_value, c.supported ? "supported" : "not supported", c.fit.shape);
  }
  for (const auto& j : d.where.joints) fmt::print("  {} gap RMS {:.3g} rad\n", j.joint, j.rms_rad);
  for (const auto& f : d.joint_findings) {
    std::string leading;
    for (std::size_t m : f.leading)
      leading += " / " + candidate_label(signals, d.candidates[m].fit);
    const auto& leader = d.candidates[f.leading.front()];
    fmt::print("  per joint {}: {} ({:.1f} % of its held-out gap, p {:.3f}, {})\n",
               signals.joint_names[f.joint], leading.substr(3), leader.joint_shrinkage_percent,
               leader.joint_p_value, f.supported ? "supported" : "not supported");
  }
  for (const auto& step : d.combination)
    fmt::print("  combination + {:<30} {:6.1f} %\n", step.label, step.shrinkage_percent);

  EXPECT_TRUE(d.significant_gap) << d.verdict;  // a structured gap is left (its top: printed)
  // The operating-point mismatch: seed-line's A2 runs in cells of the identified grid that the
  // identification runs did not fill (its positions at the outer limits of the workspace), and
  // the verdict says so.
  const JointGapAnalysis& a2 = d.where.joints[1];
  double outside_time = 0.0;
  for (const auto& cell : a2.by_cell)
    if (cell.outside_identified_range) outside_time += cell.time_share;
  fmt::print("A2: {:.0f} % of the time in cells outside the identified range\n",
             100.0 * outside_time);
  EXPECT_GT(outside_time, 0.2);  // measured 56 %
  EXPECT_NE(d.verdict.find("outside the identified range"), std::string::npos) << d.verdict;

  // Joint 2 backlash. The independent fact behind the ambiguity: A2's gear torque (the rigid-body
  // torque of the drive's motion) keeps its sign all along seed-line.
  const auto& tau = signals.torque_internal_nm[1];
  ASSERT_TRUE(std::all_of(tau.begin(), tau.end(), [](double v) { return v < 0.0; }) ||
              std::all_of(tau.begin(), tau.end(), [](double v) { return v > 0.0; }));
  // On A2's own gap, its leading explanation is the group {zero offset, backlash held on one
  // flank}: the same constant, so the same modelled gap.
  const auto finding = std::find_if(d.joint_findings.begin(), d.joint_findings.end(),
                                    [](const JointFinding& f) { return f.joint == 1; });
  ASSERT_NE(finding, d.joint_findings.end());
  std::vector<std::string> leading;
  for (std::size_t m : finding->leading)
    leading.push_back(candidate_label(signals, d.candidates[m].fit));
  EXPECT_NE(std::find(leading.begin(), leading.end(), "A2 backlash"), leading.end());
  EXPECT_NE(std::find(leading.begin(), leading.end(), "A2 zero_offset"), leading.end());
  EXPECT_LE(leading.size(), 3u);  // a small group
  const auto backlash = std::find_if(
      finding->leading.begin(), finding->leading.end(),
      [&](std::size_t m) { return d.candidates[m].fit.kind == EffectKind::kBacklash; });
  ASSERT_NE(backlash, finding->leading.end());
  EXPECT_EQ(d.candidates[*backlash].fit.shape, kOneFlankShape);
  // ... and the report names it with the measurement that separates the two.
  EXPECT_NE(d.verdict.find("backlash on joint A2"), std::string::npos) << d.verdict;
  EXPECT_TRUE(std::any_of(d.measure_next.begin(), d.measure_next.end(), [](const std::string& m) {
    return m.find("A2 backlash") != std::string::npos &&
           m.find("gear torque of A2 changes sign") != std::string::npos;
  }));
}

}  // namespace
}  // namespace imscal::eval
