#pragma once
// Where the sim-to-real gap lies ("where"): shares of the gap energy (sum of g² over
// samples, rad²) by joint, by path segment kind, by frequency band, by operating-point cell and
// by direction of motion. Shares are fractions of the total (or of the joint's) gap energy; each
// grouping also gives the fraction of time, so a share well above its time fraction points at
// where the gap comes from.
//
// References (docs/references.md): [Welch1967] (power spectral density).
#include <cstddef>
#include <string>
#include <vector>

#include "eval/gap_signals.hpp"

namespace imscal::eval {

enum class MotionPhase { kRest, kAcceleration, kConstantVelocity, kDeceleration, kReversal };
inline constexpr int kMotionPhaseCount = 5;
const char* to_string(MotionPhase phase);

struct GapShare {
  std::string label;
  double energy_share = 0.0;              // of the joint's (or total) gap energy, 0..1
  double time_share = 0.0;                // fraction of the samples, 0..1
  double rms_rad = 0.0;                   // gap RMS within the group (0 when empty)
  bool outside_identified_range = false;  // operating-point cells only
};

struct JointGapAnalysis {
  std::string joint;
  double rms_rad = 0.0;
  double energy_share = 0.0;           // of the total over all joints
  std::vector<GapShare> by_phase;      // kMotionPhaseCount entries
  std::vector<GapShare> by_band;       // frequency bands (Welch spectrum)
  std::vector<GapShare> by_cell;       // operating-point cells
  std::vector<GapShare> by_direction;  // "+", "-", "rest"
  double direction_offset_rad = 0.0;   // mean gap moving + minus mean gap moving -, halved
};

struct GapAnalysis {
  double rms_rad = 0.0;  // over all joints and samples: sqrt(mean over samples of sum_j g_j²)
  std::vector<JointGapAnalysis> joints;
  std::vector<double> band_edges_hz;  // band i = [edges[i], edges[i+1])
};

// Phase of every sample of a joint from its desired velocity and acceleration: rest below 0.5 %
// of the joint's top speed (and no acceleration), reversal within 0.1 s of a sign change of the
// velocity while moving, otherwise acceleration / deceleration / constant velocity from the sign
// of v·a (constant when |a| is below 2 % of the joint's peak acceleration).
std::vector<MotionPhase> motion_phases(const GapSignals& signals, std::size_t joint);

// One-sided Welch power spectral density of x (Hann windows of `window` samples, 50 % overlap,
// each run separately): frequencies [Hz] and density [rad²/Hz].
struct Spectrum {
  std::vector<double> frequency_hz, density;
};
Spectrum welch_spectrum(const std::vector<double>& x,
                        const std::vector<std::pair<std::size_t, std::size_t>>& runs,
                        double cycle_s, std::size_t window = 256);

GapAnalysis analyse_gap(const GapSignals& signals);

}  // namespace imscal::eval
