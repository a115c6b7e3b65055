// The frame-and-bias bundle (calib/frame_calibration.hpp): set up, solved and reported by
// calib/frame_bundle*.cpp and calib/frame_calibration_report.cpp.
#include "calib/frame_calibration.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "calib/frame_bundle.hpp"
#include "robot/forward_kinematics.hpp"

namespace imscal::calib {

Eigen::Isometry3d frame_calibration_truth_convention(const Eigen::Isometry3d& T_R_W_true,
                                                     const Eigen::Isometry3d& T_S_H_true,
                                                     const KinematicModel& kinematics,
                                                     const JointVector& q_link_first_rest_rad) {
  const Eigen::Isometry3d T_W_S_1 = T_R_W_true.inverse() *
                                    forward_kinematics<double>(kinematics, q_link_first_rest_rad) *
                                    T_S_H_true.inverse();
  Eigen::Isometry3d T_W_Wnew = Eigen::Isometry3d::Identity();
  T_W_Wnew.translation() = T_W_S_1.translation();
  return T_R_W_true * T_W_Wnew;
}

FrameCalibrationResult calibrate_frames(const FrameCalibrationInput& input,
                                        const FrameCalibrationOptions& options) {
  FrameBundle bundle(input, options);
  auto [first, final_stage] = solve_frame_bundle(bundle);
  return report_frame_bundle(bundle, first, final_stage);
}

std::size_t FrameCalibrationResult::parameter_index(const std::string& name) const {
  const auto named = [&](const std::string& n) {
    return std::find(parameter_names.begin(), parameter_names.end(), n);
  };
  auto it = named(name);
  if (it == parameter_names.end()) {
    // A block of one component by its name alone ("time_offset" for "time_offset.dt").
    const auto prefix = [&](const std::string& n) { return n.rfind(name + ".", 0) == 0; };
    it = std::find_if(parameter_names.begin(), parameter_names.end(), prefix);
    if (it != parameter_names.end() && std::count_if(it, parameter_names.end(), prefix) != 1)
      it = parameter_names.end();
  }
  if (it == parameter_names.end())
    throw std::out_of_range("frame calibration result: no estimated parameter " + name);
  return static_cast<std::size_t>(it - parameter_names.begin());
}

double FrameCalibrationResult::sigma(const std::string& name) const {
  const auto i = static_cast<Eigen::Index>(parameter_index(name));
  if (i >= covariance.rows())
    throw std::out_of_range("frame calibration result: no covariance for " + name);
  return std::sqrt(std::max(0.0, covariance(i, i)));
}

double FrameCalibrationResult::value(const std::string& name) const {
  const auto i = static_cast<Eigen::Index>(parameter_index(name));
  if (i >= parameter_values.size())
    throw std::out_of_range("frame calibration result: no value for " + name);
  return parameter_values[i];
}

}  // namespace imscal::calib
