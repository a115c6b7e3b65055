// summary.txt of a calibration session (calib/calibration_session_summary.hpp).
#include "calib/calibration_session_summary.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "calib/calibration_json.hpp"
#include "core/units.hpp"
#include "core/version.hpp"

namespace imscal::calib {
namespace {

class Lines {
 public:
  void operator()(const std::string& text) { s_ << text << '\n'; }
  std::string str() const { return s_.str(); }

 private:
  std::ostringstream s_;
};

void header_and_verdict(Lines& line, const SessionSummarySources& sources,
                        const SessionResult& session) {
  const FrameCalibrationResult& r = session.frames;
  const MountingValidation& v = session.validation;
  line(fmt::format("imscal {} calibrate", kVersion));
  line(fmt::format("IMS record  {}", sources.imu));
  line(fmt::format("robot log   {}", sources.robot_log));
  if (!sources.frames.empty())
    line(fmt::format("frames      {} (T_R_W's rotation and T_S_H held: not estimated here)",
                     sources.frames));
  line("");
  line(fmt::format("VERDICT: {}", to_string(v.verdict)));
  for (const auto& reason : v.reasons) line("  - " + reason);
  line("");
  const RestPoseResult& rests = session.rests;
  line(fmt::format("rests used: {}, rejected: {}", rests.rests.size(), rests.rejected.size()));
  for (const auto& why : rests.rejected) line("  rejected: " + why);
  for (const auto& why : rests.trimmed) line("  trimmed: " + why);
  if (!session.rest_shortage.empty()) line("  WARNING: " + session.rest_shortage);
  line(fmt::format("initial time offset (cross-correlation): {:.3f} ms (peak {:.3f})",
                   session.initial_time_offset.offset_s * 1e3,
                   session.initial_time_offset.peak_correlation));
  line(fmt::format("solver: {} ({} iterations, {})", r.converged ? "converged" : "NOT converged",
                   r.iterations, r.solver_brief_report));
}

void estimates(Lines& line, const FrameCalibrationResult& r) {
  line("");
  line("estimates (value +- 1 sigma):");
  for (const auto& e : r.estimates) {
    std::string values;
    for (Eigen::Index k = 0; k < e.value.size(); ++k)
      values += fmt::format(
          "  {}={:.6g}+-{:.2g}",
          k < Eigen::Index(e.components.size()) ? e.components[std::size_t(k)] : std::to_string(k),
          e.value[k], k < e.sigma.size() ? e.sigma[k] : 0.0);
    line(fmt::format("  {} [{}]:{}", e.name, e.unit, values));
  }
  const Eigen::Vector3d rpy_S_H = roll_pitch_yaw(r.T_S_H.linear()) / kRadPerDeg;
  line(fmt::format("  T_S_H: xyz {:.4f} {:.4f} {:.4f} mm, rpy {:.5f} {:.5f} {:.5f} deg",
                   r.T_S_H.translation().x() * 1e3, r.T_S_H.translation().y() * 1e3,
                   r.T_S_H.translation().z() * 1e3, rpy_S_H.x(), rpy_S_H.y(), rpy_S_H.z()));
  const Eigen::Vector3d rpy_R_W = roll_pitch_yaw(r.T_R_W.linear()) / kRadPerDeg;
  line(
      fmt::format("  T_R_W: xyz {:.4f} {:.4f} {:.4f} mm, rpy {:.5f} {:.5f} {:.5f} deg "
                  "(W origin: the sensor at rest 1)",
                  r.T_R_W.translation().x() * 1e3, r.T_R_W.translation().y() * 1e3,
                  r.T_R_W.translation().z() * 1e3, rpy_R_W.x(), rpy_R_W.y(), rpy_R_W.z()));
  if (!r.heading || !r.heading->reference) return;
  const HeadingEstimate& h = *r.heading;
  line(fmt::format(
      "  base heading (yaw of T_W_R): {:.4f} +- {:.4f} deg with the reference {:.4f} +- {:.4f} "
      "deg ({}); the IMS alone (Earth rate): {:.4f} +- {:.4f} deg",
      h.yaw_rad / kRadPerDeg, h.sigma_rad / kRadPerDeg, h.reference->yaw_rad / kRadPerDeg,
      h.reference->sigma_rad / kRadPerDeg, h.reference->source, h.ims_only_yaw_rad / kRadPerDeg,
      h.ims_only_sigma_rad / kRadPerDeg));
}

void checks_and_residuals(Lines& line, const FrameCalibrationResult& r,
                          const MountingValidation& v) {
  if (!r.weak_directions.empty()) {
    line("");
    line("weak directions:");
    for (const auto& w : r.weak_directions)
      line(
          fmt::format("  {}: 1 sigma {:.3g} {}; {}", w.description, w.sigma, w.unit, w.suggestion));
  }
  line("");
  line("mounting checks:");
  for (const auto& c : v.checks)
    line(fmt::format("  [{}] {}: {}", to_string(c.level), c.name, c.message));
  line("");
  line("rest residuals (normalised, rotation):");
  for (const auto& p : r.rest_residuals)
    line(fmt::format("  {:<28} {:7.2f} sigma {:10.6f} deg{}", p.label, p.normalised,
                     p.rotation_rad / kRadPerDeg, p.outlier ? "  OUTLIER" : ""));
  line("motion residuals (normalised, rotation, position):");
  for (const auto& p : r.motion_residuals)
    line(fmt::format("  {:<28} {:7.2f} sigma {:10.6f} deg {:9.4f} mm{}", p.label, p.normalised,
                     p.rotation_rad / kRadPerDeg, p.position_m * 1e3,
                     p.outlier ? "  OUTLIER" : ""));
}

void joint_error_figures(Lines& line, const JointSpaceErrors& je) {
  line("");
  line(
      fmt::format("joint errors: {} samples ({} outside the IMS record, {} inverse-kinematics "
                  "failures, {} left out near the wrist singularity)",
                  je.sums.rows, je.outside_record, je.ik_failures, je.near_wrist_singularity));
  // The position the smoother could not observe, corrected where the arm stood at a pose
  // again (calib/revisited_poses.hpp) and interpolated at the other standstills.
  const auto returns =
      std::count_if(je.revisited_pose_errors.begin(), je.revisited_pose_errors.end(),
                    [](const auto& e) { return e.revisit; });
  if (returns > 0) {
    double largest = 0.0;
    for (const auto& e : je.revisited_pose_errors) largest = std::max(largest, e.error_W.norm());
    line(fmt::format(
        "  position corrected at {} returns to a pose stood at before, {} standstills in all "
        "(largest {:.3f} mm)",
        returns, je.revisited_pose_errors.size(), largest * 1e3));
  }
  const JointErrorSums& sums = je.sums;  // the rows may have gone to a file as computed
  if (sums.rows == 0) return;
  for (int j = 0; j < kJointCount; ++j) {
    line(fmt::format("  A{}: RMS {:.4f} mrad, max {:.4f} mrad", j + 1,
                     std::sqrt(sums.error_squared_rad2[j] / double(sums.rows)) * 1e3,
                     sums.error_max_abs_rad[j] * 1e3));
  }
}

}  // namespace

std::string session_summary_text(const SessionSummarySources& sources,
                                 const SessionResult& session) {
  Lines line;
  header_and_verdict(line, sources, session);
  estimates(line, session.frames);
  checks_and_residuals(line, session.frames, session.validation);
  if (session.joint_errors) joint_error_figures(line, *session.joint_errors);
  return line.str();
}

}  // namespace imscal::calib
