#pragma once
// The gears' transmission-error orders found by order tracking, as in rotating machinery: each
// joint's error Δq = q_desired - q_measured resampled onto the motor angle θ = gear ratio x
// q_desired over the stretches where that motor turns one way at a steady speed, cut into
// windows of 8 motor revolutions, each window detrended (a quadratic in θ: the slow joint error
// of gravity, friction and the path) and Hann-weighted in θ, and its amplitude taken at every
// order on a quarter-order grid. A gear's error is a fixed function of the motor angle, so it
// stands out at its orders in every window, whatever the joint speed; the rest of the joint
// error (the loop's and the gear mode's response to the path, the measurement's noise) is tied
// to time, not to the motor angle, and spreads over the orders as the speed changes between
// windows. The Hann window's first nulls fall on the neighbouring quarter orders at 8
// revolutions, so a strong order does not raise its own floor.
// An order (a multiple of 0.5 up to 4) is significant where three things hold, each against the
// floor of its neighbouring quarter orders: its mean power exceeds the floor by more than
// min_significance σ of a noise-only floor (χ² with two degrees of freedom per window: σ =
// floor / sqrt(windows)); its amplitude is min_amplitude_ratio times the floor's; and the
// excess is consistent over the windows (its t statistic above min_t_statistic: a joint error
// of the path that happens to fall at the order in a few windows is not). The thresholds were set
// on the development plants 1000-1014 against their drawn orders (docs/decisions/0053).
// References: [Randall2011] (order tracking, ch. 3), [Harris1978] (the Hann window).
#include <cstddef>
#include <string>
#include <vector>

#include "ident/joint_error_io.hpp"

namespace imscal::eval {

struct OrderSpectrumOptions {
  double window_motor_revs = 8.0;      // each window's span [motor revolutions]
  double min_motor_speed_rev_s = 2.0;  // steady: the motor turns at least this fast, one way
  double max_speed_change = 0.5;       // within a window, of its first speed
  double order_step = 0.25;            // the spectrum's grid [per motor revolution]
  double max_order = 4.5;              // the grid's last order
  double min_significance = 4.0;       // [σ above the neighbouring orders' floor]
  double min_amplitude_ratio = 2.0;    // and an amplitude this many times the floor's
  double min_t_statistic = 2.5;        // and an excess this consistent over the windows
  double max_candidate = 4.0;          // the orders kept: multiples of 0.5 up to this
};

// One order of a joint's spectrum.
struct OrderLine {
  double order = 0.0;               // per motor revolution
  double amplitude_rad = 0.0;       // sqrt of the windows' mean power: the error's amplitude [rad]
  double floor_rad = 0.0;           // sqrt of the neighbouring orders' mean power [rad]
  double t_statistic = 0.0;         // the windows' mean excess of power over the floor / its σ
  double significance_sigma = 0.0;  // (power - floor) / (floor / sqrt(windows))
};

struct JointOrderSpectrum {
  std::size_t windows = 0;
  std::vector<OrderLine> lines;  // every grid order (0.25 .. max_order)
  // The significant orders (above), the strongest (by amplitude) first.
  std::vector<OrderLine> significant;
};

// Per joint of the log; gear_ratio per joint (a joint without one, or with fewer windows than 2,
// has an empty spectrum). Throws std::invalid_argument for options out of range.
std::vector<JointOrderSpectrum> transmission_error_order_spectra(
    const ident::JointErrorLog& log, const std::vector<double>& gear_ratio,
    const OrderSpectrumOptions& options = {});

// The significant orders of one joint in a line: order, amplitude [″] and significance [σ].
std::string describe_order_spectrum(const JointOrderSpectrum& spectrum);

}  // namespace imscal::eval
