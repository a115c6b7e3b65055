#pragma once
// Initial values of the frame calibration without user guesses:
//  1. the sensor's attitude at the first rest by coarse alignment (levelling by the
//     accelerometers, heading by gyrocompassing; ims/coarse_alignment.hpp);
//  2. the IMS poses at the other rests by chaining the motions' preintegrations at zero biases,
//     each started at rest (zero velocity) from the previous rest's pose, with the sensor at the
//     first rest at W's origin;
//  3. T_R_W and T_S_H from these poses and the forward kinematics of the rests' joint angles by
//     the closed-form robot-world/hand-eye solution (calib/hand_eye.hpp), which refuses pose sets
//     that cannot determine the frames (HandEyeUnobservable, naming the directions).
// The time offset starts from FrameCalibrationInput::time_offset_initial_s.
#include <Eigen/Geometry>
#include <vector>

#include "calib/frame_calibration.hpp"
#include "calib/frame_measurements.hpp"
#include "calib/hand_eye.hpp"
#include "ims/earth_model.hpp"

namespace imscal::calib {

struct FrameInitialValues {
  Eigen::Isometry3d T_R_W = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d T_S_H = Eigen::Isometry3d::Identity();
  double time_offset_s = 0.0;
  std::vector<Eigen::Isometry3d> T_W_S_rest;  // zero-bias chain, W origin at the first rest
  std::vector<Eigen::Isometry3d> T_R_H_rest;  // forward kinematics of the rests
  HandEyeResult hand_eye;
};

// motions: the preintegrations between consecutive rests at zero biases.
FrameInitialValues initial_frame_values(const FrameCalibrationInput& input,
                                        const std::vector<RestWindow>& rests,
                                        const std::vector<ImuPreintegration>& motions,
                                        const ims::EarthModel& earth);

}  // namespace imscal::calib
