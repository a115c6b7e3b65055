// The measurement as a candidate (eval/gap_measurement_budget.hpp): the gap tested against the IMS
// chain's own error budget. The chi-squared tail against tabulated quantiles; the noise floor's
// header key read and refused; then end to end through the chain (`simulate` -> `calibrate` ->
// `model-joint-errors` -> `diagnose --frames`) against the simulator's truth:
//   control   the shipped campaign (datasets/campaign: plant = nominal robot), so the whole gap is
//             the chain's own error: it must be called within the measurement, no cause raised;
//   withheld  the campaign's plant with a transmission error of 30" on A2 (once per motor
//             revolution) that the nominal model lacks: a robot effect of ~2x the chain's error
//             on that joint, which must be called beyond the measurement and ranked first, and
//             which `diagnose --scenario` sizes by re-simulating the nominal model.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>

#include "core/input_error.hpp"
#include "eval/gap_measurement_budget.hpp"
#include "ident/joint_error_io.hpp"
#include "tests/support/run_imscal.hpp"
#include "tests/support/scratch_dir.hpp"
#include "tests/support/text_file.hpp"

namespace imscal {
namespace {

namespace fs = std::filesystem;
using MeasurementBudgetCli = test_support::ScratchDirTest;
constexpr auto* run = &imscal::test_support::run_imscal;
using imscal::test_support::read_text;

TEST(MeasurementBudget, ChiSquaredTailMatchesTheTables) {
  // Upper quantiles of chi2 (Abramowitz & Stegun, table 26.8): P(X >= x) = p. Wilson-Hilferty
  // is good to ~1 % of p at these dof; 5 % tolerance leaves room and still fails a wrong formula
  // (e.g. the lower tail, or dof off by one: 10-20 % at dof 10).
  struct Quantile {
    double dof, x, p;
  };
  for (const Quantile q : {Quantile{10, 18.307, 0.05}, Quantile{30, 50.892, 0.01},
                           Quantile{100, 135.807, 0.01}, Quantile{100, 149.449, 0.001}}) {
    EXPECT_NEAR(eval::chi2_upper_tail(q.x, q.dof) / q.p, 1.0, 0.05) << q.dof << " " << q.x;
  }
  EXPECT_EQ(eval::chi2_upper_tail(0.0, 10.0), 1.0);
  EXPECT_GT(eval::chi2_upper_tail(5.0, 30.0), 0.999);  // far below the dof: all within
}

TEST(MeasurementBudget, NoiseFloorIsReadFromTheHeaderOrRefused) {
  ident::JointErrorLog log;
  log.joint_names = {"A1", "A2"};
  EXPECT_TRUE(eval::noise_floor_from_log(log, "j.csv").empty());  // no key: not known
  log.metadata = {{"other", "1"}, {eval::kNoiseFloorKey, "5e-05,6.5e-05"}};
  EXPECT_EQ(eval::noise_floor_from_log(log, "j.csv"), (std::vector<double>{5e-5, 6.5e-5}));
  for (const char* bad : {"5e-05", "5e-05,x", "5e-05,-1e-5", "5e-05,0", "5e-05,nan"}) {
    log.metadata = {{eval::kNoiseFloorKey, bad}};
    EXPECT_THROW(eval::noise_floor_from_log(log, "j.csv"), InputError) << bad;
  }
}

// calibrate -> model-joint-errors (the shipped campaign scenario: the nominal model) -> diagnose
// with the frames, on a campaign record in `record` (imu.csv, robot.csv); returns report.json.
nlohmann::json diagnose_through_the_chain(const fs::path& dir, const fs::path& record) {
  const std::string data = IMSCAL_SOURCE_DIR "/datasets";
  const fs::path cal = dir / "cal";
  EXPECT_LE(run("calibrate --imu " + (record / "imu.csv").string() + " --robot-log " +
                    (record / "robot.csv").string() + " --config " + data +
                    "/campaign/calibrate.yaml --out " + cal.string(),
                dir / "cal.log"),
            1)
      << read_text(dir / "cal.log");
  EXPECT_EQ(run("model-joint-errors --joint-errors " + (cal / "joint_errors.csv").string() +
                    " --scenario " + data + "/scenarios/campaign.yaml --out " +
                    (dir / "model.csv").string(),
                dir / "model.log"),
            0)
      << read_text(dir / "model.log");
  EXPECT_EQ(
      run("diagnose --joint-errors " + (cal / "joint_errors.csv").string() +
              " --sim-joint-errors " + (dir / "model.csv").string() + " --robot " + data +
              "/robots/kr16.yaml --frames " + (cal / "frames.json").string() + " --scenario " +
              data + "/scenarios/campaign.yaml --out " + (dir / "out").string(),
          dir / "diagnose.log"),
      0)
      << read_text(dir / "diagnose.log");
  return nlohmann::json::parse(read_text(dir / "out" / "report.json"));
}

void print_budget(const char* what, const nlohmann::json& m) {
  std::printf("%s: within %d, chi2 %.1f for %.1f dof (p %.3g), frames chi2 %.1f for %.0f\n", what,
              int(m["within"].get<bool>()), m["chi2"].get<double>(), m["dof"].get<double>(),
              m["p_value"].get<double>(), m["frames_chi2"].get<double>(),
              m["frames_dof"].get<double>());
  for (const auto& j : m["joints"])
    std::printf(
        "  %s gap %.3g rad, after the chain's columns %.3g, floor %.3g, expected %.3g, "
        "chi2 %.1f / %.1f, p %.3g\n",
        j["joint"].get<std::string>().c_str(), j["gap_rms_rad"].get<double>(),
        j["residual_rms_rad"].get<double>(), j["noise_floor_rad"].get<double>(),
        j["expected_rms_rad"].get<double>(), j["chi2"].get<double>(), j["dof"].get<double>(),
        j["p_value"].get<double>());
}

TEST_F(MeasurementBudgetCli, ControlMeasuredThroughTheChainIsWithinTheMeasurement) {
  if (std::getenv("IMSCAL_SANITIZED")) GTEST_SKIP() << "Release only: calibrate and diagnose";
  const nlohmann::json report =
      diagnose_through_the_chain(dir_, IMSCAL_SOURCE_DIR "/datasets/campaign");
  const auto& m = report["measurement"];
  print_budget("control (shipped campaign, plant = nominal)", m);
  EXPECT_TRUE(m["with_frames"].get<bool>());
  EXPECT_TRUE(m["within"].get<bool>()) << report["verdict"];
  EXPECT_FALSE(report["significant_gap"].get<bool>()) << report["verdict"];
  EXPECT_TRUE(report["leading_group"].empty());
  const std::string verdict = report["verdict"];
  EXPECT_NE(verdict.find("within what the measurement explains"), std::string::npos) << verdict;
  EXPECT_EQ(verdict.find("Most likely cause"), std::string::npos) << verdict;
  // Within the measurement, the cause ranked first is still named (a robot effect near the floor
  // is called within): report.json's first candidate.
  ASSERT_FALSE(report["candidates"].empty());
  const std::string first = "the cause ranked first is " +
                            report["candidates"][0]["effect"].get<std::string>() + " on joint " +
                            report["candidates"][0]["joint"].get<std::string>();
  EXPECT_NE(verdict.find(first), std::string::npos) << verdict;
  // The floor is the smoother's own sigma, not fitted to the gap: with plant = nominal the gap is
  // the chain's true error (the nominal model reproduces the plant to < 2e-6 rad,
  // tests/eval/test_model_joint_errors_cli.cpp), and it must lie at or below the floor. Measured
  // gap / floor 0.59..1.05 (A4 highest); 1.25 allows for the held-out half's scatter.
  for (const auto& j : m["joints"])
    EXPECT_LT(j["gap_rms_rad"].get<double>(), 1.25 * j["noise_floor_rad"].get<double>())
        << j["joint"];
}

TEST_F(MeasurementBudgetCli, WithheldTransmissionErrorIsBeyondTheMeasurement) {
  if (std::getenv("IMSCAL_SANITIZED")) GTEST_SKIP() << "Release only: simulate and diagnose";
  const std::string data = IMSCAL_SOURCE_DIR "/datasets";
  std::string scenario = read_text(data + "/scenarios/campaign.yaml");
  for (std::size_t at = scenario.find("../"); at != std::string::npos;
       at = scenario.find("../", at))
    scenario.replace(at, 3, data + "/");
  const std::string effects_end = "transmission_error: false}\n";
  const std::size_t at = scenario.find(effects_end);
  ASSERT_NE(at, std::string::npos);
  scenario.insert(
      at + effects_end.size(),
      "  A2: {transmission_error: true}\n  transmission_error: {amplitude_arcsec: 30}\n");
  std::ofstream(dir_ / "te.yaml") << scenario;
  ASSERT_EQ(run("simulate --scenario " + (dir_ / "te.yaml").string() + " --out " +
                    (dir_ / "sim").string(),
                dir_ / "sim.log"),
            0)
      << read_text(dir_ / "sim.log");
  const nlohmann::json report = diagnose_through_the_chain(dir_, dir_ / "sim");
  const auto& m = report["measurement"];
  print_budget("transmission error 30\" on A2", m);
  EXPECT_FALSE(m["within"].get<bool>()) << report["verdict"];
  // Beyond it on A2 (measured p 3.4e-4 against the corrected level 1.4e-3), on no other joint.
  const double alpha = m["corrected_alpha"];
  for (const auto& j : m["joints"])
    EXPECT_EQ(j["p_value"].get<double>() < alpha, j["joint"] == "A2") << j["joint"];
  EXPECT_TRUE(report["significant_gap"].get<bool>());
  EXPECT_EQ(report["candidates"][0]["effect"], "transmission_error");
  EXPECT_EQ(report["candidates"][0]["joint"], "A2");
  const std::string verdict = report["verdict"];
  EXPECT_NE(verdict.find("beyond what the measurement explains"), std::string::npos) << verdict;
  // diagnose --scenario: the joint model refined by re-simulating the campaign's nominal model
  // along the measured record (its gaps mapped onto the simulated grid). Measured: 18 runs,
  // "A2 transmission error of order 1 per motor revolution, 35 arcsec" against the true 30";
  // 22..40 allows for the chain's error on A2 (~9" RMS) that the fit shares.
  const auto& refinement = report["refinement"];
  ASSERT_TRUE(refinement["applied"].get<bool>()) << refinement.dump();
  const std::string change = refinement["changes"][0];
  std::printf("refined: %s\n", change.c_str());
  const std::string prefix = "A2 transmission error of order 1 per motor revolution, ";
  ASSERT_EQ(change.rfind(prefix, 0), 0u) << change;
  const double amplitude_arcsec = std::stod(change.substr(prefix.size()));
  EXPECT_GT(amplitude_arcsec, 22.0);
  EXPECT_LT(amplitude_arcsec, 40.0);
}

}  // namespace
}  // namespace imscal
