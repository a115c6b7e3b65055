// The IMS stillness check of a rest (calib/rest_stillness.hpp) on synthetic records with a
// closed-form truth: the sensor rests at a fixed point of the lab site (navigation-grade IMS,
// datasets/sensors/navigation-grade.yaml, every error drawn per seed), and turns at a known rate
// about a known axis over a known span. The ideal increments come from a spline through the
// poses (ims/spline_trajectory.hpp), the errors from ims::corrupt.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <random>

#include "calib/rest_stillness.hpp"
#include "ims/imu_noise.hpp"
#include "ims/imu_synthesis.hpp"
#include "ims/so3.hpp"
#include "ims/spline_trajectory.hpp"

namespace imscal::calib {
namespace {

namespace fs = std::filesystem;

const ims::Site kSite{48.78232, 9.18162, 245.4};  // the shipped scenarios' lab in Stuttgart

const ims::SensorSpec& spec() {
  static const ims::SensorSpec s = ims::load_sensor_spec(fs::path(IMSCAL_SOURCE_DIR) / "datasets" /
                                                         "sensors" / "navigation-grade.yaml");
  return s;
}

// The sensor's rotation angle about `axis_W` at t: `rate_rad_s` over [t_begin, t_end], constant
// before and after.
struct Slide {
  Eigen::Vector3d axis_W = Eigen::Vector3d::UnitX();
  double rate_rad_s = 0.0;
  double t_begin_s = 0.0, t_end_s = 0.0;
  double angle_at(double t) const {
    return rate_rad_s * (std::clamp(t, t_begin_s, t_end_s) - t_begin_s);
  }
};

// An ideal record of duration_s at 1 kHz: the sensor at attitude R_W_S0, turned by the slide.
ims::ImuSeries ideal_record(const Eigen::Matrix3d& R_W_S0, const Slide& slide, double duration_s) {
  std::vector<ims::PoseSample> poses;
  for (double t = 0.0; t <= duration_s + 1e-9; t += 0.01) {
    const Eigen::Matrix3d R =
        Eigen::AngleAxisd(slide.angle_at(t), slide.axis_W).toRotationMatrix() * R_W_S0;
    poses.push_back({t, Eigen::Vector3d(0.3, -0.2, 0.8), Eigen::Quaterniond(R).normalized()});
  }
  const ims::SplineTrajectory trajectory(poses);
  return ims::synthesize_ideal_increments(trajectory, ims::EarthModel(kSite), 1000.0);
}

ims::ImuSeries noisy(const ims::ImuSeries& ideal, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  const ims::SensorErrorModel errors = ims::draw_sensor_errors(spec(), rng);
  return ims::corrupt(ideal, errors, spec(), rng());
}

Eigen::Matrix3d attitude(double roll, double pitch, double yaw) {
  return (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

TEST(RestStillness, ChiSquareQuantile) {
  // Closed form: chi-square(3) upper quantiles 7.815 (0.05), 16.266 (1e-3) from the tables.
  EXPECT_NEAR(chi_square_3_upper_quantile(0.05), 7.815, 1e-3);
  EXPECT_NEAR(chi_square_3_upper_quantile(1e-3), 16.266, 1e-3);
}

// A still record over many seeds: the share of rests flagged stays within the designed
// false-alarm rate (Bonferroni over the pairs of blocks makes it an upper bound).
TEST(RestStillness, StillRecordFalseAlarmRateAsDesigned) {
  const ims::EarthModel earth(kSite);
  const std::vector<Eigen::Matrix3d> attitudes = {attitude(0.0, 0.0, 0.3), attitude(1.2, -0.4, 2.0),
                                                  attitude(0.3, 1.5, -1.0),
                                                  attitude(3.1, 0.2, 0.0)};
  RestStillnessOptions loose;  // a high design rate, so that the count is measurable
  loose.false_alarm_per_rest = 0.05;
  const RestStillnessOptions shipped;  // 1e-3
  constexpr int kSeeds = 200;
  int flagged_loose = 0, flagged_shipped = 0;
  for (std::size_t a = 0; a < attitudes.size(); ++a) {
    const ims::ImuSeries ideal = ideal_record(attitudes[a], {}, 5.5);
    for (int s = 0; s < kSeeds / int(attitudes.size()); ++s) {
      const ims::ImuSeries imu = noisy(ideal, 100 * a + s);
      flagged_loose += assess_rest_stillness(imu, earth, spec(), 0.25, 5.25, {}, loose).flagged;
      flagged_shipped += assess_rest_stillness(imu, earth, spec(), 0.25, 5.25, {}, shipped).flagged;
    }
  }
  std::printf("still records flagged: %d of %d at a design rate of 0.05, %d at 1e-3\n",
              flagged_loose, kSeeds, flagged_shipped);
  // Tolerance: the design rate plus 3 binomial sigmas (0.05 * 200 = 10 +- 3.1).
  EXPECT_LE(flagged_loose, 10 + 3 * std::sqrt(kSeeds * 0.05 * 0.95));
  EXPECT_LE(flagged_shipped, 1);  // 0.2 expected
}

// A slow rotation of 1e-4 rad/s over 1.0 .. 3.0 s (a link sliding in its backlash), still
// after it: flagged, with the rate, and trimmed to the still part after 3.0 s within one block.
TEST(RestStillness, SlideIsFlaggedAndTrimmedToTheStillPart) {
  const ims::EarthModel earth(kSite);
  // About a horizontal axis (the accelerometers see the tilt), and about the vertical (only the
  // gyros see it).
  for (const Eigen::Vector3d& axis :
       {Eigen::Vector3d(0.6, 0.8, 0.0), Eigen::Vector3d(0.0, 0.0, 1.0)}) {
    Slide slide;
    slide.axis_W = axis;
    slide.rate_rad_s = 1e-4;
    slide.t_begin_s = 1.0;
    slide.t_end_s = 3.0;
    const ims::ImuSeries ideal = ideal_record(attitude(0.4, -0.7, 1.1), slide, 7.0);
    for (std::uint64_t seed = 1; seed <= 5; ++seed) {
      const RestStillness r =
          assess_rest_stillness(noisy(ideal, seed), earth, spec(), 0.5, 6.5, {});
      ASSERT_TRUE(r.flagged) << axis.transpose();
      EXPECT_TRUE(r.usable);
      // The still part: from the first whole block after the slide to the end (blocks of 0.25 s
      // from 0.5 s: 3.0 s is a block border; the spline rounds the slide's kinks within 0.01 s).
      EXPECT_NEAR(r.still_begin_ims_s, 3.0, 0.25 + 1e-9) << r.describe();
      EXPECT_NEAR(r.still_end_ims_s, 6.5, 1e-9);
      // The most significant pair spans the slide (block centres within a block of its ends)
      // and sees all of its 2e-4 rad (10 %: the tilt's noise per pair, ~6e-6 rad, and the
      // spline's rounding); the rate is that over the span.
      EXPECT_NEAR(r.unexplained_rotation_rad, 2e-4, 0.2e-4) << r.describe();
      EXPECT_NEAR(r.motion_begin_ims_s, 1.0, 0.25);
      EXPECT_NEAR(r.motion_end_ims_s, 3.0, 0.25);
      EXPECT_NEAR(r.rate_change_rad_s,
                  r.unexplained_rotation_rad / (r.motion_end_ims_s - r.motion_begin_ims_s), 1e-12);
      EXPECT_NE(r.describe().find("rad/s"), std::string::npos);
    }
  }
}

// A slide at a constant rate over the whole rest (the A5 of the shipped mounting scenario's
// poses 5 and 6, 2e-4 rad/s): the gyro rate is constant, yet the sensor turns against the
// Earth: flagged and not usable (no still part).
TEST(RestStillness, SlideOverTheWholeRestIsNotUsable) {
  const ims::EarthModel earth(kSite);
  for (const Eigen::Vector3d& axis :
       {Eigen::Vector3d(0.0, 1.0, 0.0), Eigen::Vector3d(0.0, 0.0, 1.0),
        Eigen::Vector3d(1.0, 0.0, 0.0)}) {
    Slide slide;
    slide.axis_W = axis;
    slide.rate_rad_s = 2e-4;
    slide.t_begin_s = 0.0;
    slide.t_end_s = 6.0;
    const ims::ImuSeries imu = noisy(ideal_record(attitude(0.4, -0.7, 1.1), slide, 6.0), 7);
    const RestStillness r = assess_rest_stillness(imu, earth, spec(), 0.5, 5.5, {});
    EXPECT_TRUE(r.flagged) << axis.transpose();
    EXPECT_FALSE(r.usable) << axis.transpose() << ": " << r.describe();
  }
}

// The same slide as above, seen by the robot's readings (the explained rotation is the slide's
// own angle): not flagged.
TEST(RestStillness, MotionTheReadingsExplainIsNotFlagged) {
  const ims::EarthModel earth(kSite);
  Slide slide;
  slide.axis_W = Eigen::Vector3d(0.6, 0.8, 0.0);
  slide.rate_rad_s = 1e-4;
  slide.t_begin_s = 1.0;
  slide.t_end_s = 3.0;
  const ims::ImuSeries imu = noisy(ideal_record(attitude(0.4, -0.7, 1.1), slide, 7.0), 3);
  // Block mean of the slide's angle (the readings' frame need not be S: magnitudes are used).
  const ExplainedRotation explained = [&](double t0, double t1) {
    double sum = 0.0;
    int n = 0;
    for (double t = t0; t < t1; t += 0.002, ++n) sum += slide.angle_at(t);
    return Eigen::Vector3d(Eigen::Vector3d::UnitZ() * (sum / n));
  };
  const RestStillness r = assess_rest_stillness(imu, earth, spec(), 0.5, 6.5, explained);
  EXPECT_FALSE(r.flagged) << r.describe();
}

}  // namespace
}  // namespace imscal::calib
