// The gap effects' registry (eval/gap_effects.hpp): one definition per kind, in the order of
// EffectKind, each complete, the names unique (report.json names effects by them).
#include <gtest/gtest.h>

#include <set>
#include <string>

#include "eval/gap_effects.hpp"

namespace imscal::eval {
namespace {

TEST(GapEffects, RegistryHoldsOneCompleteDefinitionPerKindInOrder) {
  std::set<std::string> names;
  for (int i = 0; i < kEffectKindCount; ++i) {
    const EffectKind kind = effect_kind_from_index(i);
    ASSERT_NE(kEffectDefinitions[std::size_t(i)], nullptr) << "registry row " << i << " missing";
    const EffectDefinition& d = effect_definition(kind);
    EXPECT_EQ(d.kind, kind) << "registry row " << i;
    ASSERT_NE(d.name, nullptr);
    EXPECT_TRUE(names.insert(d.name).second) << "name used twice: " << d.name;
    EXPECT_STREQ(to_string(kind), d.name);
    ASSERT_NE(d.what_to_measure, nullptr);
    EXPECT_GT(std::string(d.what_to_measure).size(), 20u) << d.name;
    EXPECT_NE(d.shapes, nullptr) << d.name;
    if (d.nominal) {
      EXPECT_GT(d.nominal->parameter_count, 0) << d.name;
      EXPECT_NE(d.nominal->applies, nullptr) << d.name;
      EXPECT_NE(d.nominal->typical_value, nullptr) << d.name;
      EXPECT_NE(d.nominal->apply, nullptr) << d.name;
      EXPECT_NE(d.nominal->describe, nullptr) << d.name;
      // A parameter of the nominal model changes the simulated link: it acts through dynamics.
      EXPECT_TRUE(d.acts_through_dynamics) << d.name;
    }
  }
  EXPECT_THROW(effect_kind_from_index(kEffectKindCount), std::invalid_argument);
}

}  // namespace
}  // namespace imscal::eval
