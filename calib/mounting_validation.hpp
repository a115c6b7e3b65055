#pragma once
// Mounting validation: what the lab checks before a measurement campaign, from the frame-and-bias
// bundle (calib/frame_calibration.hpp):
//  - residuals per rest pose and per motion, with the outliers the bundle flagged;
//  - repeatability of T_S_H between the two halves of the session (the rests split in two, each
//    half calibrated on its own) and between two sessions (two results);
//  - a slipped mount: T_S_H calibrated on consecutive segments of rests (windows of k rests);
//    neighbouring segments that differ beyond n combined sigma AND beyond a floor in deg/mm mean
//    "the mount slipped between rest i and rest j";
//  - with a surveyed heading of the base: the IMS's own heading against it;
//  - a verdict pass / warn / fail with the reasons in plain words.
//
// Differences of T_S_H are taken in the bundle's tangent space: rotation as the small angle of
// R_S_H,a R_S_H,b^T (left frame S) [rad], translation p_S_H,a - p_S_H,b [m]; two estimates from
// disjoint data are independent, so the covariance of the difference is the sum of theirs.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "calib/frame_calibration.hpp"

namespace imscal::calib {

enum class Verdict { kPass = 0, kWarn = 1, kFail = 2 };
const char* to_string(Verdict verdict);  // "pass", "warn", "fail"

struct MountingThresholds {
  // Outliers among the rest and motion blocks: more than max_outliers_pass -> warn; a fraction
  // of all blocks above max_outlier_fraction_warn -> fail.
  std::size_t max_outliers_pass = 0;
  double max_outlier_fraction_warn = 0.2;
  // Repeatability of T_S_H (halves, sessions, segments): the largest component of the
  // difference in units of its combined 1-sigma. A difference counts only when it also exceeds
  // the floors in rad / m (systematic effects outside the covariance, e.g. joint backlash,
  // should not raise alarms at the micro-radian level).
  double repeat_warn_sigma = 3.0;
  double repeat_fail_sigma = 5.0;
  double repeat_rotation_floor_rad = 0.002 * M_PI / 180.0;
  double repeat_translation_floor_m = 0.02e-3;
  // Slip between segments: beyond slip_sigma and beyond the floors above.
  double slip_sigma = 5.0;
  // Precision of the combined T_S_H: a 1-sigma (largest component) above these -> warn.
  double max_rotation_sigma_rad = 0.005 * M_PI / 180.0;
  double max_translation_sigma_m = 0.05e-3;
};

struct MountingValidationOptions {
  MountingThresholds thresholds;
  bool check_halves = true;
  bool check_segments = true;
  std::size_t segment_rests = 5;  // rests per segment (k); a short last segment joins the previous
};

// T_S_H with its 6x6 tangent covariance [rotation (rad) in S; translation (m)].
struct MountingEstimate {
  Eigen::Isometry3d T_S_H = Eigen::Isometry3d::Identity();
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
  bool has_covariance = false;
};

// Reads T_S_H and its covariance block from a result (parameter_names "R_S_H..." / "p_S_H..."
// or "T_S_H.rotation..." / "T_S_H.translation..."; without them, the 1-sigma of the estimates
// named "T_S_H.rotation..." and "T_S_H.translation..." (deg / mm) on the diagonal).
MountingEstimate mounting_estimate(const FrameCalibrationResult& result);

struct MountingDifference {
  double rotation_rad = 0.0;  // angle of R_S_H,a R_S_H,b^T
  double translation_m = 0.0;
  Eigen::Matrix<double, 6, 1> difference = Eigen::Matrix<double, 6, 1>::Zero();
  Eigen::Matrix<double, 6, 1> combined_sigma = Eigen::Matrix<double, 6, 1>::Zero();
  // max_k |difference_k| / combined_sigma_k; infinite when a sigma is missing and the
  // difference is not zero.
  double normalised = 0.0;
  // True when the difference exceeds `sigma_multiple` and one of the floors.
  bool exceeds(double sigma_multiple, const MountingThresholds& t) const;
};

MountingDifference compare_mountings(const MountingEstimate& a, const MountingEstimate& b);

// A part of the session (a half or a segment): rests [first_rest, last_rest] calibrated alone.
struct SessionPart {
  std::string label;  // "first half (rests 1-7)"
  std::size_t first_rest = 0;
  std::size_t last_rest = 0;  // inclusive
  bool calibrated = false;
  std::string failure;  // why not, when not calibrated
  bool converged = false;
  MountingEstimate estimate;
};

struct SegmentComparison {
  std::size_t earlier = 0;  // indices into MountingValidation::segments
  std::size_t later = 0;
  MountingDifference difference;
  bool slipped = false;
};

struct MountingCheck {
  std::string name;  // "convergence", "outliers", "precision", "halves", "slip", ...
  Verdict level = Verdict::kPass;
  std::string message;  // plain words, with the numbers
};

struct MountingValidation {
  Verdict verdict = Verdict::kPass;
  std::vector<std::string> reasons;   // messages of the checks that warn or fail
  std::vector<MountingCheck> checks;  // every check, passed ones included

  MountingEstimate combined;
  std::vector<PoseResidual> rest_residuals;
  std::vector<PoseResidual> motion_residuals;
  std::vector<std::string> outliers;
  std::size_t outlier_count = 0;  // flagged rest + motion blocks

  std::vector<SessionPart> halves;  // empty when not checked
  std::optional<MountingDifference> halves_difference;
  std::vector<SessionPart> segments;
  std::vector<SegmentComparison> segment_comparisons;
  std::vector<WeakDirection> weak_directions;
};

// Consecutive ranges [first, last] of `per_segment` rests covering 0..rest_count-1; a last range
// shorter than min_rests joins the previous one.
std::vector<std::pair<std::size_t, std::size_t>> rest_segments(std::size_t rest_count,
                                                               std::size_t per_segment,
                                                               std::size_t min_rests = 3);

// With a heading reference (FrameCalibrationResult::heading): the IMS alone's heading against the
// reference, beyond repeat_warn_sigma / repeat_fail_sigma of their combined sigma a warn / fail
// (a wrong reference, a wrong sign convention, or a base that turned); none without a reference.
std::optional<MountingCheck> heading_reference_check(const FrameCalibrationResult& result,
                                                     const MountingThresholds& thresholds);

// Pure assessment (no solving) of a combined result and parts already calibrated.
MountingValidation assess_mounting(const FrameCalibrationResult& combined,
                                   std::vector<SessionPart> halves,
                                   std::vector<SessionPart> segments,
                                   const MountingThresholds& thresholds);

// Calibrates the rests [first, last] of `input` alone (same options, without the clock offset's
// rate windows: a part reports T_S_H, which they do not enter); a refusal of the bundle
// (InputError, HandEyeUnobservable) is recorded in the part, not thrown.
SessionPart calibrate_part(const FrameCalibrationInput& input,
                           const FrameCalibrationOptions& options, std::size_t first_rest,
                           std::size_t last_rest, std::string label);

using ValidationProgress = std::function<void(const std::string& stage, double fraction)>;

// Calibrates the halves and the segments with the bundle and assesses them with `combined`
// (the bundle's result on all of `input`).
MountingValidation validate_mounting(const FrameCalibrationInput& input,
                                     const FrameCalibrationOptions& options,
                                     const FrameCalibrationResult& combined,
                                     const MountingValidationOptions& validation_options,
                                     const ValidationProgress& progress = {});

// Repeatability between two sessions (two results of the same mount): a check with its level.
MountingCheck compare_sessions(const FrameCalibrationResult& first,
                               const FrameCalibrationResult& second,
                               const MountingThresholds& thresholds);

}  // namespace imscal::calib
