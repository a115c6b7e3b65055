#pragma once
// The joint model of the gap (eval/gap_selection.hpp) refined on the simulator of the nominal model
// (eval/gap_nominal_plant.hpp): every member whose effect is a parameter of the nominal model is
// fitted from its linearised sensitivity and then refined by re-simulating the nominal model with
// the parameter changed; the other members keep their linear columns (within their bounds,
// eval/gap_bounds.hpp). Gauss-Newton on the training rows, every joint stacked:
//
//   g - m(p) ≈ J Δp + C b      J: forward differences of m at p (one simulation per parameter)
//
// p starts at 0 (the nominal model), so the first step is the linearised fit; a step that does not
// lower the training residual is halved once, then the search stops; at most 4 steps, fewer when a
// step moves every parameter by less than 1 % of its difference step; every size within its
// physical bound. Before that, a member that is an effect of a joint's drive (Coulomb friction,
// backlash, transmission error) stands for whichever of them on its joint the linearised fit
// explains best on the training rows (the linear candidates confuse them); a transmission error is
// tried at the 3 orders h per motor revolution (of 1 to 8 in steps of 0.5) whose raw ripple
// [sin, cos](h N q_internal) best fits its joint's gap less the other members. The refined model
// is applied when its held-out residual is below the linear model's; the predicted shrinkage is
// then the refined model's held-out one.
#include <cstddef>
#include <vector>

#include "eval/gap_candidates.hpp"
#include "eval/gap_nominal_plant.hpp"

namespace imscal::eval {

NominalRefinement refine_on_nominal_plant(const GapSignals& signals, const NominalPlant& plant,
                                          const std::vector<CandidateFit>& members,
                                          const std::vector<bool>& training,
                                          const std::vector<std::size_t>& heldout,
                                          double linear_heldout_energy);

}  // namespace imscal::eval
