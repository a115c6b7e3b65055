// ident::identify_joints, the per-joint identification of `imscal identify` on worker threads:
// the result is the same, bit for bit, as one thread's (each joint's least squares depends only
// on its own data), in joint order; a joint that did not move gets the neutral model with the
// reason instead of failing the others; progress is reported once per joint.
#include <gtest/gtest.h>

#include <array>
#include <set>

#include "core/config_node.hpp"
#include "ident/identify_joints.hpp"
#include "tests/ident/joint_simulation.hpp"

namespace imscal::ident {
namespace {

constexpr double kDt = 0.002;
constexpr std::size_t kSamples = 20000;  // 40 s: enough rows for the default cells

JointErrorLog three_moving_joints_and_one_still() {
  JointErrorLog log;
  log.robot = "kr16";
  log.cycle_s = kDt;
  for (std::size_t j = 0; j < 4; ++j) {
    test_support::SimulatedJoint joint;
    joint.backlash_l_rad = 0.4e-3 * double(j);
    joint.dead_time = int(j % 3);
    joint.measurement_noise_rad = 1e-6;
    auto record = test_support::simulate_joint(joint, kSamples, kDt, unsigned(j) + 7);
    if (j == 3) {  // the still joint: commanded and measured at one angle throughout
      record.q_desired.assign(kSamples, 0.25);
      record.q_measured = record.q_desired;
    }
    if (j == 0) log.time_s = record.t_s;
    log.joint_names.emplace_back(std::array{"A1", "A2", "A3", "A4"}[j]);
    log.q_desired_rad.push_back(record.q_desired);
    log.q_measured_rad.push_back(record.q_measured);
  }
  log.payload_kg.assign(kSamples, 5.0);
  return log;
}

IdentificationConfig config_for_four_joints() {
  auto config = load_identification_config(ConfigNode::load_file(
      std::string(IMSCAL_SOURCE_DIR) + "/datasets/identification/ident-paper.yaml"));
  config.max_speed_rad_s.resize(4);
  config.options.grid.na_max = config.options.grid.nb_max = 8;  // a small sweep: a fast test
  return config;
}

TEST(IdentifyJoints, ThreadsGiveTheSequentialResultInJointOrder) {
  const JointErrorLog log = three_moving_joints_and_one_still();
  const IdentificationConfig config = config_for_four_joints();
  std::vector<std::size_t> done_counts;
  std::set<std::size_t> done_joints;
  const auto parallel = identify_joints(log, config, 4, [&](std::size_t joint, std::size_t done) {
    done_joints.insert(joint);
    done_counts.push_back(done);
  });
  const auto sequential = identify_joints(log, config, 1);
  ASSERT_EQ(parallel.size(), 4u);
  ASSERT_EQ(sequential.size(), 4u);
  // Progress: every joint once, the count rising 1..4.
  EXPECT_EQ(done_joints, (std::set<std::size_t>{0, 1, 2, 3}));
  EXPECT_EQ(done_counts, (std::vector<std::size_t>{1, 2, 3, 4}));
  for (std::size_t j = 0; j < 4; ++j) {
    SCOPED_TRACE(log.joint_names[j]);
    const JointParameters& p = parallel[j].result.parameters;
    const JointParameters& s = sequential[j].result.parameters;
    EXPECT_EQ(p.name, log.joint_names[j]);
    EXPECT_EQ(parallel[j].failure, sequential[j].failure);
    // Bit for bit: no tolerance, the arithmetic of a joint does not depend on the thread.
    EXPECT_EQ(p.backlash_l_rad, s.backlash_l_rad);
    ASSERT_EQ(p.cells.size(), s.cells.size());
    for (std::size_t c = 0; c < p.cells.size(); ++c) {
      EXPECT_EQ(p.cells[c].status, s.cells[c].status);
      EXPECT_EQ(p.cells[c].a, s.cells[c].a);
      EXPECT_EQ(p.cells[c].b, s.cells[c].b);
    }
  }
  // The three moving joints are identified; the still one has the neutral model and the reason.
  for (std::size_t j = 0; j < 3; ++j) EXPECT_TRUE(parallel[j].failure.empty()) << j;
  EXPECT_FALSE(parallel[3].failure.empty());
  ASSERT_EQ(parallel[3].result.cells.size(), 1u);
  EXPECT_EQ(parallel[3].result.cells[0].status, CellStatus::kNeutral);
}

// A joint fitted without some of the table's inputs (no second order, no gear mode) gets each
// missing input with one zero coefficient in its place, its own coefficients unchanged.
TEST(IdentifyJoints, AbsentInputsArePaddedInTheirPlaceWithZeros) {
  using enum TableInput;
  JointParameters joint;
  joint.transmission_error_2_rad_per_rad = 400.0;
  CellParameters cell;
  cell.structure = {1, 1, 0, 5, {2, 3, 1, 2, 1}};
  cell.c = {1, 2, 3, 4, 5, 6, 7, 8, 9};
  joint.cells = {cell};
  const std::vector<TableInput> own{kModelTorque, kTransmissionErrorSin, kTransmissionErrorCos,
                                    kTransmissionErrorModeSin, kTransmissionErrorModeCos};
  const std::vector<TableInput> table{kModelTorque,
                                      kTransmissionErrorSin,
                                      kTransmissionErrorCos,
                                      kTransmissionError2Sin,
                                      kTransmissionError2Cos,
                                      kTransmissionErrorModeSin,
                                      kTransmissionErrorModeCos,
                                      kTransmissionError2ModeSin,
                                      kTransmissionError2ModeCos};
  pad_absent_inputs(joint, own, table);
  const CellParameters& padded = joint.cells[0];
  EXPECT_EQ(padded.structure.extra_inputs, 9);
  EXPECT_EQ(padded.structure.nx,
            (std::array<int, kMaxExtraInputs>{2, 3, 1, 1, 1, 2, 1, 1, 1, 0, 0}));
  EXPECT_EQ(padded.c, (std::vector<double>{1, 2, 3, 4, 5, 6, 0, 0, 7, 8, 9, 0, 0}));
  EXPECT_NO_THROW(padded.structure.validate());
  EXPECT_EQ(joint.transmission_error_2_rad_per_rad, 0.0);
  // Inputs out of the table's order are a programming error.
  const std::vector<TableInput> swapped{kTransmissionErrorCos, kTransmissionErrorSin};
  EXPECT_THROW(pad_absent_inputs(joint, swapped, table), std::logic_error);
}

}  // namespace
}  // namespace imscal::ident
