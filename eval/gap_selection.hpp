#pragma once
// The joint model of the gap diagnosis (eval/gap_diagnosis.hpp): which candidates, fitted
// together, explain the gap. Forward-backward selection on the held-out rows, every model refitted
// jointly (one stacked LS over the joints the chosen candidates act on, each candidate within its
// physical bound, eval/gap_bounds.hpp):
//
//   start     the candidate ranked first (the verdict names it, so the model holds it)
//   forward   add the pool member whose joint refit shrinks the held-out gap most, less 0.5 pp per
//             own parameter (the per-joint ranking's parsimony charge); kept when its further
//             held-out gain is significant (block bootstrap, p < alpha) and adds at
//             least min_combination_gain_percent of the whole gap or min_shrinkage_percent of its
//             own joint's remaining gap with at least 0.5 pp of the whole (an effect on a joint
//             with a small share of the whole gap is still a cause of its own); of the trials on
//             its joint nested in it (an offset in a drift) that it does not improve on
//             significantly by the same rule, and that add significantly themselves, the one with
//             the fewest own parameters is added instead
//   backward  after each addition, drop a member (not the first) whose loss, with the others
//             refitted without it, is no longer significant by the same rule
//
// The pool: every candidate; per forward step the five whose own columns best explain the model's
// residual are fitted again to that residual (shape and size: an effect hidden behind a larger one,
// whose fit to the whole gap explains nothing of it) and refitted jointly. After each addition the
// candidates tried before compete again against the grown model's residual; those the backward
// step dropped stay out. The predicted shrinkage is the final joint refit's held-out one.
#include <cstdint>
#include <vector>

#include "eval/gap_diagnosis.hpp"

namespace imscal::eval {

struct JointModel {
  std::vector<CombinationStep> steps;  // in the order added, the first candidate first
  double heldout_energy = 0.0;         // of the final joint refit's residual [rad²]
};

JointModel select_joint_model(const GapSignals& signals, const DiagnosisOptions& options,
                              const std::vector<CandidateResult>& candidates,
                              const std::vector<bool>& training,
                              const std::vector<std::size_t>& heldout, std::size_t block,
                              std::uint64_t& seed);

}  // namespace imscal::eval
