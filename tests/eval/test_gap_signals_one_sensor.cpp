// The gap signals of joint errors without the q_internal block (a robot with one position sensor
// per joint) against those of the same record with it: every signal that does not read the
// encoders equal, bit for bit; the drive's actual motion unknown (empty) instead of a crash; the
// transmission error, which needs the motor angle, not tried; and a gap the encoders do not enter
// (a 6 ms time offset of A5's measurement) diagnosed alike.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <vector>

#include "calib/robot_description.hpp"
#include "eval/gap_candidates.hpp"
#include "eval/gap_diagnosis.hpp"
#include "eval/gap_signals.hpp"
#include "ident/joint_error_io.hpp"

namespace imscal::eval {
namespace {

constexpr double kCycle_s = 0.002;
constexpr std::size_t kSamples = 5000;  // 10 s
constexpr double kTimeOffset_s = 0.006;

// Six joints swinging within the KR 16's limits; A5's measurement 6 ms late, the others exact;
// the encoders read the desired angle 1 mrad low.
ident::JointErrorLog record() {
  ident::JointErrorLog log;
  log.robot = "kr16";
  log.cycle_s = kCycle_s;
  log.joint_names = {"A1", "A2", "A3", "A4", "A5", "A6"};
  log.q_desired_rad.assign(6, {});
  log.q_measured_rad.assign(6, {});
  log.q_internal_rad.assign(6, {});
  for (std::size_t k = 0; k < kSamples; ++k) {
    const double t = double(k) * kCycle_s;
    log.time_s.push_back(t);
    log.payload_kg.push_back(5.0);
    for (std::size_t j = 0; j < 6; ++j) {
      const double w = 2.0 * std::numbers::pi * (0.3 + 0.07 * double(j));
      const auto q = [&](double at_s) { return 0.1 * double(j) + 0.3 * std::sin(w * at_s); };
      log.q_desired_rad[j].push_back(q(t));
      log.q_measured_rad[j].push_back(j == 4 ? q(t - kTimeOffset_s) : q(t));
      log.q_internal_rad[j].push_back(q(t) - 1e-3);
    }
  }
  return log;
}

TEST(GapSignalsOneSensor, SignalsWithoutTheEncodersEqualAndTheDiagnosisAgrees) {
  const calib::RobotDescription robot = calib::load_robot_description(
      std::filesystem::path(IMSCAL_SOURCE_DIR) / "datasets" / "robots" / "kr16.yaml");
  const ident::JointErrorLog with_block = record();
  ident::JointErrorLog one_sensor = with_block;
  one_sensor.q_internal_rad.clear();
  const std::vector<std::vector<double>> no_sim_error(6, std::vector<double>(kSamples, 0.0));
  const GapSignals a = make_gap_signals(with_block, no_sim_error, robot, nullptr);
  const GapSignals b = make_gap_signals(one_sensor, no_sim_error, robot, nullptr);
  EXPECT_EQ(b.gap_rad, a.gap_rad);
  EXPECT_EQ(b.qd_desired_rad_s, a.qd_desired_rad_s);
  EXPECT_EQ(b.torque_nm, a.torque_nm);
  EXPECT_EQ(b.gravity_torque_nm, a.gravity_torque_nm);
  EXPECT_EQ(b.unit_payload_nm_kg, a.unit_payload_nm_kg);
  EXPECT_EQ(b.mass_matrix_kg_m2, a.mass_matrix_kg_m2);
  ASSERT_EQ(a.torque_internal_nm.size(), 6u);
  EXPECT_TRUE(b.q_internal_rad.empty());
  EXPECT_TRUE(b.qd_internal_rad_s.empty());
  EXPECT_TRUE(b.torque_internal_nm.empty());
  EXPECT_TRUE(b.unit_payload_internal_nm_kg.empty());

  const std::vector<bool> training(kSamples, true);
  EXPECT_TRUE(fit_candidate(EffectKind::kTransmissionError, a, 4, training).has_value());
  EXPECT_FALSE(fit_candidate(EffectKind::kTransmissionError, b, 4, training).has_value());
  // The time offset reads only q_desired: the same fit, bit for bit, with or without the block.
  const auto offset_a = fit_candidate(EffectKind::kTimeOffset, a, 4, training);
  const auto offset_b = fit_candidate(EffectKind::kTimeOffset, b, 4, training);
  ASSERT_TRUE(offset_a && offset_b);
  EXPECT_EQ(offset_b->parameters, offset_a->parameters);
  // Truth: a 6 ms delay of a sine of at most 0.3 x 2 pi x 0.58 rad/s; to first order the gap is
  // dt x qd, the second-order term (dt w)^2 / 2 ~ 1.3e-4 relative: 1 % of dt is far above it.
  EXPECT_NEAR(offset_b->parameters[0], kTimeOffset_s, 0.01 * kTimeOffset_s);

  const Diagnosis da = diagnose_gap(a), db = diagnose_gap(b);
  ASSERT_FALSE(da.candidates.empty());
  ASSERT_FALSE(db.candidates.empty());
  EXPECT_EQ(db.candidates.front().fit.kind, EffectKind::kTimeOffset);
  EXPECT_EQ(db.candidates.front().fit.kind, da.candidates.front().fit.kind);
  EXPECT_EQ(db.candidates.front().fit.joint, 4u);
  EXPECT_EQ(db.candidates.front().fit.parameters, da.candidates.front().fit.parameters);
}

}  // namespace
}  // namespace imscal::eval
