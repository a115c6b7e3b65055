// `imscal model-joint-errors` end to end: the model side of a comparison, written on the samples
// of a measured joint_errors.csv, then `imscal diagnose --sim-joint-errors` on it. The "measured"
// record is the simulator's truth of a short scenario (one PTP move between two rests, every
// drive effect on; eval::simulate_truth_joint_errors) with ~1 arcsec of noise. Truth: when the
// plant is the nominal robot, the nominal model run along the measured desired path reproduces
// the plant's joint errors (up to the derivatives of q_d, which the log lacks: differences
// instead of the planner's); when the plant's A1 Coulomb friction is half the data sheet's, the
// gap lies on A1 and the diagnosis raises it.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>

#include "eval/gap_signals.hpp"
#include "eval/verification.hpp"
#include "ident/joint_error_io.hpp"
#include "sim/scenario.hpp"
#include "tests/support/run_imscal.hpp"
#include "tests/support/scratch_dir.hpp"
#include "tests/support/text_file.hpp"

namespace imscal {
namespace {

namespace fs = std::filesystem;
using ModelJointErrorsCli = test_support::ScratchDirTest;

constexpr auto* run = &imscal::test_support::run_imscal;
using imscal::test_support::read_text;

// A scenario of tests/data/scenarios/short-program.yaml whose plant is kr16.yaml times
// `deviations` (empty: the nominal robot itself).
fs::path write_scenario(const fs::path& dir, const std::string& name,
                        const std::string& deviations) {
  const std::string datasets = IMSCAL_SOURCE_DIR "/datasets";
  const fs::path file = dir / (name + ".yaml");
  std::ofstream(file)
      << "imscal-scenario: 1\nname: " << name << "\nrobot: " << datasets
      << "/robots/kr16.yaml\nnominal_robot: " << datasets << "/robots/kr16.yaml\n"
      << deviations << "program: " << IMSCAL_TEST_DATA_DIR
      << "/scenarios/short-program.yaml\nsensor: " << datasets << "/sensors/navigation-grade.yaml\n"
      << "imu: {rate_hz: 1000}\nbase_in_world: {xyz_m: [0, 0, 0], rpy_deg: [0, 0, 0]}\n"
      << "site: {latitude_deg: 48.78232, longitude_deg: 9.18162, height_m: 245.4}\n"
      // The play of the joints that carry no load here closed, as in the shipped scenarios
      // (datasets/scenarios/deviating-seed-line.yaml): an unloaded link slides inside it, where
      // the smallest change of the input sets it elsewhere.
      << "effects:\n  all: {transmission_error: true}\n  A1: {backlash: false}\n"
      << "  A4: {backlash: false}\n  A6: {backlash: false}\nseed: 3\n";
  return file;
}

// The truth of the scenario's run as a measured record, with white noise of 5e-6 rad (~1 arcsec).
ident::JointErrorLog measured_record(const fs::path& scenario) {
  ident::JointErrorLog log = eval::simulate_truth_joint_errors(sim::load_scenario(scenario));
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0.0, 5e-6);
  for (auto& q : log.q_measured_rad)
    for (double& v : q) v += noise(rng);
  return log;
}

double rms(const std::vector<double>& x) {
  double e = 0.0;
  for (double v : x) e += v * v;
  return std::sqrt(e / double(x.size()));
}

TEST_F(ModelJointErrorsCli, TheNominalModelReproducesANominalPlantOnTheSameSamples) {
  const fs::path scenario = write_scenario(dir_, "nominal-plant", "");
  const ident::JointErrorLog truth =
      eval::simulate_truth_joint_errors(sim::load_scenario(scenario));
  ident::write_joint_errors_csv(dir_ / "measured.csv", measured_record(scenario));
  const std::string args = "model-joint-errors --joint-errors " + (dir_ / "measured.csv").string() +
                           " --scenario " + scenario.string() + " --out " +
                           (dir_ / "model.csv").string();
  ASSERT_EQ(run(args, dir_ / "a.log"), 0) << read_text(dir_ / "a.log");
  const ident::JointErrorLog model = ident::read_joint_errors_csv(dir_ / "model.csv");
  ASSERT_EQ(model.sample_count(), truth.sample_count());
  EXPECT_EQ(model.time_s, truth.time_s);
  EXPECT_EQ(model.q_desired_rad, truth.q_desired_rad);
  const auto e_truth = eval::measured_joint_errors(truth);
  const auto e_model = eval::measured_joint_errors(model);
  for (std::size_t j = 0; j < 6; ++j) {
    std::vector<double> diff(truth.sample_count());
    for (std::size_t k = 0; k < diff.size(); ++k) diff[k] = e_model[j][k] - e_truth[j][k];
    std::printf("joint %zu: joint error RMS %.3g rad, model - truth RMS %.3g rad\n", j,
                rms(e_truth[j]), rms(diff));
    // The same plant: what differs is only the feed-forward's derivatives of q_d (measured
    // 2e-7..6e-7 rad against joint errors of 4e-4..4e-3 rad): below the 5e-6 rad of noise.
    EXPECT_LT(rms(diff), 2e-6) << "joint " << j;
  }
  // The diagnosis of the noisy record against it: the noise alone, nothing raised.
  const std::string robot = std::string(IMSCAL_SOURCE_DIR) + "/datasets/robots/kr16.yaml";
  ASSERT_EQ(run("diagnose --joint-errors " + (dir_ / "measured.csv").string() +
                    " --sim-joint-errors " + (dir_ / "model.csv").string() + " --robot " + robot +
                    " --out " + (dir_ / "out").string(),
                dir_ / "d.log"),
            0)
      << read_text(dir_ / "d.log");
  const auto report = nlohmann::json::parse(read_text(dir_ / "out" / "report.json"));
  EXPECT_FALSE(report["significant_gap"].get<bool>()) << report["verdict"];
  // With --robot instead of the scenario: the simulator's defaults (every effect but the
  // transmission error, the play of every joint, upright gravity, the logged mass as a point
  // mass), on the same samples. Not the scenario's plant, so only the samples are compared.
  ASSERT_EQ(run("model-joint-errors --joint-errors " + (dir_ / "measured.csv").string() +
                    " --robot " + IMSCAL_SOURCE_DIR + "/datasets/robots/kr16.yaml --out " +
                    (dir_ / "model-robot.csv").string(),
                dir_ / "r.log"),
            0)
      << read_text(dir_ / "r.log");
  const ident::JointErrorLog by_robot = ident::read_joint_errors_csv(dir_ / "model-robot.csv");
  EXPECT_EQ(by_robot.time_s, truth.time_s);
  EXPECT_EQ(by_robot.q_desired_rad, truth.q_desired_rad);
  // An existing output is refused without --force (exit 2, unchanged), replaced with it.
  const std::string before = read_text(dir_ / "model.csv");
  EXPECT_EQ(run(args, dir_ / "b.log"), 2) << read_text(dir_ / "b.log");
  EXPECT_EQ(read_text(dir_ / "model.csv"), before);
  EXPECT_EQ(run(args + " --force", dir_ / "c.log"), 0) << read_text(dir_ / "c.log");
}

TEST_F(ModelJointErrorsCli, DiagnoseOnTheModelSideRaisesTheJointThatDiffers) {
  const fs::path scenario = write_scenario(dir_, "half-friction-a1",
                                           "plant_deviations:\n  A1: {coulomb_friction: 0.5}\n");
  ident::write_joint_errors_csv(dir_ / "measured.csv", measured_record(scenario));
  ASSERT_EQ(run("model-joint-errors --joint-errors " + (dir_ / "measured.csv").string() +
                    " --scenario " + scenario.string() + " --out " + (dir_ / "model.csv").string(),
                dir_ / "a.log"),
            0)
      << read_text(dir_ / "a.log");
  const std::string robot = std::string(IMSCAL_SOURCE_DIR) + "/datasets/robots/kr16.yaml";
  const fs::path out = dir_ / "out";
  ASSERT_EQ(
      run("diagnose --joint-errors " + (dir_ / "measured.csv").string() + " --sim-joint-errors " +
              (dir_ / "model.csv").string() + " --robot " + robot + " --out " + out.string(),
          dir_ / "b.log"),
      0)
      << read_text(dir_ / "b.log");
  const auto report = nlohmann::json::parse(read_text(out / "report.json"));
  EXPECT_TRUE(report["significant_gap"].get<bool>()) << report["verdict"];
  const auto& per_joint = report["gap_rms_per_joint_rad"];
  for (const char* j : {"A2", "A3", "A4", "A5", "A6"})
    EXPECT_GT(per_joint["A1"].get<double>(), 10.0 * per_joint[j].get<double>()) << j;
  EXPECT_TRUE(report["joint_significance"][0]["significant"].get<bool>());
  const std::string text = read_text(out / "report.txt");
  EXPECT_NE(text.find("Gap RMS per joint: A1"), std::string::npos);
  EXPECT_EQ(text.find("No significant structured gap"), std::string::npos);
}

// A record with a gap (samples the IMS chain could not measure, here 20 ms during the move):
// the model is written on exactly the measured samples; across the gap q_d is interpolated
// linearly (the desired path is smooth over 20 ms: its error there is ~1e-6 rad), so the joint
// errors still match the plant's.
TEST_F(ModelJointErrorsCli, ARecordWithAGapKeepsItsSamples) {
  const fs::path scenario = write_scenario(dir_, "nominal-plant", "");
  const ident::JointErrorLog truth =
      eval::simulate_truth_joint_errors(sim::load_scenario(scenario));
  ident::JointErrorLog gapped = truth;
  const std::size_t from = 1000, count = 10;  // t = 2.0 .. 2.02 s
  gapped.time_s.erase(gapped.time_s.begin() + from, gapped.time_s.begin() + from + count);
  gapped.payload_kg.erase(gapped.payload_kg.begin() + from,
                          gapped.payload_kg.begin() + from + count);
  for (auto* q : {&gapped.q_desired_rad, &gapped.q_measured_rad, &gapped.q_internal_rad})
    for (auto& v : *q) v.erase(v.begin() + from, v.begin() + from + count);
  ident::split_at_gaps(gapped);
  ASSERT_EQ(gapped.segment_starts.size(), 2u);
  ident::write_joint_errors_csv(dir_ / "gapped.csv", gapped);
  ASSERT_EQ(run("model-joint-errors --joint-errors " + (dir_ / "gapped.csv").string() +
                    " --scenario " + scenario.string() + " --out " + (dir_ / "model.csv").string(),
                dir_ / "a.log"),
            0)
      << read_text(dir_ / "a.log");
  const ident::JointErrorLog model = ident::read_joint_errors_csv(dir_ / "model.csv");
  EXPECT_EQ(model.time_s, gapped.time_s);
  const auto e_truth = eval::measured_joint_errors(gapped);
  const auto e_model = eval::measured_joint_errors(model);
  for (std::size_t j = 0; j < 6; ++j) {
    std::vector<double> diff(gapped.sample_count());
    for (std::size_t k = 0; k < diff.size(); ++k) diff[k] = e_model[j][k] - e_truth[j][k];
    EXPECT_LT(rms(diff), 2e-6) << "joint " << j;
  }
}

TEST_F(ModelJointErrorsCli, RefusesAnotherRobotsRecordAndMissingInputs) {
  const fs::path scenario = write_scenario(dir_, "nominal-plant", "");
  ident::JointErrorLog log = eval::simulate_truth_joint_errors(sim::load_scenario(scenario), 0.2);
  log.robot = "another-robot";
  ident::write_joint_errors_csv(dir_ / "other.csv", log);
  EXPECT_EQ(run("model-joint-errors --joint-errors " + (dir_ / "other.csv").string() +
                    " --scenario " + scenario.string() + " --out " + (dir_ / "m.csv").string(),
                dir_ / "a.log"),
            2);
  EXPECT_NE(read_text(dir_ / "a.log").find("another-robot"), std::string::npos)
      << read_text(dir_ / "a.log");
  EXPECT_FALSE(fs::exists(dir_ / "m.csv"));
  // Neither --robot nor --scenario: refused, nothing written.
  EXPECT_NE(run("model-joint-errors --joint-errors " + (dir_ / "other.csv").string() + " --out " +
                    (dir_ / "m.csv").string(),
                dir_ / "b.log"),
            0);
  EXPECT_FALSE(fs::exists(dir_ / "m.csv"));
}

}  // namespace
}  // namespace imscal
