#pragma once
// Candidate effects the data cannot tell apart (gap diagnosis). Two candidates are
// ambiguous on a record when their modelled gaps on the held-out rows are the same within a
// tenth of what neither explains:
//
//   RMS(p_a - p_b) <= kAmbiguityFraction * RMS(g - p_a)      (held-out rows, the joints compared)
//
// and the second needs no more parameters than the first (a model that nests the first and
// predicts the same is not a second explanation, only a longer one). Then their held-out
// shrinkages differ by at most ~1 % of the residual energy: no ranking between them means
// anything, and the report names them together with the measurement that would separate them.
// Example: a joint whose gear torque never changes sign holds its link on one flank of the play,
// so its backlash is a constant offset of half the play, exactly a zero offset of the joint
// (eval/gap_candidates.hpp, kOneFlankShape); a path on which that torque reverses separates them.
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "eval/gap_candidates.hpp"

namespace imscal::eval {

inline constexpr double kAmbiguityFraction = 0.1;

struct AmbiguityGroup {
  std::vector<std::size_t> members;  // indices into the ranked list, the group's head first
  double difference_rms_rad = 0.0;   // largest RMS(p_head - p_member) on the held-out rows
  double residual_rms_rad = 0.0;     // RMS(g - p_head) on the held-out rows
  std::string separate_by;           // the measurement that would tell the members apart
};

// The ambiguity groups (two or more members) of ranked candidate fits, compared on all joints
// (joint: nullopt) or on one joint only; only fits flagged in `eligible` take part. A group's head
// is its best-ranked member; every later eligible fit joins the first head it is ambiguous with.
std::vector<AmbiguityGroup> ambiguity_groups(const GapSignals& signals,
                                             const std::vector<const CandidateFit*>& ranked,
                                             const std::vector<bool>& eligible,
                                             const std::vector<std::size_t>& heldout_rows,
                                             std::optional<std::size_t> joint = std::nullopt);

// What to measure to tell two candidates apart (plain words).
std::string separating_measurement(const GapSignals& signals, const CandidateFit& a,
                                   const CandidateFit& b);

// What to measure to pin one candidate down (plain words).
const char* what_to_measure(EffectKind kind);

}  // namespace imscal::eval
