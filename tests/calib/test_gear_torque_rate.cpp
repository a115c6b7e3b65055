// The creep velocities' torque-rate term (calib/gear_torque_rate.hpp through
// calib/encoder_motion.hpp), checked two ways:
//  - closed form: a hand-made log whose A2 and A5 readings creep exponentially to their targets;
//    the controller law gives the torque rate analytically, and the sensor's speed per unit
//    joint rate comes from central differences of the forward kinematics (not the Jacobian);
//  - the simulator's truth: the seed-line record (KR 16 with elastic gears, friction, play;
//    the chain believes the nominal file, here the plant's own description), whose link-minus-
//    motor rate (plant.samples, the truth/joints.csv of `simulate`, read by this test only) the
//    term must bound after two stops, and which must be near zero where the arm has settled,
//    late in a final rest lengthened to 10 s.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include "calib/encoder_motion.hpp"
#include "calib/gear_torque_rate.hpp"
#include "robot/forward_kinematics.hpp"
#include "robot/robot_description.hpp"
#include "sim/scenario.hpp"
#include "sim/simulation.hpp"
#include "sim/simulation_output.hpp"

namespace imscal::calib {
namespace {

namespace fs = std::filesystem;

constexpr double kCycle = 0.002;
constexpr double kCreepTau = 0.3;  // s

JointVector target() {
  return (JointVector() << 0.2, -1.4, 1.5, 0.3, 0.7, -0.4).finished();
}

JointVector creep_amplitude() {
  return (JointVector() << 0.0, -1.5e-3, 0.0, 0.0, 0.75e-3, 0.0).finished();
}

// 4 s of commanded standstill; from t = 0 the readings approach the target as a e^(-t / tau).
RobotLog creeping_log() {
  RobotLog log;
  log.robot_name = "kr16";
  log.cycle_s = kCycle;
  for (int k = 0; k <= 2000; ++k) {
    RobotLogSample s;
    s.t_s = k * kCycle;
    s.q_desired_rad = target();
    s.q_internal_rad = target() - creep_amplitude() * std::exp(-s.t_s / kCreepTau);
    log.samples.push_back(s);
  }
  return log;
}

// The sensor's speed per unit rate of joint i [m/s per rad/s]: central differences of 1e-6 rad
// of the forward kinematics (error ~ h^2 / 6 of the arm's curvature, < 1e-11 relative).
double sensor_speed_per_joint_rate(const RobotDescription& robot, const JointVector& q, int i,
                                   const Eigen::Vector3d& p_H_S) {
  const double h = 1e-6;
  JointVector plus = q, minus = q;
  plus[i] += h;
  minus[i] -= h;
  const Eigen::Vector3d a = forward_kinematics<double>(robot.kinematics, plus) * p_H_S;
  const Eigen::Vector3d b = forward_kinematics<double>(robot.kinematics, minus) * p_H_S;
  return (a - b).norm() / (2.0 * h);
}

EncoderMotionOptions torque_term_only() {
  EncoderMotionOptions options;  // the other parts of the sigma off: sigma = the term
  options.velocity_sigma_floor_m_s = 0.0;
  options.velocity_sigma_fraction = 0.0;
  return options;
}

TEST(GearTorqueRate, CreepSigmaAgainstTheControllerLawInClosedForm) {
  const RobotDescription robot =
      load_robot_description(fs::path(IMSCAL_SOURCE_DIR) / "datasets" / "robots" / "kr16.yaml");
  const RobotLog log = creeping_log();
  const Eigen::Vector3d p_H_S(0.001, -0.002, 0.12);
  const EncoderMotion motion = encoder_motion(log, robot.kinematics, Eigen::Isometry3d::Identity(),
                                              p_H_S, 0.0, torque_term_only(), &robot);
  ASSERT_FALSE(motion.creep_velocity.empty());
  std::size_t checked = 0;
  double worst_relative = 0.0;
  for (const ims::VelocitySample& v : motion.creep_velocity) {
    if (v.t_s > 4.0 - 0.05) break;  // the fits' windows narrow at the run's end
    // q_d - q_m = A e^(-t/tau), q_m_dot = A/tau e^(-t/tau), q_m_ddot = -A/tau^2 e^(-t/tau):
    // e_v = (kp - 1/tau) A e^(-t/tau), e_v_dot = -e_v / tau, tau_dot = (ki - kv / tau) e_v.
    double expected_sq = 0.0;
    for (int i = 0; i < kJointCount; ++i) {
      const JointControllerGains& g = robot.joints[std::size_t(i)].controller;
      const double a = creep_amplitude()[i] * std::exp(-v.t_s / kCreepTau);
      const double e_v = (g.kp_position_1_s - 1.0 / kCreepTau) * a;
      const double torque_rate =
          (g.ki_velocity_nm_per_rad - g.kp_velocity_nm_s_per_rad / kCreepTau) * e_v;
      const double deflection_rate =
          torque_rate / robot.joints[std::size_t(i)].drive.stiffness_nm_per_rad;
      const JointVector q = target() - creep_amplitude() * std::exp(-v.t_s / kCreepTau);
      expected_sq += std::pow(deflection_rate * sensor_speed_per_joint_rate(robot, q, i, p_H_S), 2);
    }
    const double expected = std::sqrt(expected_sq);
    // The rates are lines through +-20 ms (slope overstated by h^2 / (10 tau^2) = 4.4e-4), the
    // acceleration their difference over 40 ms (central difference: h^2 / (6 tau^2) = 3e-3 of
    // it, the fit's bias on top): 1e-2 of the term bounds both with margin.
    EXPECT_NEAR(v.sigma_m_s, expected, 1e-2 * expected) << "t = " << v.t_s;
    worst_relative = std::max(worst_relative, std::abs(v.sigma_m_s - expected) / expected);
    ++checked;
  }
  std::printf("closed form: %zu creep velocities, worst relative difference %.2e\n", checked,
              worst_relative);
  EXPECT_GT(checked, 1000u);

  // Off (the option, or no robot file): the sigma is the floor and fraction only.
  EncoderMotionOptions off = torque_term_only();
  off.gear_torque_rate = false;
  for (const ims::VelocitySample& v :
       encoder_motion(log, robot.kinematics, Eigen::Isometry3d::Identity(), p_H_S, 0.0, off, &robot)
           .creep_velocity)
    EXPECT_EQ(v.sigma_m_s, 0.0);
}

// The seed-line program with its final rest 10 s long instead of 3 s, so that the arm settles
// (written beside the test's working folder).
fs::path long_final_rest(const fs::path& program) {
  std::ifstream in(program);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string rest = "rest: {duration_s: 3, label: \"final rest\"}";
  const std::size_t at = text.find(rest);
  EXPECT_NE(at, std::string::npos) << program;
  if (at != std::string::npos)
    text.replace(at, rest.size(), "rest: {duration_s: 10, label: \"final rest\"}");
  const fs::path file = fs::temp_directory_path() /
                        ("gear-torque-rate-seed-line-" + std::to_string(::getpid()) + ".yaml");
  std::ofstream(file) << text;
  return file;
}

// The seed-line record and the figures per window of its standstills, for the next two tests.
struct Window {
  double begin_s = 0.0;                            // robot clock
  double term_max_m_s = 0.0, truth_max_m_s = 0.0;  // at the sensor
};

class SeedLineTruth {
 public:
  SeedLineTruth() {
    sim::Scenario scenario = sim::load_scenario(fs::path(IMSCAL_SOURCE_DIR) / "datasets" /
                                                "scenarios" / "seed-line.yaml");
    scenario.program_file = long_final_rest(scenario.program_file);
    nominal_ = sim::load_nominal_robot(scenario).description;
    sim_ = sim::run_simulation(scenario, scenario.seed, {}, 1e9);
    fs::remove(scenario.program_file);
    log_ = sim::make_robot_log(sim_);
    p_H_S_ = sim_.T_H_S.translation();
    motion_ = encoder_motion(log_, nominal_.kinematics, sim_.T_W_R, p_H_S_, 0.0, torque_term_only(),
                             &nominal_);
  }

  // The truth's link-minus-motor rate at the sensor [m/s] at plant sample j: the sensor's
  // position by forward kinematics of the link angles less that of the readings (motor angle /
  // N), differentiated centrally over the plant's output interval.
  double truth_speed_m_s(std::size_t j) const {
    const auto& s = sim_.plant.samples;
    const auto offset = [&](std::size_t i) {
      return Eigen::Vector3d(
          forward_kinematics<double>(nominal_.kinematics, s[i].q_link_rad) * p_H_S_ -
          forward_kinematics<double>(nominal_.kinematics, s[i].q_motor_rad) * p_H_S_);
    };
    return ((offset(j + 1) - offset(j - 1)) / (s[j + 1].t_s - s[j - 1].t_s)).norm();
  }

  // The largest term and truth in windows of width_s over [begin_s, end_s).
  std::vector<Window> windows(double begin_s, double end_s, double width_s) const {
    std::vector<Window> out;
    for (double b = begin_s; b + width_s <= end_s + 1e-9; b += width_s) out.push_back({b});
    const auto slot = [&](double t) -> Window* {
      if (t < begin_s || t >= begin_s + width_s * double(out.size())) return nullptr;
      return &out[std::size_t((t - begin_s) / width_s)];
    };
    for (const ims::VelocitySample& v : motion_.creep_velocity)
      if (Window* w = slot(v.t_s)) w->term_max_m_s = std::max(w->term_max_m_s, v.sigma_m_s);
    const auto& s = sim_.plant.samples;
    for (std::size_t j = 1; j + 1 < s.size(); ++j)
      if (Window* w = slot(s[j].t_s))
        w->truth_max_m_s = std::max(w->truth_max_m_s, truth_speed_m_s(j));
    return out;
  }

  // Start of the commanded standstill that contains t_s (robot clock).
  double standstill_begin_s(double t_s) const {
    const auto& s = log_.samples;
    std::size_t k = 0;
    while (k + 1 < s.size() && s[k + 1].t_s <= t_s) ++k;
    while (k > 0 && s[k - 1].q_desired_rad == s[k].q_desired_rad) --k;
    return s[k].t_s;
  }

 private:
  RobotDescription nominal_;
  sim::SimulationResult sim_;
  RobotLog log_;
  Eigen::Vector3d p_H_S_;
  EncoderMotion motion_;
};

const SeedLineTruth& seed_line() {
  static const SeedLineTruth truth;
  return truth;
}

// After a stop, in windows of 0.5 s from settle_s (1 s) on while the truth is above 1e-7 m/s (1 %
// of the creep updates' floor; below, the truth's differences are rounding): the term must
// bound the truth, and by no more than 20 times. It leaves out the motor's inertia and the
// Coulomb friction's change, which takes up part of the controller's torque change
// at creep speeds (docs/decisions/0081: ~5x); measured 5.4..13 here, 20 leaves ~50 % margin
// above the worst and still says the term follows the truth's decay, not a constant.
void expect_bounded(const SeedLineTruth& truth, const char* what, double stop_s, double end_s) {
  std::printf("%s: stop at %.3f s\n", what, stop_s);
  int windows = 0;
  for (const Window& w : truth.windows(stop_s + 1.0, end_s, 0.5)) {
    std::printf("  +%.2f s: term %.2e m/s, truth %.2e m/s, ratio %.2f\n", w.begin_s - stop_s,
                w.term_max_m_s, w.truth_max_m_s, w.term_max_m_s / w.truth_max_m_s);
    if (w.truth_max_m_s < 1e-7) continue;
    EXPECT_GE(w.term_max_m_s, w.truth_max_m_s) << what << " +" << w.begin_s - stop_s << " s";
    EXPECT_LE(w.term_max_m_s, 20.0 * w.truth_max_m_s) << what << " +" << w.begin_s - stop_s << " s";
    ++windows;
  }
  EXPECT_GE(windows, 3) << what;
}

TEST(GearTorqueRate, BoundsTheSimulatedLinkRateAfterAStop) {
  const SeedLineTruth& truth = seed_line();
  const double line_stop_s = truth.standstill_begin_s(8.0);  // the rest of 3 s before the line
  expect_bounded(truth, "rest before the line", line_stop_s, line_stop_s + 3.0);
  const double final_stop_s = truth.standstill_begin_s(1e9);
  expect_bounded(truth, "final rest", final_stop_s, final_stop_s + 10.0);
}

// Settled: 5 s after the last stop the truth's link rate has fallen below 1e-7 m/s; the term
// must be below 1e-6 m/s there, a tenth of the creep updates' floor of 1e-5 m/s (it adds < 0.5 %
// to their sigma in quadrature), i.e. it leaves a settled arm's updates as they were.
TEST(GearTorqueRate, NearZeroWhereTheArmHasSettled) {
  const SeedLineTruth& truth = seed_line();
  const double stop_s = truth.standstill_begin_s(1e9);
  for (const Window& w : truth.windows(stop_s + 5.0, stop_s + 10.0, 0.5)) {
    std::printf("  final rest +%.2f s: term %.2e m/s, truth %.2e m/s\n", w.begin_s - stop_s,
                w.term_max_m_s, w.truth_max_m_s);
    EXPECT_LT(w.truth_max_m_s, 1e-7);
    EXPECT_LT(w.term_max_m_s, 1e-6);
  }
}

}  // namespace
}  // namespace imscal::calib
