// The result of the solved frame-and-bias bundle (calib/frame_bundle.hpp): the estimates with
// their covariance in reporting units, the weak directions, the base's heading (with and without
// a heading reference), and the residuals per rest and motion with the outliers. Blocks are
// found through the bundle's parameter layout by name.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <tuple>

#include "calib/frame_bundle.hpp"
#include "calib/frame_covariance.hpp"
#include "core/units.hpp"
#include "robot/forward_kinematics.hpp"

namespace imscal::calib {
namespace {

// The solution, the solver's summary and the initial values.
void report_solution(const FrameBundle& b, const FrameStage& first, const FrameStage& final_stage,
                     FrameCalibrationResult& result) {
  const FrameUnknowns& x = b.x;
  const Eigen::Matrix3d R_W_R = x.R_W_R();
  const Eigen::Matrix3d R_S_H = x.R_S_H();
  const Eigen::Vector3d p_S_H = Eigen::Map<const Eigen::Vector3d>(x.p_S_H);
  result.initial_T_R_W = b.init.T_R_W;
  result.initial_T_S_H = b.init.T_S_H;
  result.initial_time_offset_s = b.init.time_offset_s;
  result.T_S_H.linear() = R_S_H;
  result.T_S_H.translation() = p_S_H;
  const Eigen::Isometry3d T_R_H_1 = forward_kinematics<double>(
      b.input.kinematics, JointVector(b.input.rests[0].q_link_rad + x.joint_deviation(0)));
  const Eigen::Vector3d p_R_S_1 =
      T_R_H_1.translation() + T_R_H_1.linear() * (-(R_S_H.transpose() * p_S_H));
  Eigen::Isometry3d T_W_R = Eigen::Isometry3d::Identity();
  T_W_R.linear() = R_W_R;
  T_W_R.translation() = -R_W_R * p_R_S_1;  // the sensor at rest 1 at W's origin
  result.T_R_W = T_W_R.inverse();
  result.biases = x.biases();
  for (const double* a : x.b_a_blocks) result.acc_bias_at_rests_m_s2.emplace_back(a[0], a[1], a[2]);
  result.gyro_scale_factor = Eigen::Map<const Eigen::Vector3d>(x.s_g);
  result.acc_scale_factor = Eigen::Map<const Eigen::Vector3d>(x.s_a);
  result.time_offset_s = x.dt[0];
  if (b.link_share_estimated) result.link_share = x.link_share[0];
  for (int k = 0; k < kJointCount; ++k) {
    result.windup_scale[k] = 1.0 - x.m_w[k];
    result.play_scale[k] = 1.0 - x.m_p[k];
  }
  for (std::size_t i = 0; i < b.rests.size(); ++i)
    result.joint_deviation_rad.push_back(x.joint_deviation(i));
  const ceres::Solver::Summary& summary = final_stage.summary;
  result.solver_brief_report = summary.BriefReport();
  result.iterations = static_cast<int>(summary.iterations.size());
  result.final_cost = summary.final_cost;
  result.converged = summary.IsSolutionUsable() && summary.termination_type == ceres::CONVERGENCE &&
                     first.summary.IsSolutionUsable();
}

// The covariance of the layout's blocks at the final solution; with known frames, theirs.
FrameCovariance bundle_covariance(const FrameBundle& b, FrameStage& final_stage) {
  // A failed solve has no estimate to take a covariance at (ceres::Covariance on it aborts).
  FrameCovariance cov;
  if (final_stage.summary.IsSolutionUsable()) {
    cov = compute_frame_covariance(*final_stage.problem, b.layout.covariance_blocks());
  } else {
    cov.message = "no covariance: the solve failed (" + final_stage.summary.message + ")";
  }
  if (!b.frames_known || !cov.computed) return cov;
  // The held frames have no covariance from this problem (constant blocks: zero); theirs is
  // the earlier session's, reported as it is (the other unknowns are conditional on them).
  const int frames = 9;  // R_W_R, R_S_H, p_S_H: the layout's first three blocks
  cov.covariance.topLeftCorner<frames, frames>() = b.input.known_frames->covariance;
  cov.covariance.topRightCorner(frames, cov.covariance.cols() - frames).setZero();
  cov.covariance.bottomLeftCorner(cov.covariance.rows() - frames, frames).setZero();
  const Eigen::VectorXd sigma = cov.covariance.diagonal().cwiseMax(0.0).cwiseSqrt();
  for (Eigen::Index i = 0; i < sigma.size(); ++i)
    for (Eigen::Index j = 0; j < sigma.size(); ++j) {
      const double d = sigma[i] * sigma[j];
      cov.correlation(i, j) = d > 0.0 ? cov.covariance(i, j) / d : (i == j ? 1.0 : 0.0);
    }
  return cov;
}

// The 1-sigma of each component of a declared block [SI].
Eigen::VectorXd block_sigma(const FrameBundle& b, const FrameCovariance& cov,
                            const std::string& block, int size) {
  const int offset = b.layout.offset(block);
  Eigen::VectorXd s(size);
  for (int k = 0; k < size; ++k)
    s[k] = std::sqrt(std::max(0.0, cov.covariance(offset + k, offset + k)));
  return s;
}

// Frames, biases, time offset and scale factors in reporting units.
void report_estimates(const FrameBundle& b, const FrameCovariance& cov,
                      FrameCalibrationResult& result) {
  const Eigen::Vector3d rotvec_W_R = ims::quat_log<double>(Eigen::Quaterniond(b.x.R_W_R()));
  const Eigen::Vector3d rotvec_S_H = ims::quat_log<double>(Eigen::Quaterniond(b.x.R_S_H()));
  const Eigen::Vector3d p_S_H = Eigen::Map<const Eigen::Vector3d>(b.x.p_S_H);
  auto sigma = [&](const std::string& block, int size) { return block_sigma(b, cov, block, size); };
  std::vector<EstimatedVector>& e = result.estimates;
  e.push_back({"R_W_R.rotation_vector (sigma: small angles about W east/north/up)",
               "deg",
               {"east", "north", "up"},
               rotvec_W_R * kDegPerRad,
               sigma("R_W_R", 3) * kDegPerRad});
  e.push_back({"T_S_H.rotation_vector (sigma: small angles about S axes)",
               "deg",
               {"x", "y", "z"},
               rotvec_S_H * kDegPerRad,
               sigma("R_S_H", 3) * kDegPerRad});
  e.push_back({"T_S_H.translation", "mm", {"x", "y", "z"}, p_S_H * 1e3, sigma("p_S_H", 3) * 1e3});
  e.push_back({"gyro_bias",
               "deg/h",
               {"x", "y", "z"},
               result.biases.gyro_rad_s * kDegPerRad * 3600.0,
               sigma("gyro_bias", 3) * kDegPerRad * 3600.0});
  e.push_back({"acc_bias",
               "ug",
               {"x", "y", "z"},
               result.biases.acc_m_s2 / kStandardGravity_m_s2 * 1e6,
               sigma("acc_bias", 3) / kStandardGravity_m_s2 * 1e6});
  if (b.layout.contains("time_offset")) {
    e.push_back({"time_offset",
                 "ms",
                 {"dt"},
                 Eigen::VectorXd::Constant(1, b.x.dt[0] * 1e3),
                 sigma("time_offset", 1) * 1e3});
  }
  if (b.layout.contains("gyro_scale_factor")) {
    e.push_back({"gyro_scale_factor",
                 "ppm",
                 {"x", "y", "z"},
                 result.gyro_scale_factor * 1e6,
                 sigma("gyro_scale_factor", 3) * 1e6});
    e.push_back({"acc_scale_factor",
                 "ppm",
                 {"x", "y", "z"},
                 result.acc_scale_factor * 1e6,
                 sigma("acc_scale_factor", 3) * 1e6});
  }
}

// The deflection scales k = 1 - m with their 1-sigma, per estimated joint, and the link share.
void report_drive_estimates(const FrameBundle& b, const FrameCovariance& cov,
                            FrameCalibrationResult& result) {
  for (auto [block, factor, sigma, label] :
       {std::tuple{"windup_scale_deviation", &result.windup_scale, &result.windup_scale_sigma,
                   "windup_scale (gear wind-up found / robot file's)"},
        std::tuple{"play_scale_deviation", &result.play_scale, &result.play_scale_sigma,
                   "play_scale (backlash play found at rest / robot file's)"}}) {
    std::vector<std::string> components;
    std::vector<double> values, sigmas;
    for (int joint = 0; joint < kJointCount; ++joint) {
      const std::string name = fmt::format("A{}", joint + 1);
      const std::optional<int> i = b.layout.find(block, name);
      if (!i) continue;
      const double s = std::sqrt(std::max(0.0, cov.covariance(Eigen::Index(*i), Eigen::Index(*i))));
      (*sigma)[joint] = s;
      components.push_back(name);
      values.push_back((*factor)[joint]);
      sigmas.push_back(s);
    }
    if (values.empty()) continue;
    result.estimates.push_back(
        {label, "1", components,
         Eigen::Map<const Eigen::VectorXd>(values.data(), Eigen::Index(values.size())),
         Eigen::Map<const Eigen::VectorXd>(sigmas.data(), Eigen::Index(sigmas.size()))});
  }
  if (!b.layout.contains("link_share")) return;
  result.link_share_sigma = block_sigma(b, cov, "link_share", 1)[0];
  result.estimates.push_back({"link_share (of the drives' viscous friction, at the gear output)",
                              "1",
                              {"s"},
                              Eigen::VectorXd::Constant(1, result.link_share),
                              Eigen::VectorXd::Constant(1, result.link_share_sigma)});
}

void report_weak_directions(const FrameBundle& b, const FrameCovariance& cov,
                            FrameCalibrationResult& result) {
  std::vector<Eigen::Matrix3d> flange_rotations;
  const std::vector<Eigen::Isometry3d>& T_R_H = b.init.T_R_H_rest;
  for (std::size_t i = 0; i + 1 < b.rests.size(); ++i)
    flange_rotations.push_back(T_R_H[i].linear().transpose() * T_R_H[i + 1].linear());
  const FrameParameterLayout& layout = b.layout;
  const int offset_dt = layout.contains("time_offset") ? layout.offset("time_offset") : -1;
  result.weak_directions = describe_weak_directions(
      cov, layout.offset("R_W_R"), layout.offset("R_S_H"), layout.offset("p_S_H"), offset_dt,
      b.time_offset_observed, b.x.R_S_H(), flange_rotations);
  if (!b.frames_known) return;
  // The frames are not estimated from this record's poses: what its poses do not excite is no
  // weakness of the frames (their sigma is the earlier session's).
  std::erase_if(result.weak_directions, [](const WeakDirection& w) {
    return w.description.rfind("the poses hardly turn the flange", 0) == 0;
  });
}

double wrapped_rad(double angle_rad) {
  return std::remainder(angle_rad, 2.0 * std::numbers::pi);
}

// The base's heading from the covariance's R_W_R.up; with a reference, the IMS alone's figures
// by taking the reference's information out again (HeadingEstimate).
void report_heading(const FrameBundle& b, const FrameCovariance& cov,
                    FrameCalibrationResult& result) {
  if (!cov.computed || b.frames_known) return;
  HeadingEstimate h;
  const Eigen::Matrix3d R_W_R = b.x.R_W_R();
  h.yaw_rad = std::atan2(R_W_R(1, 0), R_W_R(0, 0));  // R_W_R = Rz(yaw) Ry(pitch) Rx(roll)
  const int up = b.layout.index("R_W_R", "up");
  h.sigma_rad = std::sqrt(std::max(0.0, cov.covariance(up, up)));
  h.ims_only_yaw_rad = h.yaw_rad;
  h.ims_only_sigma_rad = h.sigma_rad;
  h.reference = b.input.heading_reference;
  if (h.reference) {
    const double reference_information = 1.0 / (h.reference->sigma_rad * h.reference->sigma_rad);
    const double ims_information = 1.0 / (h.sigma_rad * h.sigma_rad) - reference_information;
    if (ims_information > 0.0) {
      h.ims_only_sigma_rad = 1.0 / std::sqrt(ims_information);
      h.ims_only_yaw_rad =
          wrapped_rad(h.yaw_rad + reference_information / ims_information *
                                      wrapped_rad(h.yaw_rad - h.reference->yaw_rad));
    } else {
      h.ims_only_sigma_rad = std::numeric_limits<double>::infinity();
    }
    // The heading is the reference's (with the IMS): no weak direction; the mounting report's
    // heading check gives both figures (calib/mounting_validation.hpp).
    std::erase_if(result.weak_directions, [](const WeakDirection& w) {
      return w.description.rfind("heading of R in W", 0) == 0;
    });
  }
  result.heading = h;
}

void report_rest_residuals(const FrameBundle& b, const FrameStage& stage,
                           FrameCalibrationResult& result) {
  const FrameUnknowns& x = b.x;
  for (std::size_t i = 0; i < b.rests.size(); ++i) {
    const RestResidual& f = stage.rest_functors[i];
    Eigen::Matrix<double, 6, 1> r;
    f(x.q_W_R, x.q_S_H, x.dq[i], x.b_g, x.b_a_blocks[i], x.s_g, x.s_a, x.m_w, x.m_p, r.data());
    PoseResidual p;
    p.label = b.input.rests[i].label;
    p.normalised = std::sqrt(r.squaredNorm() / 6.0);
    p.rotation_rad = (r.tail<3>() * f.force_sigma).norm() / f.gravity_W.norm();
    p.outlier = p.normalised > b.options.outlier_threshold_sigma;
    if (p.outlier) {
      result.outliers.push_back(fmt::format(
          "{}: the mean rate and specific force at rest disagree with the model by {:.1f} sigma "
          "(tilt equivalent {:.2g} deg): robot not still, mount slipped, or wrong joint angles",
          p.label, p.normalised, p.rotation_rad * kDegPerRad));
    }
    result.rest_residuals.push_back(p);
  }
}

void report_motion_residuals(const FrameBundle& b, const FrameStage& stage,
                             FrameCalibrationResult& result) {
  const FrameUnknowns& x = b.x;
  const std::vector<RestObservation>& rests = b.input.rests;
  for (std::size_t i = 0; i + 1 < b.rests.size(); ++i) {
    const MotionResidual& f = stage.motion_functors[i];
    Eigen::Matrix<double, 9, 1> r;
    f(x.q_W_R, x.q_S_H, x.p_S_H, x.dq[i], x.dq[i + 1], x.b_g, x.b_a_blocks[i], x.b_a_blocks[i + 1],
      x.m_w, x.m_p, r.data());
    const Eigen::Matrix<double, 9, 1> raw = stage.motion_covariance_factor[i] * r;
    PoseResidual p;
    p.label = fmt::format("{} -> {}", rests[i].label, rests[i + 1].label);
    p.normalised = std::sqrt(r.squaredNorm() / 9.0);
    p.rotation_rad = raw.head<3>().norm();
    p.position_m = raw.tail<3>().norm();
    p.outlier = p.normalised > b.options.outlier_threshold_sigma;
    if (p.outlier) {
      result.outliers.push_back(fmt::format(
          "motion {}: the IMS's motion disagrees with the forward kinematics by {:.1f} sigma "
          "(rotation {:.2g} deg, position {:.3f} mm): slipped mount, rest boundaries inside the "
          "motion, or joint readings off",
          p.label, p.normalised, p.rotation_rad * kDegPerRad, p.position_m * 1e3));
    }
    result.motion_residuals.push_back(p);
  }
}

}  // namespace

FrameCalibrationResult report_frame_bundle(const FrameBundle& b, const FrameStage& first,
                                           FrameStage& final_stage) {
  FrameCalibrationResult result;
  report_solution(b, first, final_stage, result);
  const FrameCovariance cov = bundle_covariance(b, final_stage);
  result.parameter_names = cov.parameter_names;
  if (!result.parameter_names.empty()) result.parameter_values = b.layout.values();
  result.covariance = cov.covariance;
  result.correlation = cov.correlation;
  result.covariance_rank_deficient = cov.rank_deficient;
  if (cov.computed) {
    report_estimates(b, cov, result);
    report_drive_estimates(b, cov, result);
  }
  report_weak_directions(b, cov, result);
  report_heading(b, cov, result);
  report_rest_residuals(b, final_stage, result);
  report_motion_residuals(b, final_stage, result);
  return result;
}

}  // namespace imscal::calib
