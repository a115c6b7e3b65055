// The transmission error's order per motor revolution found from the identification record
// (eval/transmission_error_order.hpp): on the deviating plant's identification runs, whose gears
// err twice per motor revolution (datasets/scenarios/deviating-identification.yaml, the known
// simulated truth) while the identification config says once, the search finds 2 on A1..A3, the
// joints that carry the error into the path. And a per-joint harmonic list in the config reaches
// each joint's phase rate. On a plant whose gears err at two orders, the search finds both.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "core/config_node.hpp"
#include "eval/transmission_error_order.hpp"
#include "eval/verification.hpp"
#include "ident/identification_config.hpp"
#include "ident/parameter_table_io.hpp"
#include "sim/scenario.hpp"
#include "tests/support/text_file.hpp"

namespace imscal::eval {
namespace {

const std::string kDefaultConfig =
    std::string(IMSCAL_SOURCE_DIR) + "/datasets/identification/ident-default.yaml";

TEST(TransmissionErrorOrder, APerJointListGivesEachJointItsPhaseRate) {
  const ident::IdentificationConfig config =
      ident::load_identification_config(ConfigNode::load_string(
          "imscal-identification-config: 1\n"
          "joints: {max_speed_deg_s: [156, 156, 156, 330, 330, 615],\n"
          "         gear_ratio: [160, 160, 150, 100, 100, 58], nominal_payload_kg: 16}\n"
          "model: {transmission_error: true,\n"
          "        transmission_error_harmonic_per_motor_rev: [2, 2, 1.5, 1, 1, 0.5]}\n",
          "per-joint harmonics"));
  const std::vector<double> harmonic{2, 2, 1.5, 1, 1, 0.5}, ratio{160, 160, 150, 100, 100, 58};
  for (std::size_t j = 0; j < 6; ++j) {
    EXPECT_EQ(config.transmission_error_harmonic(j), harmonic[j]);
    EXPECT_EQ(config.joint_options(j).transmission_error_rad_per_rad, harmonic[j] * ratio[j]);
  }
}

// Candidates 1 (the config's, the prior), 2 (the plant's) and 3. The gains measured: A1 0.22,
// A2 0.69, A3 0.95 points of held-out joint-error fit over the prior (> 0.15 needed to replace it).
TEST(TransmissionErrorOrder, FindsTheDeviatingPlantsTwoPerRevolutionOnA1ToA3) {
  const sim::Scenario scenario =
      sim::load_scenario(sim::resolve_scenario("deviating-identification"));
  const ident::JointErrorLog log = simulate_truth_joint_errors(scenario);
  const ident::IdentificationConfig config =
      ident::load_identification_config(ConfigNode::load_file(kDefaultConfig));
  ASSERT_EQ(config.transmission_error_harmonic(1), 1.0);
  const ModelTorqueSource model = scenario_model_torque(scenario);
  const TransmissionErrorOrderSearch search =
      search_transmission_error_orders(log, config, {1.0, 2.0, 3.0}, &model);
  ASSERT_EQ(search.chosen_harmonic.size(), 6u);
  for (std::size_t j = 0; j < 3; ++j) {
    SCOPED_TRACE(log.joint_names[j]);
    fmt::print("{}: fits 1: {:.2f}, 2: {:.2f}, 3: {:.2f} %; chosen {}\n", log.joint_names[j],
               search.fit_percent[0][j], search.fit_percent[1][j], search.fit_percent[2][j],
               search.chosen_harmonic[j]);
    EXPECT_EQ(search.chosen_harmonic[j], 2.0);
    EXPECT_GT(search.gain_points[j], 0.15);
  }
  const ident::IdentificationConfig searched = with_searched_orders(config, search);
  EXPECT_EQ(searched.transmission_error_harmonic(1), 2.0);
}

// The deviating plant with a second order on A2 and A3: 2 per motor revolution at 15" (as
// shipped, every joint) plus 3.5 per revolution at 15", 100 deg on A2 and A3 (the known simulated
// truth); A1 keeps its one order. Candidates 1 (the prior), 2, 3.5 and 4. The two passes find
// {2, 3.5} on A2 and A3 (3.5 first: at the same amplitude its faster phase moves the joint more)
// and the second pair lowers their held-out BIC; A1 keeps no second harmonic, and its table
// cells get zero coefficients for the pair.
TEST(TransmissionErrorOrder, FindsASecondOrderWhereAJointHasOne) {
  // One simulated identification session, eight identifications at one order and two with the
  // order sweep: ~15 s CPU in Release.
  if (std::getenv("IMSCAL_SANITIZED")) GTEST_SKIP() << "slow under the sanitizers";
  const std::filesystem::path shipped = sim::resolve_scenario("deviating-identification");
  std::string yaml = test_support::read_text(shipped);
  // The copy lives elsewhere: its paths (../robots/...) made absolute.
  const std::string datasets = shipped.parent_path().parent_path().string() + "/";
  for (std::size_t at = yaml.find("../"); at != std::string::npos; at = yaml.find("../", at))
    yaml.replace(at, 3, datasets);
  const auto replace = [&yaml](const std::string& from, const std::string& to) {
    const std::size_t at = yaml.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    yaml.replace(at, from.size(), to);
  };
  const std::string shapes =
      "transmission_error_shapes: [{amplitude_arcsec: 15, harmonic_per_motor_rev: 2, phase_deg: "
      "40}, {amplitude_arcsec: 15, harmonic_per_motor_rev: 3.5, phase_deg: 100}]";
  replace("  A1: {backlash: false}",
          "  A1: {backlash: false}\n  A2: {" + shapes + "}\n  A3: {" + shapes + "}");
  const std::filesystem::path file =
      std::filesystem::temp_directory_path() / "imscal-two-order-identification.yaml";
  std::ofstream(file) << yaml;
  const sim::Scenario scenario = sim::load_scenario(file);
  std::filesystem::remove(file);
  const ident::JointErrorLog log = simulate_truth_joint_errors(scenario);
  const ident::IdentificationConfig config =
      ident::load_identification_config(ConfigNode::load_file(kDefaultConfig));
  const ModelTorqueSource model = scenario_model_torque(scenario);
  const TransmissionErrorOrderSearch search =
      search_transmission_error_orders(log, config, {1.0, 2.0, 3.5, 4.0}, &model, true);
  ASSERT_EQ(search.second_harmonic.size(), 6u);
  for (std::size_t j = 0; j < 3; ++j)
    fmt::print("{}: {}\n", log.joint_names[j], describe_order_search(search, j));
  EXPECT_EQ(search.chosen_harmonic[0], 2.0);
  EXPECT_EQ(search.second_harmonic[0], 0.0) << "A1 has one order";
  for (std::size_t j = 1; j < 3; ++j) {
    SCOPED_TRACE(log.joint_names[j]);
    const std::pair<double, double> found{
        std::min(search.chosen_harmonic[j], search.second_harmonic[j]),
        std::max(search.chosen_harmonic[j], search.second_harmonic[j])};
    EXPECT_EQ(found, (std::pair<double, double>{2.0, 3.5}));
    EXPECT_LT(search.second_bic[j], 0.0);
  }
  ASSERT_TRUE(search.second_harmonic_used);
  const ident::IdentificationConfig searched = with_searched_orders(config, search);
  EXPECT_EQ(searched.joint_options(1).transmission_error_2_rad_per_rad,
            search.second_harmonic[1] * 160.0);
  EXPECT_FALSE(searched.joint_options(0).second_transmission_error_input);

  // The table: A1's cells carry the pair as two zero coefficients (and a zero phase rate), and
  // their other coefficients are those of A1 identified without the pair, bit for bit.
  const IdentifiedTable with_pair = identify_table(log, searched, "two orders", &model);
  ident::IdentificationConfig without = searched;
  without.options.second_transmission_error_input = false;
  const IdentifiedTable alone = identify_table(log, without, "one order", &model);
  const ident::JointParameters& a1 = with_pair.table.joints[0];
  EXPECT_EQ(a1.transmission_error_2_rad_per_rad, 0.0);
  ASSERT_EQ(a1.cells.size(), alone.table.joints[0].cells.size());
  for (std::size_t c = 0; c < a1.cells.size(); ++c) {
    const ident::CellParameters& padded = a1.cells[c];
    const ident::CellParameters& plain = alone.table.joints[0].cells[c];
    ASSERT_EQ(padded.c.size(), plain.c.size() + 2);
    EXPECT_EQ(padded.c[padded.c.size() - 1], 0.0);
    EXPECT_EQ(padded.c[padded.c.size() - 2], 0.0);
    EXPECT_TRUE(std::equal(plain.c.begin(), plain.c.end(), padded.c.begin()));
    EXPECT_EQ(padded.a, plain.a);
    EXPECT_EQ(padded.b, plain.b);
  }
  // It round-trips through parameters.json, A2's second phase rate and A1's zeros with it.
  const ident::ParameterTable read =
      ident::parse_parameters_json(ident::parameters_json_text(with_pair.table), "round trip");
  EXPECT_EQ(read.joints[0].cells[0].c, a1.cells[0].c);
  EXPECT_EQ(read.joints[0].transmission_error_2_rad_per_rad, 0.0);
  EXPECT_EQ(read.joints[1].transmission_error_2_rad_per_rad,
            with_pair.table.joints[1].transmission_error_2_rad_per_rad);
}

TEST(TransmissionErrorOrder, RefusesAConfigWithoutTheTransmissionError) {
  ident::IdentificationConfig config =
      ident::load_identification_config(ConfigNode::load_file(kDefaultConfig));
  config.options.transmission_error_input = false;
  EXPECT_THROW(search_transmission_error_orders(ident::JointErrorLog{}, config, {1.0}),
               std::invalid_argument);
}

}  // namespace
}  // namespace imscal::eval
