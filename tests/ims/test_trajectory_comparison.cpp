// compare_trajectories against hand-computed errors: a known offset, a known rotation, sigmas
// that make the normalised error exactly known; and the CLI's acceptance check (exit code 1).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>

#include "ims/so3.hpp"
#include "ims/trajectory_comparison.hpp"

namespace ims = imscal::ims;
namespace fs = std::filesystem;

namespace {
ims::NavTrajectory straight_line(std::size_t n) {
  ims::NavTrajectory t;
  for (std::size_t i = 0; i < n; ++i) {
    ims::NavState s;
    s.t_s = 0.001 * static_cast<double>(i);
    s.p_W = Eigen::Vector3d(0.1 * s.t_s, -0.2, 1.0);
    s.q_W_S = ims::quat_exp(Eigen::Vector3d(0.0, 0.0, 0.3 * s.t_s));
    t.states.push_back(s);
  }
  return t;
}
}  // namespace

TEST(TrajectoryComparison, KnownOffsetAndRotation) {
  const ims::NavTrajectory truth = straight_line(200);
  ims::NavTrajectory estimate = truth;
  const Eigen::Vector3d offset(3e-4, -4e-4, 0.0);  // |offset| = 0.5 mm exactly
  const Eigen::Vector3d tilt(2e-5, 0.0, 0.0);      // 2e-5 rad about East
  for (auto& s : estimate.states) {
    s.p_W += offset;
    s.q_W_S = ims::quat_exp(Eigen::Vector3d(-tilt)) * s.q_W_S;  // error = truth * est^-1 = tilt
    estimate.sigmas.push_back(
        (Eigen::Matrix<double, 9, 1>() << 1e-5, 1, 1, 1, 1, 1, 1e-4, 2e-4, 1).finished());
  }
  const ims::TrajectoryComparison c = ims::compare_trajectories(estimate, truth);
  EXPECT_EQ(c.matched_states, 200u);
  // Rounding of 1 m-size coordinates: 1e-15 relative; tolerances 1e-12 leave room for it.
  EXPECT_NEAR(c.position_rms_m, 5e-4, 1e-12);
  EXPECT_NEAR(c.position_max_m, 5e-4, 1e-12);
  EXPECT_NEAR(c.attitude_rms_rad, 2e-5, 1e-12);
  // Normalised errors: 2e-5/1e-5 = 2 (attitude E), -3e-4/1e-4 -> 3, 4e-4/2e-4 -> 2.
  EXPECT_NEAR(c.normalised_error_rms[0], 2.0, 1e-6);
  EXPECT_NEAR(c.normalised_error_rms[6], 3.0, 1e-9);
  EXPECT_NEAR(c.normalised_error_rms[7], 2.0, 1e-9);
  EXPECT_NEAR(c.normalised_error_rms[3], 0.0, 1e-12);
}

TEST(TrajectoryComparison, MatchesByTimeAndRefusesDisjointRecords) {
  const ims::NavTrajectory truth = straight_line(100);
  ims::NavTrajectory estimate;
  for (std::size_t i = 10; i < 100; i += 10) estimate.states.push_back(truth.states[i]);
  const auto c = ims::compare_trajectories(estimate, truth);
  EXPECT_EQ(c.matched_states, 9u);
  EXPECT_NEAR(c.position_rms_m, 0.0, 1e-15);
  EXPECT_TRUE(std::isnan(c.normalised_error_rms[0]));  // no sigmas given
  ims::NavTrajectory late = estimate;
  for (auto& s : late.states) s.t_s += 100.0;
  EXPECT_THROW(ims::compare_trajectories(late, truth), std::invalid_argument);
}

TEST(TrajectoryComparison, CliFailsTheAcceptanceCheckWithExitCodeOne) {
  const fs::path dir = fs::temp_directory_path() / "imscal_test_compare_cli";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const ims::NavTrajectory truth = straight_line(50);
  ims::NavTrajectory estimate = truth;
  for (auto& s : estimate.states) s.p_W.z() += 1e-3;  // 1 mm error
  ims::write_trajectory_csv(dir / "truth.csv", truth.states);
  ims::write_trajectory_csv(dir / "estimate.csv", estimate.states);
  const std::string base = std::string(IMSCAL_BINARY) + " compare --estimate " +
                           (dir / "estimate.csv").string() + " --reference " +
                           (dir / "truth.csv").string();
  const int pass = std::system((base + " --max-position-rms-mm 1.5 > /dev/null 2>&1").c_str());
  EXPECT_EQ(WEXITSTATUS(pass), 0);
  const int fail = std::system((base + " --max-position-rms-mm 0.5 > /dev/null 2>&1").c_str());
  EXPECT_EQ(WEXITSTATUS(fail), 1);
  const int missing = std::system((std::string(IMSCAL_BINARY) +
                                   " compare --estimate /nonexistent.csv --reference " +
                                   (dir / "truth.csv").string() + " > /dev/null 2>&1")
                                      .c_str());
  EXPECT_EQ(WEXITSTATUS(missing), 2);
}
