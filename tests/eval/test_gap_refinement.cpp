// The joint model of the gap refined on the simulator of the nominal model
// (eval/gap_refinement.hpp): resized effects the linear candidates under-predict, diagnosed blind
// from "real" = the nominal plant with one parameter changed (+ the harness's noise), "sim" = the
// nominal plant. Checked against the truth the case was built with: the parameter recovered and
// the predicted held-out shrinkage against the one the true effect gives (the noise is then all
// that remains). Release only: each case is ~15 runs of the plant over the ~8.5 s program.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>

#include "core/units.hpp"
#include "eval/gap_diagnosis.hpp"
#include "tests/eval/gap_cases.hpp"

namespace imscal::eval {
namespace {

struct Refined {
  Diagnosis d;
  double truth_percent = 0.0;  // held-out shrinkage with the true effect modelled
};

Refined diagnose(const test::GapWorld& world, const test::WithheldEffect& effect,
                 std::uint64_t seed) {
  const auto c = world.make_case({effect}, seed);
  const GapSignals s = make_gap_signals(c.real, c.sim_joint_error_rad, world.robot);
  return {diagnose_gap(s, DiagnosisOptions{}, &c.nominal),
          test::true_heldout_shrinkage_percent(c, s)};
}

// The refined member standing for `kind` on `joint` (parameters.size(): none).
std::size_t find_member(const NominalRefinement& r, EffectKind kind, std::size_t joint) {
  for (std::size_t i = 0; i < r.parameters.size(); ++i)
    if (r.parameters[i].kind == kind && r.parameters[i].joint == joint) return i;
  return r.parameters.size();
}

TEST(GapRefinement, CoulombFrictionLoweredIsSizedBySimulation) {
  if (std::getenv("IMSCAL_SANITIZED")) GTEST_SKIP() << "Release only: ~15 plant runs";
  const test::GapWorld world;
  // A4's Coulomb friction x0.7: the robot file's 10 N m becomes 7 N m.
  const double nominal_nm = world.robot.joints[3].drive.coulomb_nm;
  const Refined r = diagnose(world, {"coulomb", 3, 0.7}, 91);
  ASSERT_TRUE(r.d.refinement.applied);
  const std::size_t m = find_member(r.d.refinement, EffectKind::kCoulombFriction, 3);
  ASSERT_LT(m, r.d.refinement.parameters.size());
  // 2 %: the noise (~3e-6 rad white + coloured) against a ~6e-5 rad gap; measured 0.3 %.
  EXPECT_NEAR(r.d.refinement.values[m][0], -0.3 * nominal_nm, 0.02 * 0.3 * nominal_nm);
  // The refined model leaves the noise: its shrinkage within 1 pp of the true one.
  EXPECT_NEAR(r.d.combination.back().shrinkage_percent, r.truth_percent, 1.0);
}

TEST(GapRefinement, TransmissionErrorOfAnotherOrderIsFoundAndSized) {
  if (std::getenv("IMSCAL_SANITIZED")) GTEST_SKIP() << "Release only: ~15 plant runs";
  const test::GapWorld world;
  // A transmission error of order 2.5 per motor revolution, 40 arcsec, on A4: an order between
  // the linear candidates' first three.
  const Refined r = diagnose(world, {"transmission", 3, 2.5, 40.0}, 95);
  ASSERT_TRUE(r.d.refinement.applied);
  const std::size_t m = find_member(r.d.refinement, EffectKind::kTransmissionError, 3);
  ASSERT_LT(m, r.d.refinement.parameters.size());
  EXPECT_EQ(r.d.refinement.parameters[m].harmonic_per_motor_rev, 2.5);
  // 5 %: the amplitude against the noise of the ~1e-4 rad gap.
  const Eigen::VectorXd& p = r.d.refinement.values[m];
  EXPECT_NEAR(std::hypot(p[0], p[1]) / kRadPerArcsec, 40.0, 2.0);
  EXPECT_NEAR(r.d.combination.back().shrinkage_percent, r.truth_percent, 1.0);
}

}  // namespace
}  // namespace imscal::eval
