// The verification's files as eval/verification_files.hpp writes them, read back: the figures of
// the compensated case against the uncompensated one (what `imscal population` reads), and the
// path files `imscal evaluate` reads (eval/path_evaluation.hpp). Truth: the values written.
#include "eval/verification_files.hpp"

#include <gtest/gtest.h>

#include "eval/path_evaluation.hpp"
#include "tests/support/scratch_dir.hpp"

namespace {

namespace eval = imscal::eval;
using VerificationFiles = imscal::test_support::ScratchDirTest;

eval::VerificationCase make_case(const std::string& label, double max_m, double true_max_m) {
  eval::VerificationCase c;
  c.label = label;
  c.figures.max_path_deviation_m = max_m;
  c.figures.scatter_floor_m = 0.25 * max_m;
  c.figures.systematic_max_m = 0.5 * max_m;
  c.true_figures.max_path_deviation_m = true_max_m;
  return c;
}

// A result of two cycles along a straight line: before 2 mm, compensated 0.5 mm (75 %).
eval::VerificationResult make_result() {
  eval::VerificationResult r;
  r.scenario = "line";
  r.cycles = 2;
  r.segments = {"lin 1"};
  r.before = make_case("uncompensated", 2e-3, 1.6e-3);
  r.after = {make_case("compensated", 0.5e-3, 0.4e-3)};
  for (int k = 0; k < 3; ++k) {
    Eigen::Matrix<double, 8, 1> pose;
    pose << 0.1 * k, 0.5 + 0.01 * k, 0.0, 0.8, 1.0, 0.0, 0.0, 0.0;
    r.desired_poses.push_back(pose);
  }
  r.attained_poses = {{r.desired_poses, r.desired_poses}, {r.desired_poses, r.desired_poses}};
  return r;
}

TEST_F(VerificationFiles, CompensatedFiguresReadBackAsWritten) {
  const std::string text = eval::write_verification_files(
      dir_ / "line", make_result(), {1, 4, 0, "", true}, imscal::Overwrite::kRefuse);
  EXPECT_NE(text.find("compensated"), std::string::npos);
  const eval::VerifiedFigures f = eval::read_verified_figures(dir_ / "line" / "verification.json");
  // JSON numbers round-trip exactly; the reductions are 1 - after/before in %.
  EXPECT_DOUBLE_EQ(f.before_mm, 2.0);
  EXPECT_DOUBLE_EQ(f.after_mm, 0.5);
  EXPECT_DOUBLE_EQ(f.reduction_percent, 75.0);
  EXPECT_DOUBLE_EQ(f.true_reduction_percent, 75.0);
  EXPECT_DOUBLE_EQ(f.scatter_floor_mm, 0.125);
  EXPECT_DOUBLE_EQ(f.systematic_mm, 0.25);
}

TEST_F(VerificationFiles, PathFilesReadBackByTheEvaluation) {
  const eval::VerificationResult r = make_result();
  eval::write_verification_files(dir_ / "line", r, {}, imscal::Overwrite::kRefuse);
  const eval::PoseSeries commanded =
      eval::read_path_file((dir_ / "line" / "commanded.csv").string(), -1e300, 1e300);
  ASSERT_EQ(commanded.size(), r.desired_poses.size());
  for (std::size_t k = 0; k < commanded.size(); ++k) {
    EXPECT_EQ(commanded[k].t_s, r.desired_poses[k][0]);  // {} prints the shortest exact form
    EXPECT_EQ(commanded[k].p_m.x(), r.desired_poses[k][1]);
  }
  EXPECT_TRUE(std::filesystem::exists(dir_ / "line" / "attained_compensated_1.csv"));
}

TEST_F(VerificationFiles, NoCompensatedCaseIsAnError) {
  eval::VerificationResult r = make_result();
  r.after.front().label = "other";
  eval::write_verification_files(dir_ / "line", r, {}, imscal::Overwrite::kRefuse);
  EXPECT_THROW(eval::read_verified_figures(dir_ / "line" / "verification.json"),
               std::runtime_error);
}

}  // namespace
