#pragma once
// Coarse alignment at rest: the attitude R_W_S of a resting IMS from its own data, levelling by
// the accelerometers and heading by gyrocompassing (the gyros must sense the Earth rate, e.g.
// ring-laser gyros), each angle with its 1-sigma from the scatter of the data.
//
// Method (inertial-frame gyrocompassing, robust to short disturbances). A plain average of rates
// and specific forces over the interval is wrecked by the small permanent tilts a "resting"
// vehicle or robot takes during disturbances: a 1 mrad tilt step inside a 300 s window shifts the
// mean rate by 3.3e-6 rad/s, i.e. ~3 deg of heading at 12.5 deg/h horizontal Earth rate (this is
// what the PSINS record tests/data/real/rlg-static shows: 83..92 deg from 5-min plain means).
// Instead:
//  1. the gyro increments are integrated into the attitude of S relative to a non-rotating frame
//     m (= S at the reference time t_ref, the sample nearest the middle of the interval), and the
//     velocity increments are rotated into m and summed per block (the interval is cut into
//     `block_count` equal blocks): F_k = block-mean specific force in m. Every rotation of the
//     body, disturbance or not, is thus tracked by the gyros and drops out.
//  2. At rest, W turns in m with the Earth rate omega_m (a constant vector in m), so
//     F(t) = exp((t - t_ref) [omega_m x]) f_ref. omega_m is found by Gauss-Newton: de-rotate
//     the F_k with the current omega_m, fit a straight line F = f_ref + s (t - t_ref) per axis
//     (least squares over the blocks), and correct the horizontal part of omega_m by
//     f_ref x s / |f_ref|^2. The part along the plumb line is fixed to the EarthModel's
//     (~Omega sin(lat)): it does not turn f and so cannot be measured this way.
//  3. R_W_S at t_ref (S = m at t_ref) by TRIAD: f_ref matched to the model's f_W = -g_W (the
//     primary vector: levelling), omega_m to omega_ie_W (the secondary: heading).
//  4. Blocks whose residual exceeds `outlier_factor` times the median residual (linear
//     accelerations of a disturbance that did not average out) are dropped and the fit redone.
// Uncertainty: per axis, the residuals of the block fit are modelled as white noise (accelerometer
// noise, residual sway) plus a random walk anchored at t_ref (gyro angle random walk turning
// f into the horizontal); the ratio of the two is chosen by restricted maximum likelihood on
// the residuals, the walk kept only if a likelihood-ratio test finds it (99 %). The resulting
// covariance of the line parameters (f_ref, s) is propagated to the
// angles through the numerical Jacobian of step 3 (full linearised propagation), so correlated
// noise is not counted as independent. Not included: accelerometer biases and horizontal gyro
// biases, which a static record cannot separate from tilt and heading. Measured calibration
// (tests/ims/test_coarse_alignment.cpp, 200 draws): reported sigma / observed scatter 0.77..0.83
// for gyro white noise alone (REML underrates a pure walk a little), 1.00..1.04 for accelerometer
// noise alone, 0.92..0.96 for both. On the real RLG record the heading sigma of 300 s windows is
// ~6x the spread of the window headings: residual sway makes block means anticorrelated, which
// the white part overrates (conservative).
//
// Angles (sensor axes X right, Y forward, Z up, as in PSINS files; W = ENU):
//   R_W_S = Rz(yaw) * Rx(pitch) * Ry(roll)
//   yaw     : PSINS yaw, counter-clockwise from North of the Y axis, in (-pi, pi]
//   heading : clockwise from North of the Y (forward) axis = -yaw, in [0, 2 pi)
//   pitch   : elevation of the Y axis above the horizontal (nose up > 0), in [-pi/2, pi/2]
//   roll    : rotation about Y; > 0 when the X (right) axis points below the horizontal.
//
// References (docs/references.md): [Groves2013] (levelling, gyrocompassing), [Shuster1981] (TRIAD).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <vector>

#include "ims/earth_model.hpp"
#include "ims/imu_data.hpp"

namespace imscal::ims {

struct AttitudeAngles {
  double roll_rad = 0.0;
  double pitch_rad = 0.0;
  double heading_rad = 0.0;  // clockwise from North of +Y, [0, 2 pi)
  double yaw_rad = 0.0;      // counter-clockwise from North of +Y (PSINS), (-pi, pi]
};

AttitudeAngles attitude_angles(const Eigen::Matrix3d& R_W_S);
// R_W_S from PSINS-style angles [rad] (yaw counter-clockwise from North).
Eigen::Matrix3d R_W_S_from_angles(double roll_rad, double pitch_rad, double yaw_rad);

struct CoarseAlignmentOptions {
  // Blocks the interval is cut into (>= 8); 64 give the noise model enough residuals to tell a
  // random walk from white noise (with 16 the gyro-noise sigma came out ~25 % low).
  int block_count = 64;
  double outlier_factor = 6.0;  // drop blocks whose residual norm exceeds this x the median
  int max_iterations = 20;      // Gauss-Newton iterations for the Earth-rate direction
};

struct CoarseAlignment {
  double t_ref_s = 0.0;  // the attitude holds at this time (sample nearest the interval middle)
  double start_s = 0.0;  // interval covered: (start_s, end_s]
  double end_s = 0.0;
  std::size_t first_sample = 0;
  std::size_t sample_count = 0;

  Eigen::Quaterniond q_W_S = Eigen::Quaterniond::Identity();
  AttitudeAngles angles;
  Eigen::Matrix3d angle_covariance = Eigen::Matrix3d::Zero();  // (roll, pitch, heading) [rad^2]
  double sigma_roll_rad = 0.0;
  double sigma_pitch_rad = 0.0;
  double sigma_heading_rad = 0.0;

  // Quality figures: measured against what the EarthModel expects at the site.
  double specific_force_m_s2 = 0.0;  // |f_ref|
  double expected_gravity_m_s2 = 0.0;
  double earth_rate_horizontal_rad_s = 0.0;  // |horizontal omega| found by gyrocompassing
  double expected_earth_rate_horizontal_rad_s = 0.0;
  int blocks_used = 0;
  int blocks_rejected = 0;
  double block_duration_s = 0.0;
  int iterations = 0;
};

struct SampleRange {
  std::size_t first = 0;
  std::size_t count = 0;
};

// The samples whose interval (t - dt, t] lies in [start_s, start_s + duration_s] (file time).
SampleRange samples_in_interval(const ImuSeries& series, double start_s, double duration_s);

// Aligns on samples [first, first + count) of a series of increments or rates taken at rest.
// Throws std::invalid_argument if the range is too short for `block_count` blocks, the site is
// within 1 deg of a pole (no horizontal Earth rate), or the data are degenerate.
CoarseAlignment align_at_rest(const ImuSeries& series, SampleRange range, const EarthModel& earth,
                              const CoarseAlignmentOptions& options = {});

// Disjoint consecutive windows of window_s inside range (a shorter remainder is left out).
std::vector<CoarseAlignment> align_windows(const ImuSeries& series, SampleRange range,
                                           double window_s, const EarthModel& earth,
                                           const CoarseAlignmentOptions& options = {});

// Mean, standard deviation (n - 1) and extremes of one angle over windows; the heading is
// unwrapped around the first window so that 359.9 and 0.1 deg count as 0.2 deg apart.
struct AngleSpread {
  double mean_rad = 0.0;
  double std_rad = 0.0;
  double min_rad = 0.0;
  double max_rad = 0.0;
};
enum class AngleKind { kRoll, kPitch, kHeading };
AngleSpread angle_spread(const std::vector<CoarseAlignment>& windows, AngleKind kind);

}  // namespace imscal::ims
