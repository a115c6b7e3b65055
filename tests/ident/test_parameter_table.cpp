// parameters.json: exact round trip, and the loader's refusals of inconsistent tables, each with
// the file and the JSON path of the offending value.
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <random>
#include <string>

#include "core/input_error.hpp"
#include "ident/parameter_table_io.hpp"
#include "tests/support/arx_systems.hpp"
#include "tests/support/scratch_dir.hpp"

namespace {
namespace ident = imscal::ident;
using nlohmann::json;

// A two-joint table with random stable models, irregular numbers (to exercise the exact
// round trip of doubles) and one filled cell.
// second_harmonic: schema 4's second transmission-error pair too.
ident::ParameterTable sample_table(bool transmission_error = true, bool second_harmonic = false) {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  ident::ParameterTable t;
  t.robot = "kr16";
  t.sample_time_s = 0.002;
  t.created_by = "imscal test";
  t.model_form = ident::TableForm::kInverse;  // schema 2's keys in the round trip
  t.preview_cycles = 6;
  t.extra_inputs = {ident::TableInput::kModelTorque, ident::TableInput::kTorqueSign};
  if (transmission_error) {  // schema 3's inputs and keys
    t.extra_inputs.push_back(ident::TableInput::kTransmissionErrorSin);
    t.extra_inputs.push_back(ident::TableInput::kTransmissionErrorCos);
  }
  if (second_harmonic) {
    t.extra_inputs.push_back(ident::TableInput::kTransmissionError2Sin);
    t.extra_inputs.push_back(ident::TableInput::kTransmissionError2Cos);
  }
  const int inputs = int(t.extra_inputs.size());
  t.direction_speed_scale_rad_s = 0.0123;
  t.source = {"/tmp/joint_errors.csv", std::string(64, 'a'), 123456, "simulated"};
  for (const char* name : {"A1", "A2"}) {
    ident::JointParameters j;
    j.name = name;
    j.dimensions = {{ident::OperatingQuantity::kSpeed, {0.0, 0.1 * M_PI / 3, 2.7227136331111539}},
                    {ident::OperatingQuantity::kPayload, {0.0, 8.0, 16.0}}};
    j.backlash_l_rad = 1e-3 * uniform(rng);
    j.backlash_l_sigma_rad = 1e-5 * uniform(rng);
    j.backlash_identified = true;
    j.backlash_lag_samples = 17;
    j.torque_sign_scale_nm = 10.0 * uniform(rng) + 0.1;
    if (transmission_error) {
      j.transmission_error_rad_per_rad = 160.0 * uniform(rng) + 1.0;
      j.transmission_error_compliance_rad_per_nm = 1e-5 * uniform(rng);
    }
    if (second_harmonic) j.transmission_error_2_rad_per_rad = 400.0 * uniform(rng) + 200.0;
    const ident::CellGrid grid(j.dimensions);
    for (int flat = 0; flat < grid.cell_count(); ++flat) {
      ident::CellParameters c;
      c.bands = grid.bands_of(flat);
      c.structure = {2 + flat % 3, 1 + flat % 2, flat % 4, inputs, {3 + flat % 2, 1}};
      if (transmission_error) c.structure.nx = {3 + flat % 2, 1, 2, 1 + flat % 3};
      if (second_harmonic) c.structure.nx = {3 + flat % 2, 1, 2, 1 + flat % 3, 2, 1 + flat % 2};
      const auto model = imscal::test_support::random_multi_system(c.structure, rng);
      c.a.assign(model.a().data(), model.a().data() + model.a().size());
      c.b.assign(model.b().data(), model.b().data() + model.b().size());
      c.c.assign(model.c().data(), model.c().data() + model.c().size());
      c.figures.estimation_rows = 5000u + unsigned(flat);
      c.figures.validation_rows = 2000;
      c.figures.one_step_fit_percent = 99.1 * uniform(rng);
      c.figures.simulation_fit_percent = 95.3 * uniform(rng);
      c.figures.joint_error_fit_percent = 91.7 * uniform(rng);
      c.figures.residual_rms_rad = 1e-6 * uniform(rng);
      c.figures.whiteness_passed = flat % 2 == 0;
      c.figures.input_residual_passed = true;
      c.figures.spectral_radius = model.spectral_radius();
      if (flat == 3) {
        c.status = ident::CellStatus::kFilled;
        c.filled_from = 2;
        c.reason = "12 estimation rows, fewer than min_rows_per_cell = 2000";
      }
      j.cells.push_back(c);
    }
    t.joints.push_back(j);
  }
  return t;
}

class ParameterTableFiles : public imscal::test_support::ScratchDirTest {};

// The loader refuses `j`, naming the JSON path `field`.
void refused(const json& j, const std::string& field) {
  try {
    ident::parse_parameters_json(j.dump(), "parameters.json");
    ADD_FAILURE() << "accepted a bad table";
  } catch (const imscal::InputError& e) {
    EXPECT_EQ(e.field(), field) << e.what();
  }
}

TEST_F(ParameterTableFiles, RoundTripIsExact) {
  const ident::ParameterTable table = sample_table();
  const auto file = dir_ / "parameters.json";
  ident::write_parameters_json(file, table);
  const ident::ParameterTable back = ident::read_parameters_json(file);
  // Every double bit for bit (operator== compares the values exactly), every string and count.
  EXPECT_TRUE(back == table);
  EXPECT_EQ(ident::parameters_json_text(back), ident::parameters_json_text(table));
  // The CSV has the header and one row per joint and cell.
  ident::write_parameters_csv(dir_ / "parameters.csv", table);
  const std::string csv = ident::parameters_csv_text(table);
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 1 + 2 * 4);
}

// Schema 4's second transmission-error pair: exact round trip; its phase rate must be >= 0 (0: a
// joint without a second order) and differ from the first's; a version 3 table cannot name it.
TEST_F(ParameterTableFiles, SecondHarmonicRoundTripsAndIsChecked) {
  const ident::ParameterTable table = sample_table(true, true);
  const auto file = dir_ / "parameters.json";
  ident::write_parameters_json(file, table);
  EXPECT_TRUE(ident::read_parameters_json(file) == table);
  const json good = json::parse(ident::parameters_json_text(table));
  json same = good;
  same["joints"][0]["transmission_error_2_rad_per_rad"] =
      same["joints"][0]["transmission_error_rad_per_rad"];
  refused(same, "/joints/0/transmission_error_2_rad_per_rad");
  json negative = good;
  negative["joints"][0]["transmission_error_2_rad_per_rad"] = -1.0;
  refused(negative, "/joints/0/transmission_error_2_rad_per_rad");
  json none = good;  // a joint without a second order: written and read back as 0
  none["joints"][0]["transmission_error_2_rad_per_rad"] = 0.0;
  const ident::ParameterTable read = ident::parse_parameters_json(none.dump(), "parameters.json");
  EXPECT_EQ(read.joints[0].transmission_error_2_rad_per_rad, 0.0);
  EXPECT_EQ(json::parse(
                ident::parameters_json_text(read))["joints"][0]["transmission_error_2_rad_per_rad"],
            0.0);
  json old = good;
  old["schema_version"] = 3;
  refused(old, "/extra_inputs");
  json without = json::parse(ident::parameters_json_text(sample_table()));
  without["joints"][1]["transmission_error_2_rad_per_rad"] = 300.0;
  refused(without, "/joints/1/transmission_error_2_rad_per_rad");
}

// Schema 5's refined links of the model torque: exact round trip, one per joint, positive masses,
// not in an older table; a table without them writes no key and reads none.
TEST_F(ParameterTableFiles, ModelTorqueLinksRoundTripAndAreChecked) {
  ident::ParameterTable table = sample_table();
  EXPECT_EQ(json::parse(ident::parameters_json_text(table)).count("model_torque_links"), 0u);
  for (int i = 0; i < 2; ++i)
    table.model_torque_links.push_back({i == 0,
                                        3.1 + i,
                                        40.0 / 3.0,
                                        33.3 + i,
                                        2.2,
                                        {0.35, 0.0, 0.1 / 3.0},
                                        {0.33, 0.004, 0.09},
                                        {0.006, 0.01, 0.008}});
  const auto file = dir_ / "parameters.json";
  ident::write_parameters_json(file, table);
  EXPECT_TRUE(ident::read_parameters_json(file) == table);
  const json good = json::parse(ident::parameters_json_text(table));
  json old = good;
  old["schema_version"] = 4;
  refused(old, "/model_torque_links");
  json one = good;
  one["model_torque_links"].erase(1);
  refused(one, "/model_torque_links");
  json massless = good;
  massless["model_torque_links"][1]["mass_kg"] = 0.0;
  refused(massless, "/model_torque_links/1/mass_kg");
  json short_com = good;
  short_com["model_torque_links"][0]["com_sigma_m"] = json::array({0.1, 0.1});
  refused(short_com, "/model_torque_links/0/com_sigma_m");
}

// The gear mode of the gear-mode pairs (version 6's key, version 7's inputs): exact round trip; a
// joint without one writes no key and reads 0 (as every older table); frequency and damping > 0;
// not in a version 5 table, nor in a table without gear-mode inputs.
TEST_F(ParameterTableFiles, GearModeRoundTripsAndIsChecked) {
  using ident::TableInput;
  ident::ParameterTable table = sample_table();
  table.extra_inputs[2] = TableInput::kTransmissionErrorModeSin;  // instead of the plain pair
  table.extra_inputs[3] = TableInput::kTransmissionErrorModeCos;
  table.joints[0].transmission_error_mode_rad_s = 94.28090415820634;
  table.joints[0].transmission_error_mode_damping = 0.050677;
  const auto file = dir_ / "parameters.json";
  ident::write_parameters_json(file, table);
  EXPECT_TRUE(ident::read_parameters_json(file) == table);
  const json good = json::parse(ident::parameters_json_text(table));
  EXPECT_EQ(good["schema_version"], 7);
  EXPECT_EQ(good["joints"][1].count("transmission_error_gear_mode"), 0u);
  // Version 6 filtered its plain pairs: read as the gear-mode kinds, the same table.
  json version_6 = good;
  version_6["schema_version"] = 6;
  version_6["extra_inputs"][2] = "transmission_error_sin";
  version_6["extra_inputs"][3] = "transmission_error_cos";
  EXPECT_TRUE(ident::parse_parameters_json(version_6.dump(), "parameters.json") == table);
  json kinds_too_new = good;  // the gear-mode kinds are version 7's
  kinds_too_new["schema_version"] = 6;
  refused(kinds_too_new, "/extra_inputs");
  json old = version_6;
  old["schema_version"] = 5;
  refused(old, "/joints/0/transmission_error_gear_mode");
  json still = version_6;  // a version 5 table without the key reads as before: no mode
  still["schema_version"] = 5;
  still["joints"][0].erase("transmission_error_gear_mode");
  const ident::ParameterTable plain = ident::parse_parameters_json(still.dump(), "parameters.json");
  EXPECT_EQ(plain.joints[0].transmission_error_mode_rad_s, 0.0);
  EXPECT_EQ(plain.extra_inputs[2], TableInput::kTransmissionErrorSin);
  json zero = good;
  zero["joints"][0]["transmission_error_gear_mode"]["natural_frequency_rad_s"] = 0.0;
  refused(zero, "/joints/0/transmission_error_gear_mode/natural_frequency_rad_s");
  json undamped = good;
  undamped["joints"][0]["transmission_error_gear_mode"]["damping_ratio"] = 0.0;
  refused(undamped, "/joints/0/transmission_error_gear_mode/damping_ratio");
  json without = json::parse(ident::parameters_json_text(sample_table(false)));
  without["joints"][0]["transmission_error_gear_mode"] =
      good["joints"][0]["transmission_error_gear_mode"];
  refused(without, "/joints/0/transmission_error_gear_mode");
  // Version 7 with the plain pairs only: the mode has nothing to act on.
  json plain_7 = json::parse(ident::parameters_json_text(sample_table()));
  plain_7["joints"][0]["transmission_error_gear_mode"] =
      good["joints"][0]["transmission_error_gear_mode"];
  refused(plain_7, "/joints/0/transmission_error_gear_mode");
}

// Version 7's gear-mode pairs beside the plain pairs: exact round trip.
TEST_F(ParameterTableFiles, GearModePairsBesideThePlainPairsRoundTrip) {
  ident::ParameterTable table = sample_table(true, true);
  table.extra_inputs[4] = ident::TableInput::kTransmissionErrorModeSin;
  table.extra_inputs[5] = ident::TableInput::kTransmissionErrorModeCos;
  for (ident::JointParameters& j : table.joints) {
    j.transmission_error_2_rad_per_rad = 0.0;
    j.transmission_error_mode_rad_s = 101.5;
    j.transmission_error_mode_damping = 0.05;
  }
  const auto file = dir_ / "parameters.json";
  ident::write_parameters_json(file, table);
  EXPECT_TRUE(ident::read_parameters_json(file) == table);
}

TEST(ParameterTable, Version1TablesReadAsForwardModelsWithoutPreview) {
  json j = json::parse(ident::parameters_json_text(sample_table()));
  j["schema_version"] = 1;
  for (const char* key :
       {"model_form", "preview_cycles", "extra_inputs", "direction_speed_scale_rad_s"})
    j.erase(key);
  for (auto& joint : j["joints"]) {
    for (const char* key :
         {"torque_sign_scale_nm", "offset_envelope_rad", "offset_rate_envelope_rad_s",
          "transmission_error_rad_per_rad", "transmission_error_compliance_rad_per_nm"})
      joint.erase(key);
    for (auto& cell : joint["cells"]) {
      cell.erase("nx");
      cell.erase("c");
    }
  }
  const auto back = ident::parse_parameters_json(j.dump(), "v1.json");
  EXPECT_EQ(back.model_form, ident::TableForm::kForward);
  EXPECT_EQ(back.preview_cycles, 0);
  EXPECT_EQ(back.joints.size(), 2u);
}

// A version 2 table (before the transmission-error inputs) reads with phase rate and compliance
// 0, and is written back as version 2.
TEST(ParameterTable, Version2TablesReadWithoutTheTransmissionError) {
  const ident::ParameterTable v3 = sample_table(false);
  json j = json::parse(ident::parameters_json_text(v3));
  j["schema_version"] = 2;
  for (auto& joint : j["joints"]) {
    joint.erase("transmission_error_rad_per_rad");
    joint.erase("transmission_error_compliance_rad_per_nm");
  }
  const auto back = ident::parse_parameters_json(j.dump(), "v2.json");
  EXPECT_EQ(back.schema_version, 2);
  for (const auto& joint : back.joints) {
    EXPECT_EQ(joint.transmission_error_rad_per_rad, 0.0);
    EXPECT_EQ(joint.transmission_error_compliance_rad_per_nm, 0.0);
  }
  EXPECT_EQ(json::parse(ident::parameters_json_text(back)), j);
}

TEST(ParameterTable, NotAvailableFiguresRoundTripAsNull) {
  ident::ParameterTable table = sample_table();
  table.joints[0].cells[0].figures.simulation_fit_percent = std::nan("");
  const std::string text = ident::parameters_json_text(table);
  const auto back = ident::parse_parameters_json(text, "mem");
  EXPECT_TRUE(std::isnan(back.joints[0].cells[0].figures.simulation_fit_percent));
}

struct Refusal {
  std::string name;
  std::function<void(json&)> corrupt;
  std::string path;     // expected InputError::field
  std::string message;  // expected part of the problem
};

class LoaderRefuses : public ::testing::TestWithParam<Refusal> {};

TEST_P(LoaderRefuses, WithPathAndMessage) {
  json j = json::parse(ident::parameters_json_text(sample_table()));
  GetParam().corrupt(j);
  try {
    ident::parse_parameters_json(j.dump(), "parameters.json");
    FAIL() << "accepted a bad table";
  } catch (const imscal::InputError& e) {
    EXPECT_EQ(e.file(), "parameters.json");
    EXPECT_EQ(e.field(), GetParam().path) << e.what();
    EXPECT_NE(e.problem().find(GetParam().message), std::string::npos) << e.what();
  }
}

INSTANTIATE_TEST_SUITE_P(
    BadTables, LoaderRefuses,
    ::testing::Values(
        Refusal{"UnknownVersion", [](json& j) { j["schema_version"] = 8; }, "/schema_version",
                "unknown schema version 8"},
        Refusal{"CountsForTheFurtherInputs",
                [](json& j) { j["joints"][0]["cells"][0]["nx"] = json::array({3}); },
                "/joints/0/cells/0/nx", "1 counts for the table's 4 further inputs"},
        Refusal{"TransmissionErrorWithoutPhaseRate",
                [](json& j) { j["joints"][1]["transmission_error_rad_per_rad"] = 0.0; },
                "/joints/1/transmission_error_rad_per_rad", "the phase rate must be > 0"},
        Refusal{"NegativeCompliance",
                [](json& j) { j["joints"][0]["transmission_error_compliance_rad_per_nm"] = -1.0; },
                "/joints/0/transmission_error_compliance_rad_per_nm", "must be >= 0"},
        Refusal{"TransmissionErrorInVersion2", [](json& j) { j["schema_version"] = 2; },
                "/extra_inputs", "the transmission-error inputs need schema version 3"},
        Refusal{"FurtherCoefficientsMissing",
                [](json& j) { j["joints"][0]["cells"][0]["c"].erase(0); }, "/joints/0/cells/0/c",
                "the further inputs' nx add up to"},
        Refusal{"UnknownFurtherInput", [](json& j) { j["extra_inputs"][1] = "temperature"; },
                "/extra_inputs/1", "expected 'model_torque', 'direction', 'torque_sign', "},
        Refusal{"TorqueSignWithoutScale",
                [](json& j) { j["joints"][1]["torque_sign_scale_nm"] = 0.0; },
                "/joints/1/torque_sign_scale_nm", "the scale must be > 0"},
        Refusal{"UnknownModelForm", [](json& j) { j["model_form"] = "sideways"; }, "/model_form",
                "expected 'forward' or 'inverse'"},
        Refusal{"PreviewOfAForwardTable",
                [](json& j) {
                  j["model_form"] = "forward";
                  j["preview_cycles"] = 3;
                },
                "/preview_cycles", "only an inverse-form table has a preview"},
        Refusal{"NegativePreview",
                [](json& j) {
                  j["model_form"] = "inverse";
                  j["preview_cycles"] = -1;
                },
                "/preview_cycles", "expected 0..64 cycles"},
        Refusal{"Version1WithVersion2Keys", [](json& j) { j["schema_version"] = 1; }, "/model_form",
                "not a key of schema version 1"},
        Refusal{"WrongSchema", [](json& j) { j["schema"] = "something"; }, "/schema",
                "not an imscal parameter table"},
        Refusal{"ALengthWrong", [](json& j) { j["joints"][0]["cells"][1]["a"].push_back(0.1); },
                "/joints/0/cells/1/a", "coefficients, na ="},
        Refusal{"BLengthWrong", [](json& j) { j["joints"][1]["cells"][2]["b"] = json::array(); },
                "/joints/1/cells/2/b", "0 coefficients, nb ="},
        Refusal{"MissingCell", [](json& j) { j["joints"][0]["cells"].erase(2); }, "/joints/0/cells",
                "missing cell 2"},
        Refusal{"RepeatedCell",
                [](json& j) {
                  j["joints"][0]["cells"][1]["bands"] = j["joints"][0]["cells"][0]["bands"];
                },
                "/joints/0/cells/1/bands", "cell given twice"},
        Refusal{"NaNCoefficient", [](json& j) { j["joints"][0]["cells"][0]["a"][0] = nullptr; },
                "/joints/0/cells/0/a/0", "not a finite number"},
        Refusal{"BandOutOfRange", [](json& j) { j["joints"][0]["cells"][0]["bands"][1] = 2; },
                "/joints/0/cells/0/bands", "outside 0..1"},
        Refusal{"BandCountWrong", [](json& j) { j["joints"][0]["cells"][0]["bands"] = {0}; },
                "/joints/0/cells/0/bands", "1 band indices for 2 dimensions"},
        Refusal{"BoundsNotIncreasing",
                [](json& j) {
                  j["joints"][1]["dimensions"][1]["bounds"] = {0.0, 8.0, 8.0};
                },
                "/joints/1/dimensions/1/bounds", "strictly increasing"},
        Refusal{"UnstableModel",
                [](json& j) {
                  auto& c = j["joints"][0]["cells"][0];
                  c["na"] = 1;
                  c["a"] = {-1.5};  // pole at z = 1.5
                },
                "/joints/0/cells/0/a", "unstable"},
        Refusal{"MissingKey", [](json& j) { j["joints"][0].erase("backlash"); },
                "/joints/0/backlash", "missing key"},
        Refusal{"UnknownKey", [](json& j) { j["joints"][0]["cells"][0]["d"] = 1; },
                "/joints/0/cells/0/d", "unknown key"},
        Refusal{"WrongUnit", [](json& j) { j["units"]["angle"] = "deg"; }, "/units/angle",
                "expected 'rad'"},
        Refusal{"NegativeBacklash", [](json& j) { j["joints"][1]["backlash"]["l_rad"] = -1e-4; },
                "/joints/1/backlash/l_rad", "negative backlash"},
        Refusal{"BadSampleTime", [](json& j) { j["sample_time_s"] = 0.0; }, "/sample_time_s",
                "sample time must be > 0"},
        Refusal{"DuplicateJoint", [](json& j) { j["joints"][1]["name"] = "A1"; }, "/joints/1/name",
                "given twice"},
        Refusal{"WrongType", [](json& j) { j["joints"][0]["cells"][0]["na"] = "two"; },
                "/joints/0/cells/0/na", "expected an integer"}),
    [](const ::testing::TestParamInfo<Refusal>& info) { return info.param.name; });

TEST(ParameterTable, NotJsonRefused) {
  EXPECT_THROW(ident::parse_parameters_json("{\"schema\": ", "p.json"), imscal::InputError);
}

}  // namespace
