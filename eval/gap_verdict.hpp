#pragma once
// The gap diagnosis in plain words: where the gap lies, the most likely cause with its
// size (and the causes the data cannot tell apart from it), the expected gap once modelled, the
// leading cause per joint, and what to measure next when the evidence is weak or ambiguous.
#include "eval/gap_diagnosis.hpp"

namespace imscal::eval {

// Fills diagnosis.verdict and diagnosis.measure_next from the rest of the diagnosis.
void write_verdict(const GapSignals& signals, const DiagnosisOptions& options,
                   Diagnosis& diagnosis);

// A candidate in words: "backlash on joint A2 (held on one flank ...; half play ...)".
std::string candidate_in_words(const GapSignals& signals, const CandidateFit& fit);

}  // namespace imscal::eval
