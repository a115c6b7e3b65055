#pragma once
// The shape of a candidate effect on a joint (eval/gap_candidates.hpp) chosen by the 2-fold
// validation inside the training rows (eval/gap_validation.hpp): of the shapes within 1 % of the
// best validation error, the one with the fewest parameters (the only shape when there is one).
// An effect with a grid of shapes (EffectDefinition::shape_at) is validated one shape at a time,
// and only the chosen one is built again: its grid is never held at once.
#include <cstddef>
#include <optional>
#include <vector>

#include "eval/gap_candidates.hpp"
#include "eval/gap_validation.hpp"

namespace imscal::eval {

// nullopt when the candidate does not apply on `joint` (no shapes).
std::optional<CandidateShape> chosen_shape(EffectKind kind, const GapSignals& signals,
                                           std::size_t joint, const std::vector<bool>& training,
                                           const TrainingFolds& folds);

}  // namespace imscal::eval
