#pragma once
// Backlash of one joint (paper, equation 3): the joint error has a part that depends only on the
// direction of motion,
//
//   Δq^bl(k) = +l  while the joint moves in + direction,   -l  while it moves in - direction,
//
// so l is half the full play of the gear (the error jumps by 2 l at a direction reversal).
//
// Identification from direction reversals:
//  1. The direction s(k) ∈ {-1, 0, +1} is the sign of the desired velocity q̇_d(k - L), held
//     while |q̇_d| is below min_speed (at rest the play stays where it was; 0 before the first
//     move). L is the lag of the joint behind its desired angle, found as the shift that
//     maximises the correlation of the desired and measured velocities (the play reverses when
//     the joint does, not when the command does).
//  2. Around every reversal, in a window before it and a window after the play has been
//     crossed (settle time), the joint error Δq = q_d - q_m is fitted by least squares as
//     c0 + c1 q̇_d + l_r s: near a reversal the linear (following-error) part of Δq is close to
//     affine in the velocity, while the backlash part flips sign. Both windows are thus at a
//     comparable operating point (same place, low speed, the same acceleration).
//     A reversal whose direction column s is (nearly) in the span of [1, q̇_d, q̈_d] inside its
//     windows is skipped: there l_r is not determined and the rank-revealing solve returns an
//     arbitrary (once 7e3 rad) value. The share of s orthogonal to the other columns must be at
//     least min_direction_independence; a per-reversal l_r beyond max_l_rad is skipped too (a
//     gear play is a few mrad; such a value is a fit of something else).
//  3. l = mean of the per-reversal l_r, 1σ = their standard deviation / √(count): the scatter
//     between reversals is an honest measure of what the noise and the unmodelled dynamics do
//     to the estimate (residuals inside one window are strongly correlated, so the regression's
//     own σ would be far too small).
// The linear ARX model is then fitted to q_m + l s(k) (the joint angle without the backlash).
//
// References (docs/references.md): [Paper] (eq. 3).
#include <cstddef>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace imscal::ident {

struct BacklashOptions {
  double min_speed_rad_s = 1e-3;  // below this the direction is held
  double max_lag_s = 0.5;         // longest lag of the joint behind the command that is searched
  double settle_s = 0.05;         // after a reversal (+ lag): time to cross the play and settle
  double window_s = 0.15;         // length of the fit window on each side
  int min_reversals = 3;          // fewer: backlash not identified (l = 0, reason given)
  // Per reversal: |s - P s| / |s| with P the projection on [1, q̇_d, q̈_d] (scaled columns);
  // below it the reversal does not determine l and is skipped.
  double min_direction_independence = 0.2;
  // Largest plausible half play [rad] (20 mrad = 1.1 deg, ten times an industrial gear's play):
  // a per-reversal estimate beyond it is skipped (counted), so |l| <= max_l_rad.
  double max_l_rad = 0.02;
};

struct BacklashEstimate {
  bool identified = false;
  double l_rad = 0.0;        // paper's l_i (half the full play)
  double l_sigma_rad = 0.0;  // 1σ of l_rad
  int reversals_used = 0;
  int reversals_found = 0;
  int reversals_ill_conditioned = 0;  // skipped: s nearly in the span of [1, q̇_d, q̈_d]
  int reversals_implausible = 0;      // skipped: |l_r| > max_l_rad
  std::size_t lag_samples = 0;        // L
  std::vector<double> per_reversal_rad;
  std::string reason;  // why not identified (empty when identified)
};

using SampleRanges = std::span<const std::pair<std::size_t, std::size_t>>;

// Lag of q_measured behind q_desired in samples (velocity cross-correlation, 0..max_lag).
std::size_t joint_lag_samples(std::span<const double> q_desired, std::span<const double> q_measured,
                              SampleRanges segments, std::size_t max_lag);

// s(k) of step 1 with a given lag.
std::vector<double> motion_direction(std::span<const double> q_desired, SampleRanges segments,
                                     double cycle_s, double min_speed_rad_s, std::size_t lag);

BacklashEstimate identify_backlash(std::span<const double> q_desired,
                                   std::span<const double> q_measured, SampleRanges segments,
                                   double cycle_s, const BacklashOptions& options = {});

}  // namespace imscal::ident
