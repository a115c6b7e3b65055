// identification_report.json (ident/identification_report.hpp): an identification written is read
// back with the same figures (cells, chosen orders, held-out fits, backlash, order search, the
// identified structure), and a report with a missing or mistyped field is refused naming the file
// and the field.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>

#include "core/input_error.hpp"
#include "core/json_output.hpp"
#include "ident/identification_report.hpp"
#include "tests/support/json_edit.hpp"
#include "tests/support/refused_file.hpp"
#include "tests/support/scratch_dir.hpp"

namespace imscal::ident {
namespace {

using nlohmann::json;
using IdentificationReportTest = test_support::ScratchDirTest;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// One joint with an identified cell (sweep, fit, stability, validation) and a cell filled from it.
JointOutcome sample_joint() {
  JointOutcome outcome;
  outcome.seconds = 1.25;
  JointIdentification& r = outcome.result;
  r.parameters.name = "A2";
  r.table_fit = {9.75, 3300};
  r.parameters.backlash_identified = true;
  r.parameters.backlash_l_rad = 2.5e-4;
  r.parameters.cells.resize(2);
  r.parameters.cells[0].figures.joint_error_fit_percent = 57.25;
  r.parameters.cells[1].figures.joint_error_fit_percent = kNaN;  // no held-out rows
  r.backlash.l_rad = 2.5e-4;
  r.backlash.l_sigma_rad = 1e-5;
  r.backlash.reversals_found = 7;
  r.backlash.reversals_used = 5;
  r.backlash.lag_samples = 3;
  r.backlash.per_reversal_rad = {2.4e-4, 2.6e-4};
  CellIdentification identified;
  identified.cell = 0;
  identified.label = "speed[0,0.5)";
  identified.estimation_rows = 4000;
  identified.validation_rows = 1700;
  identified.rms_speed_rad_s = 0.21;
  identified.sweep = OrderSweepResult{};
  identified.sweep->chosen = ArxStructure{3, 5, 1};
  identified.fit = ArxFitResult{
      ArxModel(ArxStructure{3, 5, 0}, Eigen::VectorXd::Zero(3), Eigen::VectorXd::Zero(5)),
      Eigen::VectorXd::Constant(8, 1e-3), Eigen::MatrixXd::Identity(8, 8) * 1e-6};
  identified.stability = StabilityCheck{};
  identified.stability->stable = true;
  identified.validation = ArxValidationReport{};
  identified.validation->sample_count = 1690;
  identified.validation->one_step_fit_percent = 88.5;
  identified.validation->simulation_fit_percent = 61.0;
  CellIdentification filled;
  filled.cell = 1;
  filled.label = "speed[0.5,2)";
  filled.status = CellStatus::kFilled;
  filled.filled_from = 0;
  filled.reason = "0 estimation rows";
  r.cells = {identified, filled};
  outcome.structure.cells = 1;
  outcome.structure.compliance_rad_per_nm = {2.5e-6, 1e-7};
  outcome.structure.nominal_compliance_rad_per_nm = 2.2e-6;
  outcome.structure.transmission_error_phase_rad = {0.75, 0.125};
  outcome.structure.transmission_error_joint_speed_rad_s = 0.625;
  outcome.structure.transmission_error_frequency_hz = 15.5;
  return outcome;
}

IdentificationReportHeader sample_header() {
  IdentificationReportHeader h{
      "imscal 9.8.7",     "/d/joint_errors.csv", "ab12", "/d/identify.yaml", 35000, 2, 0.002, 3.5,
      OrderSearchReport{}};
  h.order_search->candidates_per_motor_rev = {0.5, 1.0, 2.0};
  h.order_search->joints = {{"A2", 1.0, 2.0, 4.5, 2.0, {10.0, kNaN, 31.0}}};
  h.order_search->joints[0].tracking_windows = 30;
  h.order_search->joints[0].tracked_orders = {{3.5, 3.0e-5, 6.5e-6, 184.0, 2.75},
                                              {4.0, 2.5e-5, 7.0e-6, 115.0, 2.625}};
  return h;
}

TEST_F(IdentificationReportTest, WhatIsWrittenIsReadBack) {
  const auto file = dir_ / "identification_report.json";
  const JointOutcome joint = sample_joint();
  const IdentificationReportHeader header = sample_header();
  std::ofstream(file) << json_text(identification_report_json(header, {joint}), 1, "");
  const IdentificationReport read = read_identification_report(file);
  EXPECT_EQ(read.header.created_by, header.created_by);
  EXPECT_EQ(read.header.joint_errors_sha256, "ab12");
  EXPECT_EQ(read.header.samples, 35000u);
  EXPECT_EQ(read.header.segments, 2u);
  EXPECT_EQ(read.header.sample_time_s, 0.002);
  ASSERT_TRUE(read.header.order_search.has_value());
  const OrderSearchJoint& searched = read.header.order_search->joints.at(0);
  EXPECT_EQ(searched.chosen_harmonic_per_motor_rev, 2.0);
  EXPECT_EQ(searched.gain_points, 4.5);
  EXPECT_TRUE(std::isnan(searched.held_out_joint_error_fit_percent.at(1)));
  EXPECT_EQ(searched.tracking_windows, 30u);
  ASSERT_EQ(searched.tracked_orders.size(), 2u);
  EXPECT_EQ(searched.tracked_orders[1].order_per_motor_rev, 4.0);
  EXPECT_EQ(searched.tracked_orders[1].amplitude_rad, 2.5e-5);
  EXPECT_EQ(searched.tracked_orders[1].floor_rad, 7.0e-6);
  EXPECT_EQ(searched.tracked_orders[1].significance_sigma, 115.0);
  EXPECT_EQ(searched.tracked_orders[1].t_statistic, 2.625);
  ASSERT_EQ(read.joints.size(), 1u);
  const ReportedJoint& j = read.joints[0];
  EXPECT_EQ(j.name, "A2");
  EXPECT_EQ(j.seconds, 1.25);
  EXPECT_EQ(j.table_joint_error_fit_percent, 9.75);
  EXPECT_EQ(j.table_validation_rows, 3300u);
  EXPECT_TRUE(j.backlash.identified);
  EXPECT_EQ(j.backlash.l_rad, 2.5e-4);
  EXPECT_EQ(j.backlash.full_play_rad, 5e-4);
  EXPECT_EQ(j.backlash.reversals_used, 5u);
  EXPECT_EQ(j.backlash.per_reversal_l_rad, joint.result.backlash.per_reversal_rad);
  ASSERT_EQ(j.cells.size(), 2u);
  const ReportedCell& c = j.cells[0];
  EXPECT_EQ(c.status, CellStatus::kIdentified);
  EXPECT_EQ(c.estimation_rows, 4000u);
  ASSERT_TRUE(c.chosen.has_value());
  EXPECT_EQ(c.chosen->na, 3);
  EXPECT_EQ(c.chosen->nb, 5);
  EXPECT_EQ(c.chosen->dead_time, 1);
  ASSERT_TRUE(c.validation.has_value());
  EXPECT_EQ(c.validation->samples, 1690u);
  EXPECT_EQ(c.validation->simulation_fit_percent, 61.0);
  EXPECT_EQ(c.validation->joint_error_fit_percent, 57.25);
  EXPECT_EQ(j.cells[1].status, CellStatus::kFilled);
  EXPECT_EQ(j.cells[1].filled_from, 0);
  EXPECT_EQ(j.cells[1].reason, "0 estimation rows");
  EXPECT_FALSE(j.cells[1].validation.has_value());
  ASSERT_TRUE(j.structure.has_value());
  EXPECT_EQ(j.structure->cells, 1u);
  EXPECT_EQ(j.structure->compliance_rad_per_nm.value, 2.5e-6);
  EXPECT_EQ(j.structure->compliance_rad_per_nm.sigma, 1e-7);
  EXPECT_EQ(j.structure->nominal_compliance_rad_per_nm, 2.2e-6);
  EXPECT_EQ(j.structure->transmission_error_phase_rad.sigma, 0.125);
  EXPECT_EQ(j.structure->transmission_error_joint_speed_rad_s, 0.625);
  EXPECT_EQ(j.structure->transmission_error_frequency_hz, 15.5);
  EXPECT_FALSE(j.structure->stiffness_nm_per_rad.identified());  // NaN written as null, read as NaN
}

TEST_F(IdentificationReportTest, RefusalsNameTheFileAndTheField) {
  const auto file = dir_ / "identification_report.json";
  const json good = identification_report_json(sample_header(), {sample_joint()});
  const auto refused = [&](const json::json_pointer& at, const json& value,
                           const std::string& field) {
    SCOPED_TRACE(field);
    test_support::expect_refused_naming_field(read_identification_report, file,
                                              test_support::edited(good, at, value).dump(), field);
  };
  const json& removed = test_support::kRemovedJson;
  refused("/imscal-identification-report"_json_pointer, removed, "imscal-identification-report");
  refused("/samples"_json_pointer, "many", "samples");
  refused("/joints/0/cells/1/status"_json_pointer, "guessed", "joints[0].cells[1].status");
  refused("/joints/0/cells/0/validation/simulation_fit_percent"_json_pointer, "61",
          "joints[0].cells[0].validation.simulation_fit_percent");
  refused("/joints/0/backlash/l_rad"_json_pointer, removed, "joints[0].backlash.l_rad");
  refused("/joints/0/cells/0/chosen/na"_json_pointer, 2.5, "joints[0].cells[0].chosen.na");
  refused("/transmission_error_order_search/joints/0/held_out_joint_error_fit_percent"_json_pointer,
          {1.0}, "transmission_error_order_search.joints[0].held_out_joint_error_fit_percent");
  refused("/joints"_json_pointer, json::object(), "joints");
  refused("/joints/0/table_validation_rows"_json_pointer, removed,
          "joints[0].table_validation_rows");
  refused("/joints/0/structure/transmission_error_frequency_hz"_json_pointer, "15",
          "joints[0].structure.transmission_error_frequency_hz");
}

// A report without the transmission error's speed and frequency (the pair's static gains, no
// frequency) is read with them NaN, not refused.
TEST_F(IdentificationReportTest, AStructureWithoutTheErrorsFrequencyReadsItAsNaN) {
  const auto file = dir_ / "identification_report.json";
  json older = identification_report_json(sample_header(), {sample_joint()});
  older["joints"][0]["structure"].erase("transmission_error_joint_speed_rad_s");
  older["joints"][0]["structure"].erase("transmission_error_frequency_hz");
  std::ofstream(file) << older.dump();
  const IdentificationReport read = read_identification_report(file);
  ASSERT_TRUE(read.joints.at(0).structure.has_value());
  EXPECT_TRUE(std::isnan(read.joints[0].structure->transmission_error_joint_speed_rad_s));
  EXPECT_TRUE(std::isnan(read.joints[0].structure->transmission_error_frequency_hz));
  EXPECT_EQ(read.joints[0].structure->transmission_error_phase_rad.value, 0.75);
}

// The report `imscal identify` wrote for the shipped campaign (the fuzz target's seed, its
// criterion curves cut to one point): read whole, six joints of two cells (identify.yaml: two
// speed bands, one payload band).
TEST(IdentificationReportFile, TheShippedCampaignsReportIsRead) {
  const IdentificationReport r =
      read_identification_report(std::filesystem::path(IMSCAL_SOURCE_DIR) / "fuzz" / "corpus" /
                                 "identification_report" / "campaign.json");
  ASSERT_EQ(r.joints.size(), 6u);
  for (const ReportedJoint& j : r.joints) EXPECT_EQ(j.cells.size(), 2u) << j.name;
  EXPECT_EQ(r.header.sample_time_s, 0.002);
}

}  // namespace
}  // namespace imscal::ident
