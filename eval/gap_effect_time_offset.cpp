// Time offset of one joint: [q̇_d]; the parameter is the offset dt [s] between the streams.
#include "eval/gap_effect_shapes.hpp"

namespace imscal::eval {
namespace {

std::vector<CandidateShape> shapes(const ShapeContext& x) {
  return {x.local("qd_d * dt", {x.qd}, {"dt_s"})};
}

}  // namespace

const EffectDefinition kTimeOffsetEffect{
    .kind = EffectKind::kTimeOffset,
    .name = "time_offset",
    .acts_through_dynamics = false,
    .what_to_measure = "sharp starts and stops with both streams stamped by one clock",
    .shapes = shapes,
    .size_in_words = size_in_seconds,
};

}  // namespace imscal::eval
