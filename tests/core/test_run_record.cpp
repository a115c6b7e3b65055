// run.json (core/run_record.hpp): what is written is read back, and a record that is not JSON,
// of another kind or version, or with a missing or mistyped field is refused naming the file and
// the field; `imscal run`'s folder check (core/run_stage.hpp) goes through the same reader.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "core/input_error.hpp"
#include "core/run_record.hpp"
#include "tests/support/refused_file.hpp"
#include "tests/support/scratch_dir.hpp"

namespace imscal {
namespace {

using RunRecordTest = test_support::ScratchDirTest;

TEST_F(RunRecordTest, WhatIsWrittenIsReadBack) {
  const auto file = dir_ / "run.json";
  // A config path with a non-ASCII name, as a user's folder may have.
  const RunRecord written{"/home/user/Kampagne \xc3\xa4/run.yaml", "imscal 9.8.7"};
  write_run_record(file, written);
  const RunRecord read = read_run_record(file);
  EXPECT_EQ(read.config, written.config);
  EXPECT_EQ(read.created_by, written.created_by);
}

TEST_F(RunRecordTest, RefusalsNameTheFileAndTheField) {
  const auto file = dir_ / "run.json";
  struct Case {
    std::string text, field;
  };
  const std::vector<Case> cases = {
      {R"({"schema": "imscal-run-folder", "schema_version": 1, "created_by": "x"})", "config"},
      {R"({"schema": "imscal-run-folder", "schema_version": 1, "config": 3, "created_by": "x"})",
       "config"},
      {R"({"schema": "imscal-run-folder", "schema_version": 2, "config": "a", "created_by": "x"})",
       "schema_version"},
      {R"({"schema": "imscal-frames", "schema_version": 1, "config": "a", "created_by": "x"})",
       "schema"},
      {R"({"schema_version": 1, "config": "a", "created_by": "x"})", "schema"},
      {R"({"schema": "imscal-run-folder", "schema_version": 1, "config": "a", "config": "b",
           "created_by": "x"})",
       "config"},
      {R"([1, 2])", ""},
      {"{\"schema\": ", ""},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.text);
    test_support::expect_refused_naming_field(read_run_record, file, c.text, c.field);
  }
}

// The record `imscal run` wrote for the shipped campaign (the fuzz target's seed).
TEST(RunRecordFile, TheShippedCampaignsRecordIsRead) {
  const RunRecord r = read_run_record(std::filesystem::path(IMSCAL_SOURCE_DIR) / "fuzz" / "corpus" /
                                      "run_record" / "campaign.json");
  EXPECT_EQ(r.config, "/home/user/imscal/datasets/campaign/run.yaml");
}

}  // namespace
}  // namespace imscal
