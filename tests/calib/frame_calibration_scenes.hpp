#pragma once
// Records for the frame-calibration tests (tests/calib/test_frame_calibration*.cpp): a robot that
// rests in given joint poses and moves between them, the IMS on its flange, and what the bundle
// needs (rests on the IMS clock, the robot joint series, the noise model), with the truth.
//
// Two sources: (1) a kinematic record made here (quintic joint moves, no plant: fast, and the
// poses are free, e.g. degenerate sets); (2) the plant's link-side motion of a simulated scenario
// (tests/data/scenarios/mounting-rigid.yaml) placed in W with frames drawn per seed. Both turn
// the flange poses into ideal IMS increments by ims::synthesize_ideal_increments on a spline of
// the 1 ms poses, then (optionally) into a real unit's output by ims::corrupt.
#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "calib/frame_calibration.hpp"
#include "calib/time_offset.hpp"
#include "ims/earth_model.hpp"
#include "ims/imu_noise.hpp"
#include "ims/imu_synthesis.hpp"
#include "ims/sensor_spec.hpp"
#include "ims/spline_trajectory.hpp"
#include "robot/forward_kinematics.hpp"

namespace imscal::test_support {

struct FrameScene {
  calib::KinematicModel kinematics;
  ims::Site site{48.78232, 9.18162, 245.4};
  Eigen::Isometry3d T_W_R = Eigen::Isometry3d::Identity();  // truth, W origin at the site
  Eigen::Isometry3d T_H_S = Eigen::Isometry3d::Identity();
  double clock_offset_s = 0.0123;  // t_ims = t_robot + offset
  // Robot clock: joint angles every 1 ms, rests [begin, end] and their link angles.
  std::vector<double> t_robot_s;
  std::vector<calib::JointVector> q_rad;
  std::vector<double> rest_begin_s, rest_end_s;
  std::vector<calib::JointVector> rest_q_rad;
  ims::ImuSeries imu;  // IMS clock
  ims::SensorErrorModel sensor_errors;

  Eigen::Isometry3d T_S_H() const { return T_H_S.inverse(); }
  Eigen::Isometry3d T_R_W() const { return T_W_R.inverse(); }
};

// Poses of datasets/programs/mounting.yaml (a subset): rotations about all flange axes [rad].
inline std::vector<calib::JointVector> mounting_poses() {
  const auto deg = [](double a1, double a2, double a3, double a4, double a5, double a6) {
    calib::JointVector q;
    q << a1, a2, a3, a4, a5, a6;
    return calib::JointVector(q * M_PI / 180.0);
  };
  return {deg(0, -90, 90, 0, 45, 0),        deg(0, -90, 90, 0, 45, 90),
          deg(0, -90, 90, 0, -45, 0),       deg(0, -90, 90, 90, 45, 0),
          deg(30, -80, 100, 0, 90, 0),      deg(-30, -100, 80, 45, 100, 45),
          deg(45, -60, 110, -120, 60, 180), deg(10, -90, 90, 0, 45, 0)};
}

// Quintic joint moves between rests; every pose is held rest_s, moves take move_s.
inline void make_kinematic_motion(FrameScene& scene, const std::vector<calib::JointVector>& poses,
                                  double rest_s, double move_s, double step_s = 0.001) {
  double t = 0.0;
  auto push = [&](const calib::JointVector& q) {
    scene.t_robot_s.push_back(t);
    scene.q_rad.push_back(q);
    t += step_s;
  };
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const double begin = t;
    const int rest_steps = static_cast<int>(std::lround(rest_s / step_s));
    for (int k = 0; k < rest_steps; ++k) push(poses[i]);
    scene.rest_begin_s.push_back(begin);
    scene.rest_end_s.push_back(t - step_s);
    scene.rest_q_rad.push_back(poses[i]);
    if (i + 1 == poses.size()) break;
    const int move_steps = static_cast<int>(std::lround(move_s / step_s));
    for (int k = 0; k < move_steps; ++k) {
      const double u = static_cast<double>(k) / move_steps;
      const double s = u * u * u * (10.0 - 15.0 * u + 6.0 * u * u);  // zero rate/acc at the ends
      push(poses[i] + s * (poses[i + 1] - poses[i]));
    }
  }
}

// Ideal increments of the IMS on the flange (1 kHz, IMS clock) from the scene's joint series.
inline void synthesize_scene_imu(FrameScene& scene, double rate_hz = 1000.0) {
  std::vector<ims::PoseSample> poses(scene.t_robot_s.size());
  for (std::size_t k = 0; k < poses.size(); ++k) {
    const Eigen::Isometry3d T_W_S =
        scene.T_W_R * calib::forward_kinematics<double>(scene.kinematics, scene.q_rad[k]) *
        scene.T_H_S;
    poses[k] = {scene.t_robot_s[k], T_W_S.translation(),
                Eigen::Quaterniond(T_W_S.linear()).normalized()};
  }
  const ims::SplineTrajectory trajectory(poses);
  const ims::EarthModel earth(scene.site);
  scene.imu = ims::synthesize_ideal_increments(trajectory, earth, rate_hz);
  for (ims::ImuSample& s : scene.imu.samples) s.t_s += scene.clock_offset_s;
  scene.imu.site = scene.site;
}

// A unit of `spec` with its turn-on biases drawn (scale factors and misalignments set to zero:
// the bundle's motions take the sensor's scale as exact, see calib/frame_bundle.hpp),
// noise, quantisation; bias instability only if keep_bias_instability.
inline void corrupt_scene_imu(FrameScene& scene, ims::SensorSpec spec, std::uint64_t seed,
                              bool keep_bias_instability = false) {
  std::mt19937_64 rng(seed);
  scene.sensor_errors = ims::draw_sensor_errors(spec, rng);
  scene.sensor_errors.gyro.scale_factor.setZero();
  scene.sensor_errors.gyro.misalignment.setZero();
  scene.sensor_errors.acc.scale_factor.setZero();
  scene.sensor_errors.acc.misalignment.setZero();
  if (!keep_bias_instability) {
    spec.gyro.bias_instability.clear();
    spec.acc.bias_instability.clear();
  }
  scene.imu = ims::corrupt(scene.imu, scene.sensor_errors, spec, rng());
}

inline calib::ImuNoiseModel noise_model_of(const ims::SensorSpec& spec) {
  calib::ImuNoiseModel n;
  n.gyro_noise_density_rad_per_sqrt_s = spec.gyro.white_noise_density;
  n.acc_noise_density_m_s_per_sqrt_s = spec.acc.white_noise_density;
  n.gyro_bias_sigma_rad_s = spec.gyro.turn_on_bias_sigma;
  n.acc_bias_sigma_m_s2 = spec.acc.turn_on_bias_sigma;
  n.gyro_quantization_rad = spec.gyro.quantization_lsb;
  n.acc_quantization_m_s = spec.acc.quantization_lsb;
  return n;
}

// The bundle's input for a scene: rests trimmed by `trim_s` at both ends, on the IMS clock.
inline calib::FrameCalibrationInput frame_input(const FrameScene& scene,
                                                const calib::ImuNoiseModel& noise,
                                                double trim_s = 0.5, std::size_t robot_stride = 2) {
  calib::FrameCalibrationInput in;
  in.imu = &scene.imu;
  in.site = scene.site;
  in.kinematics = scene.kinematics;
  for (std::size_t i = 0; i < scene.rest_begin_s.size(); ++i) {
    calib::RestObservation r;
    r.label = "rest " + std::to_string(i + 1);
    r.begin_ims_s = scene.rest_begin_s[i] + trim_s + scene.clock_offset_s;
    r.end_ims_s = scene.rest_end_s[i] - trim_s + scene.clock_offset_s;
    r.q_link_rad = scene.rest_q_rad[i];
    in.rests.push_back(r);
  }
  // The robot's joint log every robot_stride samples (2 ms, its control cycle, from 1 ms).
  for (std::size_t k = 0; k < scene.t_robot_s.size(); k += robot_stride) {
    in.robot.t_robot_s.push_back(scene.t_robot_s[k]);
    in.robot.q_rad.push_back(scene.q_rad[k]);
  }
  in.noise = noise;
  in.source = "test scene";
  const Eigen::Isometry3d T_W_S_1 =
      scene.T_W_R * calib::forward_kinematics<double>(scene.kinematics, scene.rest_q_rad.front()) *
      scene.T_H_S;
  in.first_rest_position_W_m = T_W_S_1.translation();
  return in;
}

// The automatic initial time offset as `imscal calibrate` has it: cross-correlation of the rate
// magnitudes (calib/time_offset.hpp), the Earth rate plus gyro bias in S taken as the first
// rest's mean gyro reading.
inline double automatic_time_offset(const calib::FrameCalibrationInput& in) {
  const calib::RateMagnitudeSeries robot =
      calib::flange_rate_magnitude(in.kinematics, in.robot.t_robot_s, in.robot.q_rad);
  Eigen::Vector3d rest_rate = Eigen::Vector3d::Zero();
  double rest_time = 0.0;
  for (std::size_t k = 1; k < in.imu->samples.size(); ++k) {
    const ims::ImuSample& s = in.imu->samples[k];
    if (s.t_s > in.rests[0].begin_ims_s && s.t_s <= in.rests[0].end_ims_s) {
      rest_rate += s.gyro;
      rest_time += s.t_s - in.imu->samples[k - 1].t_s;
    }
  }
  const calib::RateMagnitudeSeries ims =
      calib::ims_rate_magnitude(*in.imu, Eigen::Vector3d(rest_rate / rest_time));
  return calib::estimate_time_offset(robot, ims).offset_s;
}

}  // namespace imscal::test_support
