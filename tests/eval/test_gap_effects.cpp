// The gap effects' registry (eval/gap_effects.hpp): one definition per kind, in the order of
// EffectKind, each complete, the names unique (report.json names effects by them); a grid of
// shapes built one at a time gives the shapes built all at once.
#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <string>

#include "eval/gap_candidates.hpp"
#include "eval/gap_effect_shapes.hpp"
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
    // A grid of shapes one at a time: its count and its i-th shape, both or neither.
    EXPECT_EQ(d.shape_count == nullptr, d.shape_at == nullptr) << d.name;
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

TEST(GapEffects, ShapesOneAtATimeAreTheShapesAllAtOnce) {
  // The validation builds a grid's shapes one at a time (eval/gap_shape_choice.hpp): the i-th must
  // be the i-th of `shapes`, bit for bit, or the chosen shape would depend on the path.
  GapSignals s;
  s.cycle_s = 0.002;
  const std::size_t n = 600;
  s.runs = {{0, 250}, {250, n}};
  s.joint_names = {"A1"};
  std::vector<double> zeros(n, 0.0), qd(n), qdd(n);
  for (std::size_t k = 0; k < n; ++k) {
    s.time_s.push_back(double(k) * s.cycle_s);
    qd[k] = std::sin(0.02 * double(k));
    qdd[k] = std::cos(0.07 * double(k));
  }
  s.qd_desired_rad_s = {qd};
  s.qdd_desired_rad_s2 = {qdd};
  s.torque_nm = {zeros};
  s.gap_rad = {zeros};
  for (const EffectDefinition* d : kEffectDefinitions) {
    if (!d->shape_at) continue;
    const ShapeContext x(s, 0, nullptr);
    const std::vector<CandidateShape> all = d->shapes(x);
    ASSERT_EQ(all.size(), d->shape_count(x)) << d->name;
    for (std::size_t i = 0; i < all.size(); ++i) {
      const CandidateShape one = d->shape_at(x, i);
      EXPECT_EQ(one.label, all[i].label) << d->name << " " << i;
      EXPECT_EQ(one.parameter_names, all[i].parameter_names) << d->name << " " << i;
      ASSERT_EQ(one.columns.size(), all[i].columns.size());
      for (std::size_t j = 0; j < one.columns.size(); ++j)
        EXPECT_EQ(one.columns[j], all[i].columns[j]) << d->name << " " << i;
    }
  }
}

}  // namespace
}  // namespace imscal::eval
