#pragma once
// OpenCV's hand-eye solvers (the peer implementation) wrapped as HandEyeEstimators for imscal's
// problem T_R_H_i = T_R_W T_W_S_i T_S_H. Only tests and benchmarks include this (OpenCV is never
// linked into the libraries).
//
// Convention mapping (OpenCV names frames by letter, ^aT_b maps b-coordinates into a, as ours):
//
// cv::calibrateRobotWorldHandEye solves  ^cT_w ^wT_b = ^cT_g ^gT_b  (AX = ZB), inputs ^cT_w
// ("world2cam") and ^gT_b ("base2gripper"), outputs ^wT_b ("base2world") and ^cT_g
// ("gripper2cam"). Ours, rewritten: T_R_H_i T_H_S = T_R_W T_W_S_i. So c = R, w = H, g = W,
// b = S:
//   world2cam_i    = T_R_H_i (forward kinematics)     base2gripper_i = T_W_S_i (IMS pose)
//   base2world     = T_H_S = T_S_H^-1                  gripper2cam    = T_R_W
//
// cv::calibrateHandEye solves  ^bT_g(i) ^gT_c ^cT_t(i) = ^bT_t (constant), inputs ^bT_g
// ("gripper2base") and ^cT_t ("target2cam"), output ^gT_c ("cam2gripper"). Ours:
// T_R_H_i T_H_S T_S_W_i = T_R_W. So b = R, g = H, c = S, t = W:
//   gripper2base_i = T_R_H_i     target2cam_i = T_S_W_i = T_W_S_i^-1     cam2gripper = T_H_S
// and T_R_W is then the mean over i of T_R_H_i T_H_S T_S_W_i (chordal mean of the rotations,
// arithmetic mean of the translations).
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

#include <vector>

#include "bench/hand_eye_comparison.hpp"
#include "calib/hand_eye.hpp"

namespace imscal::bench {

inline cv::Mat to_cv_rotation(const Eigen::Isometry3d& pose) {
  cv::Mat m(3, 3, CV_64F);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) m.at<double>(r, c) = pose.linear()(r, c);
  }
  return m;
}
inline cv::Mat to_cv_translation(const Eigen::Isometry3d& pose) {
  cv::Mat m(3, 1, CV_64F);
  for (int r = 0; r < 3; ++r) m.at<double>(r, 0) = pose.translation()(r);
  return m;
}
inline Eigen::Isometry3d from_cv(const cv::Mat& rotation, const cv::Mat& translation) {
  cv::Mat r64, t64;
  rotation.convertTo(r64, CV_64F);
  translation.convertTo(t64, CV_64F);
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) pose.linear()(r, c) = r64.at<double>(r, c);
    pose.translation()(r) = t64.at<double>(r, 0);
  }
  return pose;
}

inline HandEyeEstimate opencv_robot_world_hand_eye(const std::vector<Eigen::Isometry3d>& T_R_H,
                                                   const std::vector<Eigen::Isometry3d>& T_W_S,
                                                   cv::RobotWorldHandEyeCalibrationMethod method) {
  std::vector<cv::Mat> r_world2cam, t_world2cam, r_base2gripper, t_base2gripper;
  for (std::size_t i = 0; i < T_R_H.size(); ++i) {
    r_world2cam.push_back(to_cv_rotation(T_R_H[i]));
    t_world2cam.push_back(to_cv_translation(T_R_H[i]));
    r_base2gripper.push_back(to_cv_rotation(T_W_S[i]));
    t_base2gripper.push_back(to_cv_translation(T_W_S[i]));
  }
  cv::Mat r_base2world, t_base2world, r_gripper2cam, t_gripper2cam;
  cv::calibrateRobotWorldHandEye(r_world2cam, t_world2cam, r_base2gripper, t_base2gripper,
                                 r_base2world, t_base2world, r_gripper2cam, t_gripper2cam, method);
  HandEyeEstimate out;
  out.T_R_W = from_cv(r_gripper2cam, t_gripper2cam);
  out.T_S_H = from_cv(r_base2world, t_base2world).inverse();
  return out;
}

inline HandEyeEstimate opencv_hand_eye(const std::vector<Eigen::Isometry3d>& T_R_H,
                                       const std::vector<Eigen::Isometry3d>& T_W_S,
                                       cv::HandEyeCalibrationMethod method) {
  std::vector<cv::Mat> r_gripper2base, t_gripper2base, r_target2cam, t_target2cam;
  for (std::size_t i = 0; i < T_R_H.size(); ++i) {
    const Eigen::Isometry3d T_S_W = T_W_S[i].inverse();
    r_gripper2base.push_back(to_cv_rotation(T_R_H[i]));
    t_gripper2base.push_back(to_cv_translation(T_R_H[i]));
    r_target2cam.push_back(to_cv_rotation(T_S_W));
    t_target2cam.push_back(to_cv_translation(T_S_W));
  }
  cv::Mat r_cam2gripper, t_cam2gripper;
  cv::calibrateHandEye(r_gripper2base, t_gripper2base, r_target2cam, t_target2cam, r_cam2gripper,
                       t_cam2gripper, method);
  const Eigen::Isometry3d T_H_S = from_cv(r_cam2gripper, t_cam2gripper);
  Eigen::Matrix3d rotation_sum = Eigen::Matrix3d::Zero();
  Eigen::Vector3d translation_sum = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < T_R_H.size(); ++i) {
    const Eigen::Isometry3d T_R_W_i = T_R_H[i] * T_H_S * T_W_S[i].inverse();
    rotation_sum += T_R_W_i.linear();
    translation_sum += T_R_W_i.translation();
  }
  HandEyeEstimate out;
  out.T_R_W.linear() = calib::nearest_rotation(rotation_sum);
  out.T_R_W.translation() = translation_sum / static_cast<double>(T_R_H.size());
  out.T_S_H = T_H_S.inverse();
  return out;
}

}  // namespace imscal::bench
