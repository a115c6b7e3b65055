#include "eval/gap_effects.hpp"

#include <stdexcept>

namespace imscal::eval {

const char* to_string(EffectKind kind) {
  return effect_definition(kind).name;
}

EffectKind effect_kind_from_index(int index) {
  if (index < 0 || index >= kEffectKindCount)
    throw std::invalid_argument("effect kind index out of range");
  return static_cast<EffectKind>(index);
}

bool acts_through_dynamics(EffectKind kind) {
  return effect_definition(kind).acts_through_dynamics;
}

}  // namespace imscal::eval
