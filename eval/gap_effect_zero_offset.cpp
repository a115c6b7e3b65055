// Zero offset of a joint: [1].
#include "eval/gap_effect_shapes.hpp"

namespace imscal::eval {
namespace {

std::vector<CandidateShape> shapes(const ShapeContext& x) {
  return {x.local("constant", {Column::Ones(x.n)}, {"offset_rad"})};
}

}  // namespace

const EffectDefinition kZeroOffsetEffect{
    .kind = EffectKind::kZeroOffset,
    .name = "zero_offset",
    .acts_through_dynamics = false,
    .what_to_measure = "static poses of the joint (a constant error does not depend on the motion)",
    .shapes = shapes,
};

}  // namespace imscal::eval
