// identification_report.json's friction levels: written and read back field by field (a joint
// not estimated keeps its reason and the nominal values, its levels null), and refused with the
// field's path when a field is of another type.
#include <gtest/gtest.h>

#include <cmath>

#include "core/input_error.hpp"
#include "ident/friction_levels_report.hpp"

namespace imscal::ident {
namespace {

std::vector<JointFrictionLevels> two_joints() {
  JointFrictionLevels a;
  a.estimated = true;
  a.coulomb_nm = {48.5, 1.25, 50.0};
  a.viscous_nm_s_per_rad = {61.0, 2.5, 60.0};
  a.reflected_inertia_kg_m2 = {9.5, 0.5, 10.24};
  a.rows = 12345;
  a.dead_time_cycles = 2;
  a.torque_rms_nm = 210.0;
  a.torque_fit_percent = 91.5;
  a.correlation_factor = 40.0;
  JointFrictionLevels b;
  b.not_estimated = "the model torque is too small against the friction to fix the scale";
  b.coulomb_nm = {0.3, 0.1, 5.0};  // not estimated: written as null
  b.viscous_nm_s_per_rad.nominal = 3.0;
  b.reflected_inertia_kg_m2.nominal = 0.336;
  return {a, b};
}

TEST(FrictionLevelsReport, RoundTrip) {
  const nlohmann::json doc = friction_levels_json(two_joints(), {"A1", "A6"});
  const std::string file = "report.json";
  const JsonField root(&file, &doc, "friction_levels");
  const auto read = friction_levels_of(root);
  ASSERT_EQ(read.size(), 2u);
  EXPECT_EQ(read[0].name, "A1");
  EXPECT_TRUE(read[0].levels.estimated);
  EXPECT_EQ(read[0].levels.coulomb_nm.value, 48.5);
  EXPECT_EQ(read[0].levels.coulomb_nm.sigma, 1.25);
  EXPECT_EQ(read[0].levels.coulomb_nm.nominal, 50.0);
  EXPECT_EQ(read[0].levels.viscous_nm_s_per_rad.value, 61.0);
  EXPECT_EQ(read[0].levels.reflected_inertia_kg_m2.nominal, 10.24);
  EXPECT_EQ(read[0].levels.rows, 12345u);
  EXPECT_EQ(read[0].levels.dead_time_cycles, 2);
  EXPECT_EQ(read[0].levels.torque_fit_percent, 91.5);
  EXPECT_FALSE(read[1].levels.estimated);
  EXPECT_EQ(read[1].levels.not_estimated, two_joints()[1].not_estimated);
  EXPECT_TRUE(std::isnan(read[1].levels.coulomb_nm.value));
  EXPECT_EQ(read[1].levels.coulomb_nm.nominal, 5.0);
}

TEST(FrictionLevelsReport, RefusesAFieldOfAnotherType) {
  nlohmann::json doc = friction_levels_json(two_joints(), {"A1", "A6"});
  doc["joints"][0]["estimated"] = "yes";
  const std::string file = "report.json";
  try {
    friction_levels_of(JsonField(&file, &doc, "friction_levels"));
    FAIL() << "a text for a boolean was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("joints[0].estimated"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace imscal::ident
