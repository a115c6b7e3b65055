#pragma once
// A reusable harness that compares robot-world/hand-eye estimators (T_R_W, T_S_H from rest poses)
// on simulated rest poses: random true frames, random joint configurations of a robot model,
// IMS poses with navigation-grade noise. Used by bench/bench_hand_eye.cpp (the baseline table
// for the frame calibration) and by tests (noise-free scenarios). Header-only, no OpenCV.
//
// Model: T_R_H_i = FK(q_i) exactly; T_W_S_i = T_R_W^-1 T_R_H_i T_S_H^-1 perturbed by a rotation
// exp(n_rot) on the S side (n_rot ~ N(0, attitude_sigma^2 I)) and a position error
// ~ N(0, position_sigma^2 I) in W.
#include <fmt/format.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <exception>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "ims/so3.hpp"
#include "robot/forward_kinematics.hpp"
#include "robot/robot_description.hpp"

namespace imscal::bench {

struct HandEyeEstimate {
  Eigen::Isometry3d T_R_W = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d T_S_H = Eigen::Isometry3d::Identity();
};

// An estimator: rest poses (FK, IMS) in, frames out; throws when it cannot solve.
using HandEyeEstimator = std::function<HandEyeEstimate(
    const std::vector<Eigen::Isometry3d>& T_R_H, const std::vector<Eigen::Isometry3d>& T_W_S)>;

struct HandEyeScenarioSpec {
  int pose_count = 20;
  double attitude_sigma_rad = 0.001 * M_PI / 180.0;  // per axis, on the IMS attitude
  double position_sigma_m = 0.02e-3;                 // per axis, on the IMS position
  double base_offset_m = 2.0;         // |components| of the true t_R_W are uniform in +-this
  double sensor_offset_m = 0.15;      // |components| of the true t_S_H are uniform in +-this
  double joint_range_fraction = 0.8;  // q_i uniform in this fraction of each joint's range
};

struct HandEyeScenario {
  HandEyeEstimate truth;
  std::vector<Eigen::Isometry3d> T_R_H;       // exact FK
  std::vector<Eigen::Isometry3d> T_W_S;       // with noise
  std::vector<Eigen::Isometry3d> T_W_S_true;  // without noise
};

inline Eigen::Matrix3d random_rotation(std::mt19937_64& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  // A normalised 4-vector of independent normals is uniform on S^3: a uniform random rotation.
  Eigen::Quaterniond q(normal(rng), normal(rng), normal(rng), normal(rng));
  return q.normalized().toRotationMatrix();
}

inline HandEyeScenario make_hand_eye_scenario(const calib::KinematicModel& model,
                                              std::uint64_t seed, const HandEyeScenarioSpec& spec) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::normal_distribution<double> normal(0.0, 1.0);
  HandEyeScenario s;
  s.truth.T_R_W.linear() = random_rotation(rng);
  s.truth.T_R_W.translation() =
      spec.base_offset_m * Eigen::Vector3d(unit(rng), unit(rng), unit(rng));
  s.truth.T_S_H.linear() = random_rotation(rng);
  s.truth.T_S_H.translation() =
      spec.sensor_offset_m * Eigen::Vector3d(unit(rng), unit(rng), unit(rng));
  const Eigen::Isometry3d T_W_R = s.truth.T_R_W.inverse();
  const Eigen::Isometry3d T_H_S = s.truth.T_S_H.inverse();
  for (int i = 0; i < spec.pose_count; ++i) {
    calib::JointVector q;
    for (int j = 0; j < calib::kJointCount; ++j) {
      const double mid = 0.5 * (model.lower_limit_rad(j) + model.upper_limit_rad(j));
      const double half = 0.5 * (model.upper_limit_rad(j) - model.lower_limit_rad(j));
      q(j) = mid + spec.joint_range_fraction * half * unit(rng);
    }
    const Eigen::Isometry3d T_R_H = calib::forward_kinematics<double>(model, q);
    const Eigen::Isometry3d T_W_S = T_W_R * T_R_H * T_H_S;
    Eigen::Isometry3d noisy = T_W_S;
    const Eigen::Vector3d rot_noise =
        spec.attitude_sigma_rad * Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
    noisy.linear() = T_W_S.linear() * ims::quat_exp(rot_noise).toRotationMatrix();
    noisy.translation() +=
        spec.position_sigma_m * Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
    s.T_R_H.push_back(T_R_H);
    s.T_W_S.push_back(noisy);
    s.T_W_S_true.push_back(T_W_S);
  }
  return s;
}

// Rotation error [rad] and translation error [m] of an estimate against the truth.
struct FrameError {
  double rotation_rad = 0.0;
  double translation_m = 0.0;
};
inline FrameError frame_error(const Eigen::Isometry3d& estimate, const Eigen::Isometry3d& truth) {
  FrameError e;
  e.rotation_rad =
      ims::quat_log(Eigen::Quaterniond(estimate.linear().transpose() * truth.linear()).normalized())
          .norm();
  e.translation_m = (estimate.translation() - truth.translation()).norm();
  return e;
}

struct HandEyeComparisonRow {
  std::string name;
  int runs = 0;
  // Estimator threw, returned non-finite numbers, or missed a rotation by more than the gross
  // error limit (a wrong solution, not an inaccurate one); such runs are left out of the means.
  int failures = 0;
  // Means over the successful runs (display units are named).
  double Z_rotation_deg = 0.0;
  double Z_translation_mm = 0.0;
  double X_rotation_deg = 0.0;
  double X_translation_mm = 0.0;
};

// Runs `estimator` on the scenarios of seeds first_seed .. first_seed + seed_count - 1.
inline HandEyeComparisonRow run_hand_eye_comparison(
    const std::string& name, const HandEyeEstimator& estimator, const calib::KinematicModel& model,
    const HandEyeScenarioSpec& spec, int seed_count, std::uint64_t first_seed = 1,
    double gross_rotation_error_rad = M_PI / 180.0) {
  HandEyeComparisonRow row;
  row.name = name;
  int ok = 0;
  for (int k = 0; k < seed_count; ++k) {
    const HandEyeScenario s = make_hand_eye_scenario(model, first_seed + std::uint64_t(k), spec);
    ++row.runs;
    HandEyeEstimate estimate;
    try {
      estimate = estimator(s.T_R_H, s.T_W_S);
    } catch (const std::exception&) {
      ++row.failures;
      continue;
    }
    if (!estimate.T_R_W.matrix().allFinite() || !estimate.T_S_H.matrix().allFinite()) {
      ++row.failures;
      continue;
    }
    const FrameError z = frame_error(estimate.T_R_W, s.truth.T_R_W);
    const FrameError x = frame_error(estimate.T_S_H, s.truth.T_S_H);
    if (!(z.rotation_rad < gross_rotation_error_rad && x.rotation_rad < gross_rotation_error_rad)) {
      ++row.failures;
      continue;
    }
    row.Z_rotation_deg += z.rotation_rad * 180.0 / M_PI;
    row.Z_translation_mm += z.translation_m * 1e3;
    row.X_rotation_deg += x.rotation_rad * 180.0 / M_PI;
    row.X_translation_mm += x.translation_m * 1e3;
    ++ok;
  }
  if (ok > 0) {
    row.Z_rotation_deg /= ok;
    row.Z_translation_mm /= ok;
    row.X_rotation_deg /= ok;
    row.X_translation_mm /= ok;
  }
  return row;
}

inline std::string format_hand_eye_table(const std::vector<HandEyeComparisonRow>& rows) {
  std::string out =
      fmt::format("{:<34} {:>5} {:>5} {:>14} {:>14} {:>14} {:>14}\n", "method", "runs", "fail",
                  "Z_rot_deg", "Z_trans_mm", "X_rot_deg", "X_trans_mm");
  for (const auto& r : rows) {
    if (r.failures == r.runs) {  // no successful run: no means to show
      out += fmt::format("{:<34} {:>5} {:>5} {:>14} {:>14} {:>14} {:>14}\n", r.name, r.runs,
                         r.failures, "n/a", "n/a", "n/a", "n/a");
      continue;
    }
    out += fmt::format("{:<34} {:>5} {:>5} {:>14.3e} {:>14.3e} {:>14.3e} {:>14.3e}\n", r.name,
                       r.runs, r.failures, r.Z_rotation_deg, r.Z_translation_mm, r.X_rotation_deg,
                       r.X_translation_mm);
  }
  return out;
}

}  // namespace imscal::bench
