// An identification config against the record it identifies (ident/
// identification_config_record.hpp): durations in seconds become counts of the record's cycle
// (closed form: round(duration / cycle)), the shipped config gives at 2 ms exactly the counts it
// gave as counts, and a config of another robot or of another cycle's counts is refused naming
// the config file, line and key.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "core/config_node.hpp"
#include "core/input_error.hpp"
#include "ident/identification_config.hpp"
#include "ident/identification_config_record.hpp"

namespace imscal::ident {
namespace {

const std::filesystem::path kDefault =
    std::filesystem::path(IMSCAL_SOURCE_DIR) / "datasets/identification/ident-default.yaml";

IdentificationConfig shipped() {
  return load_identification_config(ConfigNode::load_file(kDefault));
}

IdentificationConfig from_text(const std::string& yaml) {
  return load_identification_config(ConfigNode::load_string(yaml, "test.yaml"));
}

constexpr const char* kCountsConfig = R"(imscal-identification-config: 1
robot: kr16
cycle_s: 0.002
joints: {max_speed_deg_s: [156, 156, 156, 330, 330, 615], nominal_payload_kg: 16}
model: {form: inverse, preview_cycles: 20, model_torque: true, input_taps: 60}
)";

TEST(IdentificationConfigRecord, ShippedDurationsGiveTheCountsOfTheTwoMillisecondCycle) {
  // The counts the shipped config held before it stated seconds: its figures are those counts'.
  const IdentificationConfig c = shipped();
  EXPECT_EQ(c.robot, "kr16");
  EXPECT_EQ(c.options.preview_cycles, 20);
  EXPECT_EQ(c.options.input_taps, 60);
  EXPECT_EQ(c.options.transmission_error_taps, 32);
  EXPECT_EQ(c.options.min_rows_per_cell, 2000u);
  const IdentificationConfig at_2ms = resolve_for_record(c, "kr16", 0.002, "log.csv");
  EXPECT_EQ(at_2ms.options.input_taps, 60);
  EXPECT_EQ(at_2ms.resolved_cycle_s, 0.002);
}

TEST(IdentificationConfigRecord, AtTenMillisecondsTheDurationsStayDurations) {
  std::vector<std::string> warnings;
  const IdentificationConfig c = resolve_for_record(shipped(), "kr16", 0.01, "log.csv", &warnings);
  EXPECT_EQ(c.options.preview_cycles, 4);           // 0.04 s / 0.01 s
  EXPECT_EQ(c.options.input_taps, 12);              // 0.12 / 0.01
  EXPECT_EQ(c.options.transmission_error_taps, 6);  // 0.064 / 0.01 = 6.4, rounded
  EXPECT_EQ(c.options.min_rows_per_cell, 400u);     // 4 / 0.01
  EXPECT_EQ(c.options.torque_sign_taps, 1);         // a count: the config states no cycle_s
  bool rounded = false, counts_taken = false;
  for (const std::string& w : warnings) {
    rounded |= w.find("model.transmission_error_history_s") != std::string::npos;
    counts_taken |= w.find("taken in cycles of 0.01 s") != std::string::npos;
  }
  EXPECT_TRUE(rounded);
  EXPECT_TRUE(counts_taken);
}

TEST(IdentificationConfigRecord, AtOneMillisecondThePreviewExceedsThePrecontrol) {
  // 0.04 s at 1 ms is 40 cycles; the precontrol looks at most 32 ahead.
  try {
    (void)resolve_for_record(shipped(), "kr16", 0.001, "log.csv");
    FAIL() << "no refusal";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "model.preview_s");
    EXPECT_EQ(e.file(), kDefault.string());
    EXPECT_GT(e.line(), 0u);
    EXPECT_NE(std::string(e.what()).find("40 cycles of 0.001 s"), std::string::npos) << e.what();
  }
  // 0.12 s of input history at 1 ms is 120 coefficients; the precontrol holds 64 per input.
  const IdentificationConfig history = from_text(R"(imscal-identification-config: 1
joints: {max_speed_deg_s: [156, 156, 156, 330, 330, 615], nominal_payload_kg: 16}
model: {form: inverse, model_torque: true, input_history_s: 0.12}
)");
  try {
    (void)resolve_for_record(history, "kr16", 0.001, "log.csv");
    FAIL() << "no refusal";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "model.input_history_s");
    EXPECT_EQ(e.line(), 3u);
    EXPECT_NE(std::string(e.what()).find("120 cycles of 0.001 s"), std::string::npos) << e.what();
  }
}

TEST(IdentificationConfigRecord, AnotherRobotsLogIsRefused) {
  try {
    (void)resolve_for_record(shipped(), "ur10e", 0.002, "ur10e.csv");
    FAIL() << "no refusal";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "robot");
    EXPECT_EQ(e.line(), 6u);  // `robot: kr16` in ident-default.yaml
    const std::string what = e.what();
    EXPECT_NE(what.find("'kr16'"), std::string::npos) << what;
    EXPECT_NE(what.find("ur10e.csv is of robot 'ur10e'"), std::string::npos) << what;
  }
}

TEST(IdentificationConfigRecord, CountsOfAnotherCycleAreRefused) {
  const IdentificationConfig counts = from_text(kCountsConfig);
  EXPECT_EQ(resolve_for_record(counts, "kr16", 0.002, "log.csv").options.preview_cycles, 20);
  try {
    (void)resolve_for_record(counts, "kr16", 0.01, "log.csv");
    FAIL() << "no refusal";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "cycle_s");
    EXPECT_EQ(e.line(), 3u);
    EXPECT_NE(std::string(e.what()).find("sampled every 0.01 s"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace imscal::ident
