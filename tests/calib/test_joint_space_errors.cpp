// Joint-space errors from the IMS (calib/joint_space_errors.hpp), the chain's key figure: on
// the simulated `seed-line` run (the paper's test path, KR 16 with every drive effect, 5 kg,
// navigation-grade IMS), with the TRUE frames, biases and clock offset of the simulation (this
// isolates the joint-space step from the frame calibration), the joint errors recovered from the
// IMS match the simulator's true link-side errors q_desired - q_link. Goal: 0.01 mrad
// RMS on the lines.
//
// What limits it, measured here: after every move the simulated arm does not come to rest. Its
// joint controllers work the remaining position error (up to 4e-3 rad on A3) off through the
// friction for seconds (joint rates 1e-4..5e-3 rad/s, the flange moves by millimetres during the
// 3 s and 1 s "rests"), and its links ring against the motors for ~1 s. The IMS alone takes much
// of that creep for rest; the chain now asks the robot's readings during commanded standstill
// where the arm is really still and how it creeps (calib/encoder_motion.hpp). Each stop then
// leaves the trajectory ~50 um less certain (the unaided second after it, and the creep known
// only to ~1 % through the gears' transmission error), which is 0.1-0.3 mrad at the lines: the
// smoother's own sigma says so too. On an arm that rests between the moves the same chain reaches
// the IMS's noise floor (second test below).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <vector>

#include "calib/joint_space_errors.hpp"
#include "calib/rest_poses.hpp"
#include "core/config_node.hpp"
#include "core/input_error.hpp"
#include "ims/imu_noise.hpp"
#include "ims/imu_synthesis.hpp"
#include "ims/sensor_error_model.hpp"
#include "ims/spline_trajectory.hpp"
#include "ims/zupt_options.hpp"
#include "robot/forward_kinematics.hpp"
#include "robot/robot_description.hpp"
#include "sim/scenario.hpp"
#include "sim/simulation.hpp"
#include "sim/simulation_output.hpp"

namespace imscal::calib {
namespace {

namespace fs = std::filesystem;

// The shipped seed-line scenario, whose play of the joints that carry (almost) no gravity torque
// (A1 always, A4 and A6 in these poses) is closed: without static friction in the simulated play
// those links slide inside it at standstill (A4 by 2.2e-4 rad over the initial rest, the flange
// turning at 1.6e-4 rad/s at its start, against an Earth rate of 7.3e-5 rad/s), so the record
// would have no still start to align on. Every other effect is on.
sim::Scenario seed_line_scenario() {
  return sim::load_scenario(fs::path(IMSCAL_SOURCE_DIR) / "datasets" / "scenarios" /
                            "seed-line.yaml");
}

bool sanitized() {
  return std::getenv("IMSCAL_SANITIZED") != nullptr;
}

struct SimRun {
  sim::Scenario scenario;
  sim::SimulationResult sim;  // plant.samples: the truth (link angles) at a fixed interval
  RobotLog log;
  ims::ImuSeries imu;                       // the unit's scale and axes corrected
  std::vector<ims::NavState> sensor_truth;  // as sim.sensor_truth (IMS clock)
};

// Error correction as in the chain: the unit's scale factors and misalignments are known from its
// own calibration; the biases stay (the frames carry them).
ims::ImuSeries unit_corrected(const ims::ImuSeries& raw, ims::SensorErrorModel unit) {
  unit.gyro.bias.setZero();
  unit.acc.bias.setZero();
  return ims::correct(raw, unit);
}

const SimRun& seed_line() {
  static const SimRun run = [] {
    SimRun r;
    r.scenario = seed_line_scenario();
    // Sanitized builds: up to the end of the first line and into the 1 s pause.
    r.sim = sim::run_simulation(r.scenario, r.scenario.seed, {}, sanitized() ? 15.0 : 1e9);
    r.log = sim::make_robot_log(r.sim);
    r.imu = unit_corrected(r.sim.imu_raw, r.sim.sensor_errors);
    r.sensor_truth = r.sim.sensor_truth;
    return r;
  }();
  return run;
}

// The same program on an arm that does what it is told (link angles = desired angles = its
// readings, every 2 ms): it rests exactly when the program says so. The same IMS unit, noise
// drawn from the same seed.
const SimRun& ideal_seed_line() {
  static const SimRun run = [] {
    const SimRun& plant = seed_line();
    SimRun r;
    r.scenario = plant.scenario;
    r.sim = plant.sim;
    r.sim.plant.samples.clear();
    for (const sim::DesiredJointSample& d : r.sim.path.samples) {
      sim::PlantSample sample;
      sample.t_s = d.t_s;
      sample.q_link_rad = sample.q_motor_rad = d.q_rad;
      sample.qd_link_rad_s = d.qd_rad_s;
      r.sim.plant.samples.push_back(sample);
    }
    r.log = sim::make_robot_log(r.sim);
    const std::vector<Eigen::Isometry3d> T_R_H = sim::flange_poses(r.sim.robot, r.sim.plant);
    std::vector<ims::PoseSample> poses(T_R_H.size());
    for (std::size_t k = 0; k < T_R_H.size(); ++k) {
      const Eigen::Isometry3d T_W_S = r.sim.T_W_R * T_R_H[k] * r.sim.T_H_S;
      poses[k] = {r.sim.plant.samples[k].t_s, T_W_S.translation(),
                  Eigen::Quaterniond(T_W_S.linear()).normalized()};
    }
    const ims::SplineTrajectory trajectory(poses);
    const ims::EarthModel earth(r.scenario.site);
    const ims::ImuSeries ideal =
        ims::synthesize_ideal_increments(trajectory, earth, r.scenario.imu_rate_hz);
    r.sim.imu_in_run_bias = {};
    ims::ImuSeries raw = ims::corrupt(ideal, r.sim.sensor_errors, r.sim.sensor_spec,
                                      r.scenario.seed, &r.sim.imu_in_run_bias);
    const double offset = r.sim.imu_clock_offset_s;
    for (ims::ImuSample& sample : raw.samples) sample.t_s += offset;
    for (double& t : r.sim.imu_in_run_bias.t_s) t += offset;
    raw.site = r.scenario.site;
    r.imu = unit_corrected(raw, r.sim.sensor_errors);
    const auto truth_at = [&](double t_robot) {
      const ims::KinematicState state = trajectory.at(t_robot);
      return ims::NavState{t_robot + offset, state.q_W_S, state.v_W, state.p_W};
    };
    r.sensor_truth.push_back(truth_at(trajectory.begin_s()));
    for (const ims::ImuSample& sample : ideal.samples)
      r.sensor_truth.push_back(truth_at(sample.t_s));
    return r;
  }();
  return run;
}

JointSpaceInput true_input(const SimRun& run) {
  JointSpaceInput input;
  input.imu = &run.imu;
  input.log = &run.log;
  input.site = run.scenario.site;
  input.kinematics = run.sim.robot.kinematics;
  input.frames.T_R_W = run.sim.T_W_R.inverse();
  input.frames.T_S_H = run.sim.T_H_S.inverse();
  // The biases the record carries at its start: turn-on plus in-run part.
  input.frames.biases.gyro_rad_s =
      run.sim.sensor_errors.gyro.bias + run.sim.imu_in_run_bias.gyro_rad_s.front();
  input.frames.biases.acc_m_s2 =
      run.sim.sensor_errors.acc.bias + run.sim.imu_in_run_bias.acc_m_s2.front();
  input.frames.time_offset_s = run.sim.imu_clock_offset_s;
  // The first rest starts with the record; its link-side angles from the simulator.
  input.first_rest.begin_ims_s = run.sensor_truth.front().t_s;
  input.first_rest.end_ims_s = input.first_rest.begin_ims_s + 5.0;
  input.first_rest.q_link_rad = run.sim.plant.samples.front().q_link_rad;
  input.zupt = ims::zupt_options_from_spec(run.sim.sensor_spec);
  input.source = "seed-line";
  return input;
}

// Per-joint RMS over the samples for which `keep(t_robot)` holds of (q_measured - q_link), and of
// the smoother's sigma of q_measured [rad].
struct JointRms {
  JointVector error = JointVector::Zero();
  JointVector sigma = JointVector::Zero();
  int count = 0;
};

template <typename Keep>
JointRms rms_error(const SimRun& run, const JointSpaceErrors& errors, Keep keep) {
  const double plant_interval = run.sim.plant.samples[1].t_s - run.sim.plant.samples[0].t_s;
  JointRms out;
  for (std::size_t k = 0; k < errors.t_s.size(); ++k) {
    if (!keep(errors.t_s[k])) continue;
    const auto index = static_cast<std::size_t>(std::llround(errors.t_s[k] / plant_interval));
    const sim::PlantSample& truth = run.sim.plant.samples.at(index);
    EXPECT_NEAR(truth.t_s, errors.t_s[k], 1e-9);
    // Delta q from the IMS minus the true Delta q = q_link - q_measured.
    const JointVector difference = (errors.q_desired_rad[k] - errors.q_measured_rad[k]) -
                                   (errors.q_desired_rad[k] - truth.q_link_rad);
    out.error += difference.cwiseAbs2();
    out.sigma += errors.q_measured_sigma_rad[k].cwiseAbs2();
    ++out.count;
  }
  out.error = (out.error / std::max(out.count, 1)).cwiseSqrt();
  out.sigma = (out.sigma / std::max(out.count, 1)).cwiseSqrt();
  return out;
}

// Whether robot time t lies on one of the program's linear segments (the lines).
bool on_line(const SimRun& run, double t) {
  for (const sim::PathSegment& s : run.sim.path.segments)
    if (s.kind == sim::SegmentKind::kLinear && t >= s.begin_s && t <= s.end_s) return true;
  return false;
}

void print(const char* what, const JointVector& rms, int count) {
  std::printf("%-44s", what);
  for (int i = 0; i < kJointCount; ++i) std::printf(" A%d %7.4f", i + 1, rms(i) * 1e3);
  std::printf("  mrad RMS (%d samples)\n", count);
}

// The smoothed sensor trajectory against the truth (both on the IMS clock, same samples: the
// record starts with the first rest) [m].
double worst_position_error(const SimRun& run, const JointSpaceErrors& errors, double* at_s) {
  EXPECT_GT(errors.trajectory.size(), run.sensor_truth.size() / 2) << "trajectory not kept";
  double worst = 0.0;
  for (std::size_t k = 0; k < errors.trajectory.size() && k < run.sensor_truth.size(); ++k) {
    const ims::NavState& e = errors.trajectory[k].state;
    const ims::NavState& t = run.sensor_truth[k];
    EXPECT_NEAR(e.t_s, t.t_s, 1e-9);
    if ((e.p_W - t.p_W).norm() > worst) *at_s = e.t_s;
    worst = std::max(worst, (e.p_W - t.p_W).norm());
  }
  return worst;
}

// The default options with the smoothed trajectory kept (for worst_position_error).
JointSpaceOptions keeping_the_trajectory() {
  JointSpaceOptions options;
  options.keep_trajectory = true;
  return options;
}

void print_smoother(const JointSpaceErrors& errors) {
  const ims::ZuptSummary& s = errors.smoother;
  std::printf(
      "zero-velocity updates: %zu accepted, %zu rejected, mean NIS %.2f; velocity updates from "
      "the readings while creeping: %zu accepted, %zu rejected, mean NIS %.2f; rests %zu\n",
      s.zero_velocity.accepted, s.zero_velocity.rejected, s.zero_velocity.mean_nis,
      s.velocity_aid.accepted, s.velocity_aid.rejected, s.velocity_aid.mean_nis,
      s.rest_intervals.size());
  for (const auto& r : s.rest_intervals)
    std::printf("rest used %.3f .. %.3f s\n", r.begin_s, r.end_s);
}

TEST(JointSpaceErrors, MatchTheSimulatorsLinkSideErrorsOnSeedLine) {
  const SimRun& run = seed_line();
  const JointSpaceErrors errors = joint_space_errors(true_input(run), keeping_the_trajectory());
  print_smoother(errors);
  std::printf("robot samples: %zu kept, %zu outside the IMS record, %zu IK failures %s\n",
              errors.t_s.size(), errors.outside_record, errors.ik_failures,
              errors.first_ik_failure.c_str());
  double worst_at = 0.0;
  const double worst_position = worst_position_error(run, errors, &worst_at);
  std::printf("smoothed W_T_S vs truth: max position error %.4f mm (at %.2f s)\n",
              worst_position * 1e3, worst_at);
  EXPECT_EQ(errors.ik_failures, 0u);
  // The IMS clock runs 12.3 ms ahead: only the robot's last few samples lack IMS data... and
  // the record starts with the first rest, so at most the offset's worth is missing.
  EXPECT_LE(errors.outside_record, 10u);
  ASSERT_GT(errors.t_s.size(), run.log.samples.size() - 10);

  const JointRms all = rms_error(run, errors, [](double) { return true; });
  print("seed-line, whole record:", all.error, all.count);
  const JointRms lines = rms_error(run, errors, [&](double t) { return on_line(run, t); });
  print("seed-line, on the two lines:", lines.error, lines.count);
  print("  the smoother's own sigma there:", lines.sigma, lines.count);
  // The size of what is measured, for scale: the true joint errors' RMS on the lines.
  JointVector true_sq = JointVector::Zero();
  int true_count = 0;
  for (std::size_t k = 0; k < errors.t_s.size(); ++k) {
    if (!on_line(run, errors.t_s[k])) continue;
    const auto index = static_cast<std::size_t>(std::llround(errors.t_s[k] / 0.001));
    true_sq += (errors.q_desired_rad[k] - run.sim.plant.samples.at(index).q_link_rad).cwiseAbs2();
    ++true_count;
  }
  print("true joint errors on the lines (scale):", (true_sq / std::max(true_count, 1)).cwiseSqrt(),
        true_count);
  // The initial rest (robot clock < 6 s), where the IMS sees a true standstill and the
  // zero-velocity updates hold the trajectory: the 0.01 mrad RMS per joint holds.
  const JointRms initial_rest = rms_error(run, errors, [](double t) { return t < 5.9; });
  print("seed-line, initial rest (ZUPT-aided):", initial_rest.error, initial_rest.count);
  for (int i = 0; i < kJointCount; ++i)
    EXPECT_LT(initial_rest.error(i), 1e-5) << "joint A" << i + 1;

  // As before this change, for comparison: the IMS's own rests, no readings (and no correction
  // at the revisited poses, which needs the readings).
  JointSpaceOptions ims_only;
  ims_only.encoder_stillness = false;
  ims_only.creep_velocity_updates = false;
  ims_only.revisited_pose_correction = false;
  ims_only.keep_trajectory = true;
  const JointSpaceErrors without = joint_space_errors(true_input(run), ims_only);
  double without_at = 0.0;
  const double without_position = worst_position_error(run, without, &without_at);
  const JointRms without_lines = rms_error(run, without, [&](double t) { return on_line(run, t); });
  std::printf("IMS's own rests only (%zu): max position error %.4f mm (at %.2f s)\n",
              without.smoother.rest_intervals.size(), without_position * 1e3, without_at);
  print("  on the two lines:", without_lines.error, without_lines.count);

  // The goal is 0.01 mrad RMS on the lines: NOT MET here (see the top of the file).
  // Measured (Release): max position error 0.066 mm (IMS's own rests: 8.0 mm); on the lines A1
  // 0.015, A2 0.084, A3 0.132, A4 0.001, A5 0.052, A6 0.013 mrad RMS (IMS's own rests: 0.18,
  // 1.36, 5.71, 0.001, 4.37, 0.18), the smoother's sigma 0.051, 0.162, 0.305, 0.001, 0.164,
  // 0.055 mrad. (Without the correction at the revisited poses, here the line
  // start before and after the lines, calib/revisited_poses.hpp: 0.091 mm; A2 0.115, A3 0.163.)
  // Asserted: the chain without gross failure (IK branch, clock, frames: errors of 0.1 rad and
  // more); then what it reaches with ~1.5x margin, that the readings beat the IMS's own rests by
  // 10x in position, and that the errors stay within 1.5x the smoother's sigma on every joint (it
  // reports what it knows).
  for (int i = 0; i < kJointCount; ++i) EXPECT_LT(all.error(i), 0.05) << "joint A" << i + 1;
  if (sanitized()) return;  // 15 s only: the figures below are those of the whole run
  EXPECT_LT(worst_position, 0.1e-3);
  EXPECT_LT(worst_position * 10.0, without_position);
  const JointVector reached = (JointVector() << 0.025, 0.13, 0.2, 0.003, 0.08, 0.02).finished();
  for (int i = 0; i < kJointCount; ++i) {
    EXPECT_LT(lines.error(i), reached(i) * 1e-3) << "joint A" << i + 1;
    EXPECT_LT(lines.error(i), 1.5 * lines.sigma(i)) << "joint A" << i + 1;
  }
}

TEST(JointSpaceErrors, OnAnArmThatRestsTheChainReachesTheImsNoiseFloor) {
  // The same program and IMS on an arm without creep or ringing: rests are rests, and each line
  // starts and ends with zero-velocity updates. White accelerometer noise q (2.2 ug/sqrt(Hz)),
  // double integrated over a line of T = 2.2 s pinned at both ends, leaves q sqrt(T^3 / 12) =
  // 21 um at most; but nothing pins the position between the rests, so each of the three moves
  // adds its own (the smoother's position sigma: 16, then 27, then 36 um per axis), and the
  // lines lie at 91-95 % of the arm's reach, where the elbow is nearly stretched: there a
  // micrometre of flange position is 3-4 urad of A2/A3 (the inverse Jacobian).
  const SimRun& run = ideal_seed_line();
  const JointSpaceErrors errors = joint_space_errors(true_input(run), keeping_the_trajectory());
  print_smoother(errors);
  double worst_at = 0.0;
  const double worst_position = worst_position_error(run, errors, &worst_at);
  std::printf("ideal arm: max position error %.4f mm (at %.2f s)\n", worst_position * 1e3,
              worst_at);
  const JointRms lines = rms_error(run, errors, [&](double t) { return on_line(run, t); });
  print("ideal arm, on the two lines:", lines.error, lines.count);
  print("  the smoother's own sigma there:", lines.sigma, lines.count);
  EXPECT_EQ(errors.ik_failures, 0u);
  if (sanitized()) return;  // 15 s only: the figures below are those of the whole run
  // Measured (Release): max position error 0.046 mm; on the lines A1 0.014, A2 0.042, A3 0.091,
  // A4 0.004, A5 0.051, A6 0.013 mrad RMS against the smoother's sigma 0.018, 0.055, 0.103,
  // 0.001, 0.056, 0.027 (before the correction at the revisited line start: 0.072 mm, A1 0.029,
  // A2 0.057, A3 0.124, A5 0.069; five other noise seeds of the unit then: A3 0.061..0.212). So
  // even on an arm that rests, 0.01 mrad on the lines is below what this IMS resolves on this path
  // (its floor is ~0.1 mrad on A3, ~0.05 on A2 and A5); the wrist's A1/A4/A6 come within 0.03.
  // Asserted: the four rests are found (initial, before the line, pause, final), what is
  // reached with ~1.5x margin, and the errors within 2x the smoother's sigma (+ 3 urad: A4's
  // sigma is 1.4 urad) on every joint.
  EXPECT_EQ(errors.smoother.rest_intervals.size(), 4u);
  const JointVector reached = (JointVector() << 0.021, 0.063, 0.14, 0.0065, 0.076, 0.02).finished();
  for (int i = 0; i < kJointCount; ++i) {
    EXPECT_LT(lines.error(i), reached(i) * 1e-3) << "joint A" << i + 1;
    EXPECT_LT(lines.error(i), 2.0 * lines.sigma(i) + 3e-6) << "joint A" << i + 1;
  }
  EXPECT_LT(worst_position, 0.07e-3);
}

TEST(JointSpaceErrors, TheJointSpaceStepIsExactAlongTheTrueTrajectory) {
  // The simulator's own sensor trajectory through the same frames, interpolation and inverse
  // kinematics: what remains is the interpolation between IMS samples (1 ms: a h^2 / 8 ~ 1 um
  // at the arm's accelerations) and the IK's convergence (1e-12).
  const SimRun& run = seed_line();
  std::vector<ims::SmoothedState> truth(run.sim.sensor_truth.size());
  for (std::size_t k = 0; k < truth.size(); ++k) truth[k].state = run.sim.sensor_truth[k];
  const JointSpaceInput input = true_input(run);
  const JointSpaceErrors errors =
      joint_errors_along(truth, run.log, input.kinematics, input.frames);
  EXPECT_EQ(errors.ik_failures, 0u);
  const JointRms all = rms_error(run, errors, [](double) { return true; });
  print("seed-line, true sensor trajectory:", all.error, all.count);
  // 1 um of interpolation error over a ~1 m lever: 1e-6 rad; the goal is 1e-5 rad.
  for (int i = 0; i < kJointCount; ++i) EXPECT_LT(all.error(i), 1e-6) << "joint A" << i + 1;
}

// A wrist move through A5 = 0 (axes 4 and 6 align), measured with a constant flange orientation
// error of 2e-5 rad (a good IMS path): where |sin A5| is small the pose fixes only A4 + A6 and the
// error splits them by ~2e-5 / |sin A5| in opposite directions (without a limit: radians, the
// "1640 mrad" A4/A6 maxima once seen on the mounting run). Samples with |sin A5| < 0.05 are left
// out and counted; on the rest A4 and A6 stay within 2e-5 / 0.05 = 0.4 mrad (+ rounding).
TEST(JointSpaceErrors, SamplesNearTheWristSingularityAreLeftOutAndCounted) {
  const RobotDescription robot =
      load_robot_description(fs::path(IMSCAL_SOURCE_DIR) / "datasets" / "robots" / "kr16.yaml");
  RobotLog log;
  log.robot_name = "kr16";
  std::vector<ims::SmoothedState> trajectory;
  const Eigen::Matrix3d orientation_error =
      Eigen::AngleAxisd(2e-5, Eigen::Vector3d(0.3, -0.5, 0.8).normalized()).toRotationMatrix();
  for (int k = 0; k <= 1000; ++k) {  // 2 s at 2 ms: A5 from +0.2 to -0.2 rad
    RobotLogSample sample;
    sample.t_s = 0.002 * k;
    sample.q_desired_rad << 0.3, -1.2, 1.7, 0.4, 0.2 - 0.0004 * k, -0.6;
    sample.q_internal_rad = sample.q_desired_rad;
    log.samples.push_back(sample);
    const Eigen::Isometry3d T_R_H =
        forward_kinematics<double>(robot.kinematics, sample.q_desired_rad);
    ims::SmoothedState state;
    state.state.t_s = sample.t_s;
    state.state.q_W_S = Eigen::Quaterniond(orientation_error * T_R_H.linear());
    state.state.p_W = T_R_H.translation();
    trajectory.push_back(state);
  }
  const CalibratedFrames frames;  // W = R, S = H, one clock
  const auto worst_wrist_error = [&](const JointSpaceErrors& errors) {
    double worst = 0.0;
    for (std::size_t k = 0; k < errors.t_s.size(); ++k)
      for (int j : {3, 5})
        worst = std::max(worst, std::abs(errors.q_measured_rad[k](j) - errors.q_desired_rad[k](j)));
    return worst;
  };
  const JointSpaceErrors kept = joint_errors_along(trajectory, log, robot.kinematics, frames);
  // |0.2 - 0.0004 k| < asin(0.05): k = 375..625, 251 samples (one more or less at the edges).
  EXPECT_NEAR(double(kept.near_wrist_singularity), 251.0, 2.0);
  EXPECT_EQ(kept.ik_failures, 0u);
  EXPECT_EQ(kept.t_s.size() + kept.near_wrist_singularity, log.samples.size());
  EXPECT_LT(worst_wrist_error(kept), 2e-5 / 0.05 * 1.1);
  const JointSpaceErrors all = joint_errors_along(trajectory, log, robot.kinematics, frames, 0.0);
  EXPECT_GT(worst_wrist_error(all), 0.01) << "the split of A4 and A6 is lost near A5 = 0";
}

TEST(JointSpaceErrors, InterpolatesPosesBetweenSamples) {
  // Two states 1 ms apart: position linear, attitude along the shortest arc (closed form: a
  // rotation by angle a about a fixed axis is interpolated to f a).
  std::vector<ims::SmoothedState> states(2);
  states[0].state.t_s = 1.0;
  states[0].state.p_W = {1.0, 2.0, 3.0};
  states[1].state.t_s = 1.001;
  states[1].state.p_W = {1.004, 2.0, 2.998};
  const Eigen::Vector3d axis = Eigen::Vector3d(1.0, -2.0, 0.5).normalized();
  states[1].state.q_W_S = Eigen::Quaterniond(Eigen::AngleAxisd(0.01, axis));
  Eigen::Isometry3d pose;
  ASSERT_TRUE(interpolate_sensor_pose(states, 1.00025, pose));
  EXPECT_NEAR((pose.translation() - Eigen::Vector3d(1.001, 2.0, 2.9995)).norm(), 0.0, 1e-12);
  const Eigen::AngleAxisd turned(pose.linear());
  EXPECT_NEAR(turned.angle(), 0.0025, 1e-12);
  EXPECT_NEAR((turned.axis() - axis).norm(), 0.0, 1e-9);
  EXPECT_FALSE(interpolate_sensor_pose(states, 0.9999, pose));
  EXPECT_FALSE(interpolate_sensor_pose(states, 1.0011, pose));
}

TEST(JointSpaceErrors, BlocksGiveTheRowsOfTheWholeTrajectory) {
  // The smoothed trajectory is used block by block; the truth is the whole trajectory: the
  // rows along it (joint_errors_along) and a run whose one block holds it all. Equal bit for
  // bit: each row interpolates between the same two states, and each state is corrected once.
  const SimRun& run = seed_line();
  JointSpaceOptions whole = keeping_the_trajectory();
  whole.states_per_block = run.imu.samples.size() + 1;
  JointSpaceOptions blocks = keeping_the_trajectory();
  blocks.states_per_block = 997;  // blocks end anywhere: in rests, moves, the revisited poses
  const JointSpaceErrors a = joint_space_errors(true_input(run), whole);
  const JointSpaceErrors b = joint_space_errors(true_input(run), blocks);
  ASSERT_GE(a.revisited_pose_errors.size(), 2u);  // two or more (the sanitized line is shorter)
  ASSERT_EQ(a.revisited_pose_errors.size(), b.revisited_pose_errors.size());
  for (std::size_t k = 0; k < a.revisited_pose_errors.size(); ++k)
    EXPECT_EQ(a.revisited_pose_errors[k].error_W, b.revisited_pose_errors[k].error_W) << k;
  ASSERT_EQ(a.trajectory.size(), run.imu.samples.size() + 1);  // the initial state in front
  ASSERT_EQ(b.trajectory.size(), a.trajectory.size());
  for (std::size_t k = 0; k < a.trajectory.size(); ++k) {
    ASSERT_EQ(a.trajectory[k].state.p_W, b.trajectory[k].state.p_W) << k;
    ASSERT_EQ(a.trajectory[k].state.q_W_S.coeffs(), b.trajectory[k].state.q_W_S.coeffs()) << k;
  }
  const JointSpaceErrors along =
      joint_errors_along(a.trajectory, run.log, true_input(run).kinematics, true_input(run).frames);
  for (const JointSpaceErrors* e : {&a, &b}) {
    ASSERT_EQ(e->t_s, along.t_s);
    EXPECT_EQ(e->outside_record, along.outside_record);
    for (std::size_t k = 0; k < along.t_s.size(); ++k) {
      ASSERT_EQ(e->q_measured_rad[k], along.q_measured_rad[k]) << k;
      ASSERT_EQ(e->q_measured_sigma_rad[k], along.q_measured_sigma_rad[k]) << k;
    }
  }
}

TEST(JointSpaceErrors, RowsHandedToASinkAreTheKeptRows) {
  // The truth is the same run keeping its rows: the sink gets them in order, bit for bit, the
  // columns stay empty, and the sums (summary.txt's RMS and maximum, the noise floor) are those
  // over the kept columns, added in the same order.
  const SimRun& run = seed_line();
  const JointSpaceErrors kept = joint_space_errors(true_input(run));
  std::vector<JointErrorRow> handed;
  JointSpaceOptions sunk;
  sunk.row_sink = [&](const JointErrorRow& row) { handed.push_back(row); };
  const JointSpaceErrors streamed = joint_space_errors(true_input(run), sunk);
  EXPECT_TRUE(streamed.t_s.empty());
  EXPECT_TRUE(streamed.q_measured_sigma_rad.empty());
  ASSERT_GT(kept.t_s.size(), 100u);
  ASSERT_EQ(handed.size(), kept.t_s.size());
  for (std::size_t k = 0; k < handed.size(); ++k) {
    ASSERT_EQ(handed[k].t_s, kept.t_s[k]) << k;
    ASSERT_EQ(handed[k].payload_kg, kept.payload_kg[k]) << k;
    ASSERT_EQ(handed[k].q_desired_rad, kept.q_desired_rad[k]) << k;
    ASSERT_EQ(handed[k].q_measured_rad, kept.q_measured_rad[k]) << k;
    ASSERT_EQ(handed[k].q_internal_rad, kept.q_internal_rad[k]) << k;
    ASSERT_EQ(handed[k].q_measured_sigma_rad, kept.q_measured_sigma_rad[k]) << k;
  }
  EXPECT_EQ(streamed.sums.rows, kept.t_s.size());
  EXPECT_EQ(q_measured_sigma_rms_rad(streamed), q_measured_sigma_rms_rad(kept));
  for (int j = 0; j < kJointCount; ++j) {
    double sum = 0.0, worst = 0.0;
    for (std::size_t k = 0; k < kept.t_s.size(); ++k) {
      const double e = kept.q_desired_rad[k][j] - kept.q_measured_rad[k][j];
      sum += e * e;
      worst = std::max(worst, std::abs(e));
    }
    EXPECT_EQ(streamed.sums.error_squared_rad2[j], sum) << j;
    EXPECT_EQ(streamed.sums.error_max_abs_rad[j], worst) << j;
  }
}

TEST(JointSpaceErrors, RefusesAFirstRestOutsideTheRecord) {
  const SimRun& run = seed_line();
  JointSpaceInput input = true_input(run);
  input.first_rest.begin_ims_s = run.imu.samples.back().t_s + 1.0;
  EXPECT_THROW(joint_space_errors(input), InputError);
  input = true_input(run);
  input.imu = nullptr;
  EXPECT_THROW(joint_space_errors(input), InputError);
}

}  // namespace
}  // namespace imscal::calib
