// The accuracy goal of the mechanization: ideal increments synthesised from the analytic
// round-trip motion (rest, +-pi about x, y and z at up to 3 rad/s, +-1 m translations at up to
// 2 m/s^2, combined moves, rest; 60 s; ims/analytic_trajectory.hpp) by exact Gauss-Legendre
// quadrature (ims/imu_synthesis.hpp), mechanized without noise, must reproduce the analytic
// truth to < 1 um in position and < 1e-6 rad in attitude after 60 s at the IMS default rate of
// 1 kHz. Switching off the Earth rate or the Coriolis term must break that by far (> 0.1 mm).
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>

#include "ims/analytic_trajectory.hpp"
#include "ims/earth_model.hpp"
#include "ims/imu_file.hpp"
#include "ims/imu_synthesis.hpp"
#include "ims/nav_trajectory_io.hpp"
#include "ims/so3.hpp"
#include "ims/strapdown.hpp"

namespace ims = imscal::ims;

namespace {

constexpr double kRateHz = 1000.0;  // the IMS default rate in simulation

struct RoundTripErrors {
  double final_position_m = 0.0;
  double final_attitude_rad = 0.0;
  double final_velocity_m_s = 0.0;
  double max_position_m = 0.0;
  double max_attitude_rad = 0.0;
};

class StrapdownRoundTrip : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    earth_ = std::make_unique<ims::EarthModel>(ims::Site{48.7, 9.1, 380.0});
    motion_ = ims::make_roundtrip_test_motion();
    increments_ = std::make_unique<ims::ImuSeries>(
        ims::synthesize_ideal_increments(*motion_, *earth_, kRateHz));
  }
  static void TearDownTestSuite() {
    increments_.reset();
    motion_.reset();
    earth_.reset();
  }

  static RoundTripErrors run(ims::StrapdownOptions options) {
    const ims::KinematicState start = motion_->at(motion_->begin_s());
    const ims::NavState initial{motion_->begin_s(), start.q_W_S, start.v_W, start.p_W};
    const auto states = ims::mechanize(*increments_, *earth_, initial, options);
    RoundTripErrors e;
    for (const ims::NavState& s : states) {
      const ims::KinematicState truth = motion_->at(s.t_s);
      e.final_position_m = (s.p_W - truth.p_W).norm();
      e.final_velocity_m_s = (s.v_W - truth.v_W).norm();
      e.final_attitude_rad = ims::rotation_angle_between(s.q_W_S, truth.q_W_S);
      e.max_position_m = std::max(e.max_position_m, e.final_position_m);
      e.max_attitude_rad = std::max(e.max_attitude_rad, e.final_attitude_rad);
    }
    return e;
  }

  static std::unique_ptr<ims::EarthModel> earth_;
  static std::unique_ptr<ims::AnalyticTrajectory> motion_;
  static std::unique_ptr<ims::ImuSeries> increments_;
};

std::unique_ptr<ims::EarthModel> StrapdownRoundTrip::earth_;
std::unique_ptr<ims::AnalyticTrajectory> StrapdownRoundTrip::motion_;
std::unique_ptr<ims::ImuSeries> StrapdownRoundTrip::increments_;

}  // namespace

TEST_F(StrapdownRoundTrip, ReachesOneMicrometreAfterSixtySeconds) {
  ASSERT_GE(motion_->end_s() - motion_->begin_s(), 60.0);
  ASSERT_EQ(increments_->samples.size(), 60000u);
  const RoundTripErrors e = run({});
  RecordProperty("final_position_error_m", std::to_string(e.final_position_m));
  RecordProperty("final_attitude_error_rad", std::to_string(e.final_attitude_rad));
  std::printf(
      "round trip at %.0f Hz: final position error %.3e m, attitude %.3e rad, velocity "
      "%.3e m/s; max position %.3e m, attitude %.3e rad\n",
      kRateHz, e.final_position_m, e.final_attitude_rad, e.final_velocity_m_s, e.max_position_m,
      e.max_attitude_rad);
  // The goal (issue "IMS core", point 5); the synthesised increments are exact to ~1e-17 rad
  // (ims/imu_synthesis.hpp), so what remains is the mechanization's own error.
  EXPECT_LT(e.final_position_m, 1e-6);
  EXPECT_LT(e.final_attitude_rad, 1e-6);
  EXPECT_LT(e.max_position_m, 1e-6);
}

TEST_F(StrapdownRoundTrip, FailsWithoutEarthRate) {
  ims::StrapdownOptions options;
  options.earth_rate = false;
  const RoundTripErrors e = run(options);
  std::printf("without Earth rate: final position error %.3e m, attitude %.3e rad\n",
              e.final_position_m, e.final_attitude_rad);
  // 7.3e-5 rad/s unremoved for 60 s tilts the frame by ~4 mrad: metres of position error.
  EXPECT_GT(e.final_position_m, 1e-4);
}

TEST_F(StrapdownRoundTrip, FailsWithoutCoriolis) {
  ims::StrapdownOptions options;
  options.coriolis = false;
  const RoundTripErrors e = run(options);
  std::printf("without Coriolis: final position error %.3e m, max %.3e m\n", e.final_position_m,
              e.max_position_m);
  // 2 omega_ie v ~ 1.5e-4 m/s^2 at 1 m/s for ~2 s per move: ~0.1 mm per move, accumulated
  // as velocity over the remaining run.
  EXPECT_GT(e.max_position_m, 1e-4);
}

TEST_F(StrapdownRoundTrip, CommandLineMechanizesAFile) {
  // The same increments through a CSV file and `imscal mechanize`; the file holds the values
  // in shortest round-trip form, so the goal must hold here as well.
  namespace fs = std::filesystem;
  const fs::path dir =
      fs::temp_directory_path() /
      ("imscal_mechanize_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path imu = dir / "imu.csv";
  ims::write_imu_file(imu, *increments_, imscal::Overwrite::kAllow);
  // The motion starts at identity attitude: roll = pitch = heading = 0.
  ASSERT_LT(motion_->at(motion_->begin_s()).q_W_S.vec().norm(), 1e-15);
  const std::string command = std::string(IMSCAL_BINARY) + " mechanize --input " + imu.string() +
                              " --out " + (dir / "out").string() +
                              " --initial-attitude 0,0,0 --site 48.7,9.1,380 > " +
                              (dir / "log.txt").string() + " 2>&1";
  ASSERT_EQ(std::system(command.c_str()), 0) << command;
  const ims::NavTrajectory read = ims::read_trajectory_csv(dir / "out" / "trajectory.csv");
  ASSERT_EQ(read.states.size(), increments_->samples.size() + 1);
  const ims::NavState& last = read.states.back();
  const ims::KinematicState truth = motion_->at(last.t_s);
  EXPECT_LT((last.p_W - truth.p_W).norm(), 1e-6);
  EXPECT_LT(ims::rotation_angle_between(last.q_W_S, truth.q_W_S), 1e-6);
  EXPECT_TRUE(fs::exists(dir / "out" / "trajectory.tum"));
  // Existing outputs are refused without --force, and nothing is touched.
  EXPECT_NE(std::system(command.c_str()), 0);
  EXPECT_EQ(std::system((command + " --force").c_str()), 0);
  fs::remove_all(dir);
}
