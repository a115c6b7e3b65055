// The frame calibration's campaign figure with the plant effects on: simulation ->
// calibrate_session (calib/calibration_session.hpp, as `imscal calibrate` runs it: rest poses
// from the raw IMS record and the robot log, the initial clock offset, the bundle), over N seeds
// (50 in Release, 2 under IMSCAL_SANITIZED), each with a random base heading, a random IMS
// mount and a newly drawn IMS unit (biases, scale factors, misalignments, noise). The plant's
// motion does not depend on these draws (the base turns about the vertical only), so it is
// simulated once per scenario and the IMS record re-synthesised per seed from the same
// link-side motion.
//
// Reported per scenario: rests found, seeds calibrated or refused, the worst rotation/translation
// errors of T_S_H, the worst tilt (roll/pitch) and translation of T_R_W, and the heading,
// biases and time offset in units of their reported sigma (worst, and the share of all of them
// within 1/2/3 sigma: 68/95/99.7 % if the sigmas are honest). The accelerometer bias is compared
// with the bias the record carries over the first rest (turn-on plus the unit's in-run drift,
// ims::corrupt's InRunBias): the bundle models that drift and reports the first rest's bias.
// Goal: 0.005 deg / 0.05 mm, the rest within 3 sigma. Asserted is what the chain
// meets (see the comments at the asserts); the figures are printed for the report.
//
// Three scenarios: `mounting` as shipped (every plant effect), `mounting-rigid` (rigid drives)
// and `mounting` with the backlash off (a scratch copy), which shows what the other effects
// leave. The record is corrected with the unit's lab calibration (its drawn scale factors and
// misalignments, as the config's unit_calibration does in `imscal calibrate`).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <mutex>
#include <numbers>
#include <random>
#include <thread>

#include "calib/calibration_config.hpp"
#include "calib/calibration_session.hpp"
#include "calib/frame_calibration.hpp"
#include "core/input_error.hpp"
#include "core/units.hpp"
#include "ims/imu_noise.hpp"
#include "ims/imu_synthesis.hpp"
#include "ims/sensor_error_model.hpp"
#include "ims/so3.hpp"
#include "ims/spline_trajectory.hpp"
#include "sim/scenario.hpp"
#include "sim/simulation.hpp"
#include "sim/simulation_output.hpp"
#include "tests/support/scratch_dir.hpp"
#include "tests/support/text_file.hpp"

namespace imscal::calib {
namespace {

namespace fs = std::filesystem;

bool sanitized() {
  return std::getenv("IMSCAL_SANITIZED") != nullptr;
}

struct SeedOutcome {
  std::uint64_t seed = 0;
  std::size_t rests = 0;
  bool calibrated = false;
  bool converged = false;
  std::string refusal;
  double initial_dt_error_s = 0.0;
  double S_H_rotation_deg = 0.0, S_H_translation_mm = 0.0;
  double R_W_tilt_deg = 0.0, R_W_translation_mm = 0.0;
  double heading_sigmas = 0.0, gyro_bias_sigmas = 0.0, acc_bias_sigmas = 0.0, dt_sigmas = 0.0;
  std::vector<double> normalised_errors;  // |error| / sigma: heading, gyro and acc bias, dt
  double link_share = 0.0;
  std::size_t outliers = 0;
};

// Largest |error_k| / sigma_k of a 3-vector whose sigmas are named prefix.x/y/z; each one is
// also appended to `all`.
double worst_sigmas(const FrameCalibrationResult& r, const std::string& prefix,
                    const Eigen::Vector3d& error, std::vector<double>& all) {
  double worst = 0.0;
  const char* axes[3] = {"x", "y", "z"};
  for (int k = 0; k < 3; ++k) {
    all.push_back(std::abs(error[k]) / r.sigma(prefix + "." + axes[k]));
    worst = std::max(worst, all.back());
  }
  return worst;
}

// unit_calibration: correct the record with the unit's scale factors and misalignments as its
// lab calibration would (the drawn values exactly, biases left to the bundle), as `imscal
// calibrate` does with the config's unit_calibration.
SeedOutcome run_seed(const sim::Scenario& scenario, const sim::SimulationResult& base,
                     const RobotLog& log, std::uint64_t seed, double max_joint_spread_rad,
                     bool unit_calibration, double settle_tolerance_rad) {
  SeedOutcome o;
  o.seed = seed;
  std::mt19937_64 rng(seed * 7919 + 17);
  // Random base heading and mount (as sim/simulation.cpp draws them).
  std::uniform_real_distribution<double> yaw(-std::numbers::pi, std::numbers::pi);
  Eigen::Isometry3d T_W_R = scenario.T_W_R;
  T_W_R.linear() = Eigen::AngleAxisd(yaw(rng), Eigen::Vector3d::UnitZ()) * T_W_R.linear();
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::Vector3d rotation, translation;
  for (int i = 0; i < 3; ++i) rotation[i] = normal(rng) * scenario.mount_random_rotation_sigma_rad;
  for (int i = 0; i < 3; ++i) translation[i] = normal(rng) * scenario.mount_random_position_sigma_m;
  Eigen::Isometry3d perturbation = Eigen::Isometry3d::Identity();
  perturbation.linear() = ims::quat_exp<double>(rotation).toRotationMatrix();
  perturbation.translation() = translation;
  const Eigen::Isometry3d T_H_S = base.robot.tool.T_H_T * scenario.mount_offset * perturbation;

  // The IMS record of this mount from the plant's link-side motion.
  const std::vector<Eigen::Isometry3d> T_R_H = sim::flange_poses(base.robot, base.plant);
  std::vector<ims::PoseSample> poses(T_R_H.size());
  for (std::size_t k = 0; k < T_R_H.size(); ++k) {
    const Eigen::Isometry3d T_W_S = T_W_R * T_R_H[k] * T_H_S;
    poses[k] = {base.plant.samples[k].t_s, T_W_S.translation(),
                Eigen::Quaterniond(T_W_S.linear()).normalized()};
  }
  const ims::SplineTrajectory trajectory(poses);
  const ims::EarthModel earth(scenario.site);
  const ims::ImuSeries ideal =
      ims::synthesize_ideal_increments(trajectory, earth, scenario.imu_rate_hz);
  const ims::SensorErrorModel errors = ims::draw_sensor_errors(base.sensor_spec, rng);
  ims::InRunBias in_run;  // on the ideal series' (robot) clock
  ims::ImuSeries imu = ims::corrupt(ideal, errors, base.sensor_spec, rng(), &in_run);
  for (auto& s : imu.samples) s.t_s += scenario.imu_clock_offset_s;
  imu.site = scenario.site;
  if (unit_calibration) {
    ims::SensorErrorModel lab = errors;
    lab.gyro.bias.setZero();
    lab.acc.bias.setZero();
    imu = ims::correct(imu, lab);
  }

  // As `imscal calibrate` with the shipped defaults (calib::calibrate_session), without the
  // halves, segments and joint errors: rests, initial dt, rests again, bundle.
  SessionOptions options;
  options.config = load_calibration_config(fs::path(IMSCAL_SOURCE_DIR) / "datasets" /
                                           "calibration" / "calibrate-default.yaml");
  CalibrationConfig& config = options.config;
  if (max_joint_spread_rad > 0.0) config.rests.max_joint_spread_rad = max_joint_spread_rad;
  config.rests.settle_tolerance_rad = settle_tolerance_rad;
  config.validation.check_halves = false;
  config.validation.check_segments = false;
  config.joint_errors = false;
  SessionInputs session;
  session.imu = std::move(imu);
  session.log = log;
  session.robot = base.robot;
  session.sensor = base.sensor_spec;
  session.source = "campaign";
  try {
    const SessionResult result = calibrate_session(session, options);
    o.initial_dt_error_s = result.initial_time_offset.offset_s - scenario.imu_clock_offset_s;
    o.rests = result.rests.rests.size();
    const FrameCalibrationResult& r = result.frames;
    const std::vector<RestObservation>& rests = result.rests.rests;
    o.calibrated = true;
    o.converged = r.converged;
    for (const auto* list : {&r.rest_residuals, &r.motion_residuals})
      for (const auto& p : *list) o.outliers += p.outlier;

    // Errors against the truth (T_R_W in the bundle's W-origin convention).
    const Eigen::Isometry3d T_S_H_true = T_H_S.inverse();
    o.S_H_rotation_deg = ims::quat_log<double>(
                             Eigen::Quaterniond(r.T_S_H.linear() * T_S_H_true.linear().transpose()))
                             .norm() /
                         kRadPerDeg;
    o.S_H_translation_mm = (r.T_S_H.translation() - T_S_H_true.translation()).norm() * 1e3;
    const Eigen::Matrix3d R_W_R = r.T_R_W.linear().transpose();
    const Eigen::Vector3d rotation_error_W =
        ims::quat_log<double>(Eigen::Quaterniond(R_W_R * T_W_R.linear().transpose()));
    o.R_W_tilt_deg = rotation_error_W.head<2>().norm() / kRadPerDeg;
    o.heading_sigmas = std::abs(rotation_error_W.z()) / r.sigma("R_W_R.up");
    o.normalised_errors.push_back(o.heading_sigmas);
    // The true link angles at the middle of the first rest (robot clock).
    const double t_first =
        0.5 * (rests.front().begin_ims_s + rests.front().end_ims_s) - scenario.imu_clock_offset_s;
    std::size_t k = 0;
    while (k + 1 < base.plant.samples.size() && base.plant.samples[k].t_s < t_first) ++k;
    const Eigen::Isometry3d T_R_W_true = frame_calibration_truth_convention(
        T_W_R.inverse(), T_S_H_true, base.robot.kinematics, base.plant.samples[k].q_link_rad);
    o.R_W_translation_mm = (r.T_R_W.translation() - T_R_W_true.translation()).norm() * 1e3;
    // The gyro's in-run drift (0.003 deg/h over an hour) is far below the gyro bias's sigma:
    // its turn-on bias is the truth. The accelerometer's: the mean over the first rest.
    o.gyro_bias_sigmas =
        worst_sigmas(r, "gyro_bias", r.biases.gyro_rad_s - errors.gyro.bias, o.normalised_errors);
    Eigen::Vector3d in_run_acc = Eigen::Vector3d::Zero();
    int in_run_count = 0;
    for (std::size_t s = 0; s < in_run.t_s.size(); ++s) {
      const double t_ims = in_run.t_s[s] + scenario.imu_clock_offset_s;
      if (t_ims > rests.front().begin_ims_s && t_ims <= rests.front().end_ims_s) {
        in_run_acc += in_run.acc_m_s2[s];
        ++in_run_count;
      }
    }
    const Eigen::Vector3d acc_bias_true = errors.acc.bias + in_run_acc / std::max(in_run_count, 1);
    o.acc_bias_sigmas =
        worst_sigmas(r, "acc_bias", r.biases.acc_m_s2 - acc_bias_true, o.normalised_errors);
    o.dt_sigmas =
        std::abs(r.time_offset_s - scenario.imu_clock_offset_s) / r.sigma("time_offset.dt");
    o.normalised_errors.push_back(o.dt_sigmas);
    o.link_share = r.link_share;
  } catch (const InputError& e) {
    o.refusal = e.what();
  }
  return o;
}

struct CampaignFigures {
  std::size_t seeds = 0, calibrated = 0, converged = 0;
  std::size_t min_rests = 1000, max_rests = 0;
  double worst_initial_dt_ms = 0.0;
  double S_H_rotation_deg = 0.0, S_H_translation_mm = 0.0, R_W_tilt_deg = 0.0,
         R_W_translation_mm = 0.0, heading_sigmas = 0.0, gyro_bias_sigmas = 0.0,
         acc_bias_sigmas = 0.0, dt_sigmas = 0.0;
  // Shares of all normalised errors (heading, biases, dt of every seed) within 1, 2, 3 sigma.
  double within_1 = 0.0, within_2 = 0.0, within_3 = 0.0;
  double mean_link_share = 0.0;
  std::size_t worst_outliers = 0;
  std::string first_refusal;
};

// max_joint_spread_rad: 0 for the shipped default (1e-5 rad).
CampaignFigures run_campaign(const fs::path& scenario_file, const std::string& label,
                             std::size_t release_seeds, double max_joint_spread_rad = 0.0,
                             bool unit_calibration = true, double settle_tolerance_rad = 0.0) {
  const sim::Scenario scenario = sim::load_scenario(scenario_file);
  const std::size_t seeds = sanitized() ? 2 : release_seeds;
  // Under the sanitizers the plant (~15 s in Release) runs the first 60 s only (7 rests).
  const double duration = sanitized() ? 60.0 : std::numeric_limits<double>::infinity();
  const sim::SimulationResult base = sim::run_simulation(scenario, scenario.seed, {}, duration);
  const RobotLog log = sim::make_robot_log(base);

  std::vector<SeedOutcome> outcomes(seeds);
  std::mutex mutex;
  std::size_t next = 0;
  auto worker = [&] {
    for (;;) {
      std::size_t i;
      {
        std::lock_guard<std::mutex> lock(mutex);
        if (next >= seeds) return;
        i = next++;
      }
      outcomes[i] = run_seed(scenario, base, log, 1000 + i, max_joint_spread_rad, unit_calibration,
                             settle_tolerance_rad);
    }
  };
  std::thread a(worker), b(worker);  // 2 cores
  a.join();
  b.join();

  CampaignFigures f;
  f.seeds = seeds;
  std::size_t normalised = 0;
  for (const auto& o : outcomes) {
    for (double z : o.normalised_errors) {
      f.within_1 += z <= 1.0;
      f.within_2 += z <= 2.0;
      f.within_3 += z <= 3.0;
      ++normalised;
    }
    f.min_rests = std::min(f.min_rests, o.rests);
    f.max_rests = std::max(f.max_rests, o.rests);
    f.worst_initial_dt_ms = std::max(f.worst_initial_dt_ms, std::abs(o.initial_dt_error_s) * 1e3);
    if (!o.calibrated) {
      if (f.first_refusal.empty()) f.first_refusal = o.refusal;
      continue;
    }
    ++f.calibrated;
    f.converged += o.converged;
    f.S_H_rotation_deg = std::max(f.S_H_rotation_deg, o.S_H_rotation_deg);
    f.S_H_translation_mm = std::max(f.S_H_translation_mm, o.S_H_translation_mm);
    f.R_W_tilt_deg = std::max(f.R_W_tilt_deg, o.R_W_tilt_deg);
    f.R_W_translation_mm = std::max(f.R_W_translation_mm, o.R_W_translation_mm);
    f.heading_sigmas = std::max(f.heading_sigmas, o.heading_sigmas);
    f.gyro_bias_sigmas = std::max(f.gyro_bias_sigmas, o.gyro_bias_sigmas);
    f.acc_bias_sigmas = std::max(f.acc_bias_sigmas, o.acc_bias_sigmas);
    f.dt_sigmas = std::max(f.dt_sigmas, o.dt_sigmas);
    f.worst_outliers = std::max(f.worst_outliers, o.outliers);
    f.mean_link_share += o.link_share;
  }
  if (normalised > 0) {
    f.within_1 /= double(normalised);
    f.within_2 /= double(normalised);
    f.within_3 /= double(normalised);
  }
  if (f.calibrated > 0) f.mean_link_share /= double(f.calibrated);
  std::printf(
      "campaign %s: %zu seeds, rests found %zu..%zu, calibrated %zu, converged %zu, worst "
      "initial dt error %.3f ms\n",
      label.c_str(), f.seeds, f.min_rests, f.max_rests, f.calibrated, f.converged,
      f.worst_initial_dt_ms);
  if (f.calibrated)
    std::printf(
        "campaign %s worst: T_S_H %.5f deg %.4f mm | T_R_W tilt %.5f deg, translation %.4f mm | "
        "heading %.2f sigma | gyro bias %.2f sigma | acc bias %.2f sigma | dt %.2f sigma | "
        "outlier blocks %zu (goal 0.005 deg, 0.05 mm, 3 sigma)\n"
        "campaign %s sigmas: heading, biases and dt within 1/2/3 sigma %.2f / %.2f / %.2f "
        "(honest: 0.68 / 0.95 / 0.997); link share of the viscous friction %.3f (mean)\n",
        label.c_str(), f.S_H_rotation_deg, f.S_H_translation_mm, f.R_W_tilt_deg,
        f.R_W_translation_mm, f.heading_sigmas, f.gyro_bias_sigmas, f.acc_bias_sigmas, f.dt_sigmas,
        f.worst_outliers, label.c_str(), f.within_1, f.within_2, f.within_3, f.mean_link_share);
  if (!f.first_refusal.empty())
    std::printf("campaign %s first refusal: %s\n", label.c_str(), f.first_refusal.c_str());
  return f;
}

TEST(CalibrateCampaign, MountingScenarioAsShipped) {
  const CampaignFigures f = run_campaign(
      fs::path(IMSCAL_SOURCE_DIR) / "datasets" / "scenarios" / "mounting.yaml", "mounting", 50);
  // Met: the initial clock offset from the cross-correlation of rate magnitudes, within 1 ms of
  // the simulated 12.3 ms (the robot cycle is 2 ms; the correlation peak is sub-sample).
  EXPECT_LT(f.worst_initial_dt_ms, 1.0);
  if (sanitized()) {
    // The first 60 s hold poses 1-7, of which only pose 4 is still for the IMS (see below): the
    // stillness check leaves 1-2 rests and the chain refuses with its defined message (the
    // bundle itself runs under the sanitizers in MountingRigid and MountingWithoutBacklash,
    // which also carry the initial clock offset's check there: a refused session returns none).
    EXPECT_EQ(f.calibrated, 0u);
    EXPECT_NE(f.first_refusal.find("at least 3 are needed"), std::string::npos) << f.first_refusal;
    return;
  }
  // Met: every seed keeps enough rests (7-10 of 14; before the bundle modelled the joint
  // controllers' creep at the rests, the readings' 1e-5 rad stillness limit left 2-4 and 21 of
  // 50 seeds were refused) and converges from the automatic initial values.
  EXPECT_EQ(f.calibrated, f.seeds);
  EXPECT_EQ(f.calibrated, f.converged);
  // Links whose gears carry (almost) no load slide inside their backlash at rest where the
  // encoders cannot see it (A5 of poses 5 and 6 at 2e-4 rad/s over the whole rest, A4 of poses
  // 1, 2, 3, 7 and 14 by up to 4.5e-4 rad, decaying over seconds; truth/joints.csv, the motor
  // still): the plant's smooth Coulomb law has no static friction to hold them. The IMS
  // stillness check (calib/rest_stillness.hpp) drops those rests (4-7 per seed; none is still
  // long enough to be trimmed), so 7-10 rests remain.
  // Measured (worst of 50): T_S_H 0.0148 deg / 0.192 mm, T_R_W tilt 0.0090 deg, translation
  // 0.263 mm, heading 4.8 sigma, gyro bias 5.7 sigma, acc bias 4.4 sigma, dt 0.96 sigma, up to
  // 6 outlier blocks; heading, biases and dt within 1/2/3 sigma 0.51 / 0.81 / 0.94.
  // Before the stillness check (all 13-14 rests, the sliding ones too): T_S_H 0.0055 deg /
  // 0.109 mm, tilt 0.0099 deg, translation 0.274 mm, heading 7.4, gyro bias 11, acc bias 8.3
  // sigma, 11 outlier blocks, within 1/2/3 sigma 0.25 / 0.40 / 0.53: more precise-looking, but
  // not honest. Still not honest (goal 0.68 / 0.95 / 0.997): slides too slow for the check over
  // a rest (about an axis across both the vertical and the horizontal Earth rate only the
  // accelerometers resolve, ~6e-6 rad/s over 5 s) still bias the gyro means; T_S_H misses the
  // goal with half of the rests gone. Asserted: the 3-sigma goal for dt (met); the
  // others with a 2x margin on the measured worst, the sigma shares with room for 50 draws
  // (0.40, 0.70, 0.85), so that the chain does not fall back behind what it reaches here.
  EXPECT_GE(f.min_rests, 6u);
  EXPECT_LT(f.S_H_rotation_deg, 0.03);
  EXPECT_LT(f.S_H_translation_mm, 0.4);
  EXPECT_LT(f.R_W_tilt_deg, 0.02);
  EXPECT_LT(f.dt_sigmas, 3.0);
  EXPECT_LT(f.heading_sigmas, 10.0);
  EXPECT_LT(f.gyro_bias_sigmas, 11.0);
  EXPECT_GT(f.within_1, 0.40);
  EXPECT_GT(f.within_2, 0.70);
  EXPECT_GT(f.within_3, 0.85);
  EXPECT_LE(f.worst_outliers, 12u);
}

TEST(CalibrateCampaign, MountingRigid) {
  // tests/data/scenarios/mounting-rigid.yaml: the same poses on rigid drives (internal reading =
  // link angle; the robot file's wind-up and play are not there, the bundle's deflection scales
  // find that) with the unit's lab calibration applied. 10 seeds (2 under the sanitizers).
  // The rests are used from where the joints have settled within 3e-7 rad of their final
  // reading (calib/rest_poses.hpp; off in the shipped config, where creeping elastic drives
  // would lose their rests): without it the worst seed keeps one outlier block and the tilt
  // reaches 0.0057 deg.
  const CampaignFigures f =
      run_campaign(fs::path(IMSCAL_TEST_DATA_DIR) / "scenarios" / "mounting-rigid.yaml", "rigid",
                   10, 0.0, true, 3e-7);
  EXPECT_LT(f.worst_initial_dt_ms, 1.0);  // as above
  EXPECT_EQ(f.calibrated, f.seeds);
  EXPECT_EQ(f.calibrated, f.converged);
  if (sanitized()) return;  // 60 s, 7 rests: the figures below are those of the full record
  // Measured over the 10 seeds (worst): T_S_H 0.0019 deg / 0.030 mm, T_R_W tilt 0.0052 deg,
  // translation 0.088 mm, heading 2.4 sigma, gyro bias 1.8 sigma, acc bias 2.8 sigma, dt 1.7
  // sigma, no outlier block; heading, biases and dt within 1/2/3 sigma 0.66 / 0.95 / 1.00. The
  // accelerometer bias is that of the first rest (the unit's in-run drift, 10 ug over 600 s,
  // moves it by ~5 ug over the record: against the turn-on bias alone it was 97 sigma off, and
  // 18 sigma against the first rest's bias while the bundle took the bias as constant).
  // Asserted: the goals where met (T_S_H 0.005 deg / 0.05 mm; 3 sigma), the share within
  // 1 and 2 sigma with room for 80 draws (0.55, 0.85), the tilt at 0.01 deg (met at 0.0052 with
  // little margin) and the T_R_W translation at 0.2 mm (not met: the unloaded A1's play prior,
  // b / sqrt(12) = 8e-5 rad at the first rest, is 0.09 mm there, and no IMS measurement tells
  // A1's angle from the heading of the base).
  EXPECT_LT(f.S_H_rotation_deg, 0.005);
  EXPECT_LT(f.S_H_translation_mm, 0.05);
  EXPECT_LT(f.R_W_tilt_deg, 0.01);
  EXPECT_LT(f.R_W_translation_mm, 0.2);
  EXPECT_LT(f.heading_sigmas, 3.0);
  EXPECT_LT(f.gyro_bias_sigmas, 3.0);
  EXPECT_LT(f.acc_bias_sigmas, 3.0);
  EXPECT_LT(f.dt_sigmas, 3.0);
  EXPECT_GT(f.within_1, 0.55);
  EXPECT_GT(f.within_2, 0.85);
  EXPECT_EQ(f.worst_outliers, 0u);
}

using CalibrateCampaignScratch = test_support::ScratchDirTest;

TEST_F(CalibrateCampaignScratch, MountingWithoutBacklash) {
  // The shipped scenario with the backlash off, paths made absolute for the scratch copy.
  const fs::path datasets = fs::path(IMSCAL_SOURCE_DIR) / "datasets";
  std::string text = test_support::read_text(datasets / "scenarios" / "mounting.yaml");
  // Every occurrence: the scenario names the robot twice (the plant and the nominal robot).
  auto replace = [&](const std::string& from, const std::string& to) {
    ASSERT_NE(text.find(from), std::string::npos) << from;
    for (auto at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size()))
      text.replace(at, from.size(), to);
  };
  replace("../robots/", (datasets / "robots").string() + "/");
  replace("../programs/", (datasets / "programs").string() + "/");
  replace("../sensors/", (datasets / "sensors").string() + "/");
  replace("backlash: true", "backlash: false");
  std::ofstream(dir_ / "mounting-no-backlash.yaml") << text;
  // 10 seeds (the brief's 50 are spent on the shipped scenario; this one shows what limits the
  // rest of the chain). The elastic drives still creep after every move (up to 1.5e-4 rad over
  // a rest; the joint controllers settle through friction), the bundle models that creep from
  // the joint readings (RestObservation::q_creep_*). The unit's lab calibration is applied (as
  // for `rigid`); the shipped rest options.
  const CampaignFigures f = run_campaign(dir_ / "mounting-no-backlash.yaml", "no-backlash", 10);
  EXPECT_LT(f.worst_initial_dt_ms, 1.0);  // as above
  // Met: every seed finds >= 3 rests (13-14) and converges from the automatic initial values,
  // and the time offset lies within 3 sigma of the truth. The time offset is estimated with the
  // share of the drives' viscous friction at the gear output (the link lags the motor-side
  // readings by share * c / k, which looks like a clock offset: with the plant's 0.1 of it the
  // offset alone came out 0.047 ms = 3.2 sigma off; estimated share 0.15 +- 0.05, dt 0.84 sigma).
  EXPECT_EQ(f.calibrated, f.seeds);
  EXPECT_EQ(f.calibrated, f.converged);
  EXPECT_LT(f.dt_sigmas, 3.0);
  if (sanitized()) return;
  // Measured (worst of 10): T_S_H 0.0023 deg / 0.043 mm, T_R_W tilt 0.0042 deg (0.0051
  // before the IMS stillness check, which keeps all 14 rests here but trims some to where the
  // IMS is still), translation 0.121 mm, heading 2.1 sigma, gyro bias 1.6 sigma, acc bias 3.1
  // sigma, dt 0.84 sigma, no outlier block; within 1/2/3 sigma 0.79 / 0.95 / 0.99. Before the creep
  // and the bias drift were modelled: T_S_H 0.0043 deg / 0.108 mm, heading 6.2, gyro bias 4.9, acc
  // bias 77 sigma, 15 of 27 blocks outliers. Asserted: the goals for T_S_H and the 3-sigma
  // bounds where met, the sigma shares as for `rigid`, the tilt at 0.01 deg; the T_R_W translation
  // is not met (0.12 mm, the unloaded A1's play prior at the first rest, see `rigid`).
  EXPECT_LT(f.S_H_rotation_deg, 0.005);
  EXPECT_LT(f.S_H_translation_mm, 0.05);
  EXPECT_LT(f.R_W_tilt_deg, 0.01);
  EXPECT_LT(f.heading_sigmas, 3.0);
  EXPECT_LT(f.gyro_bias_sigmas, 3.0);
  EXPECT_GT(f.within_1, 0.55);
  EXPECT_GT(f.within_2, 0.85);
  EXPECT_EQ(f.worst_outliers, 0u);
}

}  // namespace
}  // namespace imscal::calib
