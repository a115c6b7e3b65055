// Kinematic calibration from laser-tracker positions: the deviations put into a simulated UR10
// are found within their 1σ-based bounds, the parameters the poses cannot separate are the ones
// the geometry predicts, and on a real UR10 (IPA data set, tests/data/real/ipa-ur10/SOURCE.md) the
// calibrated model predicts held-out tracker positions better than the nominal one.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "calib/kinematic_calibration.hpp"
#include "calib/tracker_poses.hpp"
#include "core/input_error.hpp"
#include "robot/forward_kinematics.hpp"
#include "robot/urdf_robot.hpp"
#include "tests/support/record_figure.hpp"
#include "tests/support/scratch_dir.hpp"

namespace imscal::calib {
namespace {

const std::filesystem::path kRobots = std::filesystem::path(IMSCAL_SOURCE_DIR) / "datasets/robots";
const std::filesystem::path kTracker =
    std::filesystem::path(IMSCAL_TEST_DATA_DIR) / "real/ipa-ur10";

double rms(const std::vector<double>& values) {
  double sum = 0.0;
  for (double v : values) sum += v * v;
  return std::sqrt(sum / static_cast<double>(values.size()));
}

int index_of(const std::string& name) {
  const std::vector<std::string> names = kinematic_parameter_names();
  return static_cast<int>(std::find(names.begin(), names.end(), name) - names.begin());
}

// A UR10 whose DH parameters deviate from the nominal ones, seen by a tracker.
struct SimulatedCell {
  KinematicModel truth;
  Eigen::Isometry3d T_tracker_base = Eigen::Isometry3d::Identity();
  Eigen::Vector3d target_m{0.3e-3, -0.2e-3, 0.093};
  std::vector<std::pair<std::string, double>> deviations{
      {"dtheta2", 8e-4}, {"da2", 0.7e-3},     {"dalpha2", -3e-4}, {"dtheta3", 5e-4},
      {"da3", -0.2e-3},  {"dalpha3", 1.5e-3}, {"dd2", -0.15e-3},  {"dtheta5", -8e-4},
      {"dd5", 0.2e-3},   {"da1", -0.2e-3},    {"dalpha4", 6e-4}};

  explicit SimulatedCell(const KinematicModel& nominal) : truth(nominal) {
    for (const auto& [name, value] : deviations) {
      const int i = (index_of(name) - kDhIndex) / 4;
      const int which = (index_of(name) - kDhIndex) % 4;
      double* fields[] = {&truth.dh[i].offset_rad, &truth.dh[i].d_m, &truth.dh[i].a_m,
                          &truth.dh[i].alpha_rad};
      *fields[which] += value;
    }
    T_tracker_base.linear() =
        Eigen::AngleAxisd(2.8, Eigen::Vector3d(0.01, 0.02, 1).normalized()).toRotationMatrix();
    T_tracker_base.translation() = Eigen::Vector3d(0.5, -3.5, -1.2);
  }

  // count poses at random joints (±π per joint), tracker noise sigma_m per axis.
  std::vector<TrackerPose> poses(int count, double sigma_m, unsigned seed) const {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> joint(-M_PI, M_PI);
    std::normal_distribution<double> noise(0.0, sigma_m);
    std::vector<TrackerPose> out;
    for (int k = 0; k < count; ++k) {
      TrackerPose p;
      for (int i = 0; i < kJointCount; ++i) p.q_rad(i) = joint(rng);
      p.p_tracker_m = T_tracker_base * (forward_kinematics<double>(truth, p.q_rad) * target_m);
      for (int a = 0; a < 3; ++a) p.p_tracker_m(a) += noise(rng);
      out.push_back(p);
    }
    return out;
  }
};

// 300 simulated poses with 20 µm tracker noise (a laser tracker's order). Every estimated
// deviation lies within 4σ of the truth (4σ: 14 DH deviations checked, a 1-in-16000 miss each); the
// dropped set is the one the geometry predicts: joint 1's Δθ and Δd (the base frame takes them),
// Δd of joints 3 and 4 (axes 2, 3, 4 parallel: only the sum of their d is seen, kept in Δd2),
// all of joint 6 (the target position on the flange takes them) and joint 5's Δa and Δα (0.1 % of
// their effect is independent, through the target's 0.36 mm offset from the flange axis). Held-out
// prediction error: the noise, RMS of |r| = sqrt(3) × 20 µm = 35 µm, bound 45 µm.
TEST(KinematicCalibration, FindsSimulatedDeviations) {
  const KinematicModel nominal = load_urdf_robot(kRobots / "ur10.urdf").kinematics;
  const SimulatedCell cell(nominal);
  const KinematicCalibration c = calibrate_kinematics(nominal, cell.poses(300, 20e-6, 5));
  const std::set<std::string> expected_dropped{"dtheta1", "dd1",     "dd3", "dd4", "da5",
                                               "dalpha5", "dtheta6", "dd6", "da6", "dalpha6"};
  std::set<std::string> dropped;
  for (const KinematicParameter& p : c.parameters) {
    if (!p.estimated) dropped.insert(p.name);
  }
  EXPECT_EQ(dropped, expected_dropped);
  for (int k = kDhIndex; k < kKinematicParameterCount; ++k) {
    const KinematicParameter& p = c.parameters[k];
    if (!p.estimated) continue;
    double truth = 0.0;
    for (const auto& [name, value] : cell.deviations) {
      if (name == p.name) truth = value;
    }
    EXPECT_LT(std::abs(p.value - truth), 4.0 * p.sigma) << p.name << " " << p.value << " " << truth;
    EXPECT_GT(p.sigma, 0.0) << p.name;
  }
  EXPECT_LT((c.p_H_target_m - cell.target_m).norm(), 0.2e-3);
  const double held_out_rms_m = rms(position_errors_m(c, cell.poses(200, 20e-6, 6)));
  std::printf("simulated: residual sigma %.1f um, held-out RMS %.1f um\n", c.residual_sigma_m * 1e6,
              held_out_rms_m * 1e6);
  EXPECT_LT(held_out_rms_m, 45e-6);
}

// The base-and-target-only fit of an exact nominal arm reproduces the tracker frame: noise-free
// poses, so only the solver's tolerance remains (1 µm, 1e-6 rad).
TEST(KinematicCalibration, NominalFitFindsTheTrackerFrame) {
  const KinematicModel nominal = load_urdf_robot(kRobots / "ur10.urdf").kinematics;
  SimulatedCell cell(nominal);
  cell.truth = nominal;
  KinematicCalibrationOptions options;
  options.estimate_geometry = false;
  const KinematicCalibration c = calibrate_kinematics(nominal, cell.poses(50, 0.0, 7), options);
  EXPECT_EQ(c.estimated_count, 9);
  EXPECT_LT((c.T_tracker_base.translation() - cell.T_tracker_base.translation()).norm(), 1e-6);
  EXPECT_LT((c.T_tracker_base.linear() - cell.T_tracker_base.linear()).norm(), 1e-6);
  EXPECT_LT((c.p_H_target_m - cell.target_m).norm(), 1e-6);
}

// Real UR10, first 400 poses of series C (random poses): the 1st, 3rd, ... fitted, the others
// held out. Measured: held-out RMS 0.962 mm nominal (with its own best base and target fit),
// 0.494 mm calibrated (whole series, 2773 poses: 0.992 -> 0.495 mm). Bounds: the nominal error
// above 0.8 mm (the signal is there), the calibrated one below 0.6 mm and below 0.6 × nominal.
// σ: the other half fitted alone gives deviations within 4σ (of the two fits' σ combined) of the
// first half's (measured: 1.8σ at worst over 23 parameters). Across sessions they differ more
// (series B against C: Δθ2 by 9σ): the deviations absorb what a session adds (temperature, the
// mix of IK branches), so the σ holds for the poses of one session.
TEST(KinematicCalibration, RealUr10PredictsHeldOutPosesBetter) {
  const KinematicModel nominal = load_urdf_robot(kRobots / "ur10.urdf").kinematics;
  const TrackerPoses data = read_tracker_poses(kTracker / "measurements_random_poses_head400.csv");
  ASSERT_EQ(data.poses.size(), 400u);
  std::vector<TrackerPose> fit, held_out;
  for (std::size_t k = 0; k < data.poses.size(); ++k) {
    (k % 2 == 0 ? fit : held_out).push_back(data.poses[k]);
  }
  KinematicCalibrationOptions nominal_only;
  nominal_only.estimate_geometry = false;
  const double nominal_mm =
      rms(position_errors_m(calibrate_kinematics(nominal, fit, nominal_only), held_out)) * 1e3;
  const KinematicCalibration c = calibrate_kinematics(nominal, fit);
  const double calibrated_mm = rms(position_errors_m(c, held_out)) * 1e3;
  const KinematicCalibration other = calibrate_kinematics(nominal, held_out);
  double worst_z = 0.0;
  std::string worst;
  for (int k = kDhIndex; k < kKinematicParameterCount; ++k) {
    const KinematicParameter& a = c.parameters[k];
    const KinematicParameter& b = other.parameters[k];
    if (!a.estimated || !b.estimated) continue;
    const double z = std::abs(a.value - b.value) / std::hypot(a.sigma, b.sigma);
    if (z > worst_z) {
      worst_z = z;
      worst = a.name;
    }
  }
  std::printf(
      "real UR10, held-out RMS: nominal %.3f mm, calibrated %.3f mm (%d parameters); halves "
      "differ by up to %.1f sigma (%s)\n",
      nominal_mm, calibrated_mm, c.estimated_count, worst_z, worst.c_str());
  test_support::record_figure("ur10_held_out_rms_nominal_mm", nominal_mm);
  test_support::record_figure("ur10_held_out_rms_calibrated_mm", calibrated_mm);
  EXPECT_GT(nominal_mm, 0.8);
  EXPECT_LT(calibrated_mm, 0.6);
  EXPECT_LT(calibrated_mm, 0.6 * nominal_mm);
  EXPECT_LT(worst_z, 4.0);
}

class TrackerPoseFiles : public test_support::ScratchDirTest {
 protected:
  std::filesystem::path write(const std::string& text) {
    const std::filesystem::path file = dir_ / "poses.csv";
    std::ofstream(file) << text;
    return file;
  }
};

TEST_F(TrackerPoseFiles, RefusesAMissingColumnAndDegrees) {
  const std::string header = "q1_rad,q2_rad,q3_rad,q4_rad,q5_rad,q6_rad,meas_x_mm,meas_y_mm";
  try {
    read_tracker_poses(write(header + "\n0,0,0,0,0,0,1,2\n"));
    FAIL() << "no meas_z_mm";
  } catch (const InputError& e) {
    EXPECT_EQ(e.line(), 1u);
    EXPECT_EQ(e.field(), "meas_z_mm");
  }
  try {
    read_tracker_poses(write(header + ",meas_z_mm\n0,0,0,0,0,0,1,2,3\n0,90,0,0,0,0,1,2,3\n"));
    FAIL() << "a joint in degrees";
  } catch (const InputError& e) {
    EXPECT_EQ(e.line(), 3u);
    EXPECT_EQ(e.field(), "q2_rad");
  }
  try {
    read_tracker_poses(
        write("q1_a_rad,q1_b_rad,q2_rad,q3_rad,q4_rad,q5_rad,q6_rad,meas_x_mm,"
              "meas_y_mm,meas_z_mm\n0,0,0,0,0,0,0,1,2,3\n"));
    FAIL() << "two columns for joint 1";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "q1_b_rad");
  }
}

}  // namespace
}  // namespace imscal::calib
