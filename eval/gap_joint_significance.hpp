#pragma once
// Significance of the gap per joint: a gap concentrated in one joint, far above that joint's
// noise, is a significant structured gap even when no candidate carries over from the training
// to the held-out blocks (a record too short for that, or an effect outside the library) and even
// when it is a small share of nothing else. Two routes, either suffices:
//
//  * by candidate: the joint's leading candidate (eval/gap_diagnosis.hpp JointFinding) shrinks
//    that joint's held-out gap by at least min_shrinkage_percent with a block-bootstrap p-value
//    below the Šidák level over the J joints, alpha_J = 1 - (1 - alpha)^(1/J) (each joint is a
//    test of its own; the family-wise level stays alpha). The bootstrap is rerun with enough
//    resamples that its floor 1 / (resamples + 1) lies well below alpha_J.
//  * far above the noise: the joint's gap RMS is at least far_above_noise_factor times its noise
//    reference, the larger of
//      - its own high-frequency floor: sigma = 1.4826 median|Δ²g| / sqrt(6) (white noise of
//        sigma has var(Δ²g) = 6 sigma²; the median keeps the few large second differences of a
//        structured gap's jumps out), and
//      - the median of the other joints' gap RMS (the measurement's noise reaches every joint at
//        a like level; a gap spread over all joints, like an error of the IMS chain, is then no
//        joint's own).
//    Coloured noise raises the ratio to its own high-frequency floor (a first-order 50 ms noise
//    at 2 ms: ~6), never to that of the other joints: the factor 10 leaves margin for both.
//
// References (docs/references.md): [Sidak1967] (the per-joint level), [Kunsch1989] (bootstrap).
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace imscal::eval {

struct JointSignificance {
  std::size_t joint = 0;
  double rms_rad = 0.0;                   // the joint's gap, whole record
  double noise_floor_rad = 0.0;           // its high-frequency floor (above)
  double noise_reference_rad = 0.0;       // max(floor, median of the other joints' gap RMS)
  double excess = 0.0;                    // rms / noise reference
  double corrected_alpha = 0.0;           // Šidák level of each joint's test
  double leader_p_value = 1.0;            // of the leading candidate's own-joint gain (1: none)
  double leader_shrinkage_percent = 0.0;  // its held-out shrinkage of the joint's gap
  bool by_candidate = false;
  bool far_above_noise = false;
  bool significant() const { return by_candidate || far_above_noise; }
};

// Robust white-noise level of a signal from its second differences inside each run [its unit];
// 0 when no run has three samples.
double high_frequency_noise_floor(const std::vector<double>& x,
                                  const std::vector<std::pair<std::size_t, std::size_t>>& runs);

// Šidák level of one of `tests` tests at family-wise level alpha.
double sidak_alpha(double alpha, std::size_t tests);

}  // namespace imscal::eval
