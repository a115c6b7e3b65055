#include "calib/kinematic_calibration.hpp"

#include <fmt/format.h>

#include <ceres/ceres.h>
#include <ceres/rotation.h>
#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <memory>
#include <stdexcept>

#include "robot/forward_kinematics.hpp"

namespace imscal::calib {
namespace {

using Vector = Eigen::Matrix<double, kKinematicParameterCount, 1>;

// r = exp(x_rot) R0 · T_R_H(q; DH + Δ) · p_target + t − p_measured [m].
struct TrackerPositionResidual {
  const KinematicModel* nominal;
  Eigen::Matrix3d R0;
  JointVector q;
  Eigen::Vector3d measured_m;

  template <typename T>
  bool operator()(const T* x, T* residual) const {
    Isometry3<T> pose = cast_pose<T>(nominal->T_R_0);
    for (int i = 0; i < kJointCount; ++i) {
      const DhParameters& p = nominal->dh[i];
      const T* delta = x + kDhIndex + 4 * i;
      pose = pose * dh_link_transform(nominal->convention, T(p.a_m) + delta[2],
                                      T(p.alpha_rad) + delta[3], T(p.d_m) + delta[1],
                                      T(q(i) + p.offset_rad) + delta[0]);
    }
    pose = pose * cast_pose<T>(nominal->T_6_H);
    const Eigen::Matrix<T, 3, 1> target =
        pose * Eigen::Matrix<T, 3, 1>(x[kTargetIndex], x[kTargetIndex + 1], x[kTargetIndex + 2]);
    const Eigen::Matrix<T, 3, 1> initial = R0.cast<T>() * target;
    T rotated[3];
    ceres::AngleAxisRotatePoint(x + kBaseRotationIndex, initial.data(), rotated);
    for (int k = 0; k < 3; ++k) {
      residual[k] = rotated[k] + x[kBaseTranslationIndex + k] - T(measured_m(k));
    }
    return true;
  }
};

using ResidualCost =
    ceres::AutoDiffCostFunction<TrackerPositionResidual, 3, kKinematicParameterCount>;

// Initial tracker <- base and target: alternately a rigid fit (Umeyama) of the predicted target
// positions onto the measured ones and a linear least-squares fit of target and translation with
// the rotation held (p_meas − R p_H = R R_H p_target + t).
void initial_frames(const KinematicModel& nominal, const std::vector<TrackerPose>& poses,
                    Eigen::Matrix3d& R, Eigen::Vector3d& t, Eigen::Vector3d& target) {
  const auto n = static_cast<Eigen::Index>(poses.size());
  std::vector<Eigen::Isometry3d> flange;
  for (const TrackerPose& p : poses) flange.push_back(forward_kinematics<double>(nominal, p.q_rad));
  target.setZero();
  for (int iteration = 0; iteration < 20; ++iteration) {
    Eigen::Matrix3Xd from(3, n), to(3, n);
    for (Eigen::Index k = 0; k < n; ++k) {
      from.col(k) = flange[k] * target;
      to.col(k) = poses[k].p_tracker_m;
    }
    const Eigen::Matrix4d fit = Eigen::umeyama(from, to, false);
    R = fit.topLeftCorner<3, 3>();
    Eigen::MatrixXd A(3 * n, 6);
    Eigen::VectorXd b(3 * n);
    for (Eigen::Index k = 0; k < n; ++k) {
      A.block<3, 3>(3 * k, 0) = R * flange[k].linear();
      A.block<3, 3>(3 * k, 3).setIdentity();
      b.segment<3>(3 * k) = poses[k].p_tracker_m - R * flange[k].translation();
    }
    const Eigen::VectorXd solution = A.colPivHouseholderQr().solve(b);
    target = solution.head<3>();
    t = solution.tail<3>();
  }
}

// Which parameters the poses identify (see the header), in layout order.
std::array<double, kKinematicParameterCount> independence(
    const std::vector<std::unique_ptr<ResidualCost>>& costs, const Vector& x,
    double min_independence) {
  Eigen::MatrixXd J(3 * costs.size(), kKinematicParameterCount);
  for (std::size_t k = 0; k < costs.size(); ++k) {
    Eigen::Matrix<double, 3, kKinematicParameterCount, Eigen::RowMajor> block;
    double residual[3];
    const double* parameters[] = {x.data()};
    double* jacobians[] = {block.data()};
    costs[k]->Evaluate(parameters, residual, jacobians);
    J.middleRows<3>(3 * static_cast<Eigen::Index>(k)) = block;
  }
  std::array<double, kKinematicParameterCount> out{};
  Eigen::MatrixXd basis(J.rows(), 0);
  for (int c = 0; c < kKinematicParameterCount; ++c) {
    const double norm = J.col(c).norm();
    if (!(norm > 0.0)) continue;
    Eigen::VectorXd column = J.col(c) / norm;
    for (int pass = 0; pass < 2; ++pass) column -= basis * (basis.transpose() * column);
    out[c] = column.norm();
    if (out[c] >= min_independence) {
      basis.conservativeResize(Eigen::NoChange, basis.cols() + 1);
      basis.col(basis.cols() - 1) = column / out[c];
    }
  }
  return out;
}

}  // namespace

std::vector<std::string> kinematic_parameter_names() {
  std::vector<std::string> names{"base_rx", "base_ry",  "base_rz",  "base_x",  "base_y",
                                 "base_z",  "target_x", "target_y", "target_z"};
  for (int i = 1; i <= kJointCount; ++i) {
    for (const char* what : {"dtheta", "dd", "da", "dalpha"}) {
      names.push_back(fmt::format("{}{}", what, i));
    }
  }
  return names;
}

namespace {

std::string unit_of(int index) {
  if (index < kBaseTranslationIndex) return "rad";
  if (index < kDhIndex) return "m";
  const int within = (index - kDhIndex) % 4;
  return within == 0 || within == 3 ? "rad" : "m";
}

// The parameters the solve may move; reasons for the others.
std::vector<KinematicParameter> parameter_table(
    const std::array<double, kKinematicParameterCount>& independence,
    const KinematicCalibrationOptions& options) {
  const std::vector<std::string> names = kinematic_parameter_names();
  std::vector<KinematicParameter> out;
  for (int c = 0; c < kKinematicParameterCount; ++c) {
    KinematicParameter p;
    p.name = names[c];
    p.unit = unit_of(c);
    p.independence = independence[c];
    if (c >= kDhIndex && !options.estimate_geometry) {
      p.reason = "nominal model: DH parameters not estimated";
    } else if (independence[c] < options.min_independence) {
      p.reason = fmt::format(
          "not identifiable: {:.2g} of its effect is independent of the parameters before it "
          "(limit {:.2g})",
          independence[c], options.min_independence);
    } else {
      p.estimated = true;
    }
    out.push_back(p);
  }
  return out;
}

// Residual variance per component and the parameters' 1σ from the scaled covariance.
void add_covariance(ceres::Problem& problem, double* x, int residual_count,
                    KinematicCalibration& result) {
  double cost = 0.0;
  problem.Evaluate(ceres::Problem::EvaluateOptions(), &cost, nullptr, nullptr, nullptr);
  const int dof = residual_count - result.estimated_count;
  result.residual_sigma_m = std::sqrt(2.0 * cost / std::max(dof, 1));
  result.rms_fit_m = std::sqrt(2.0 * cost / (residual_count / 3));
  ceres::Covariance::Options covariance_options;
  covariance_options.algorithm_type = ceres::DENSE_SVD;
  ceres::Covariance covariance(covariance_options);
  const std::vector<std::pair<const double*, const double*>> blocks{{x, x}};
  if (!covariance.Compute(blocks, &problem)) {
    throw std::runtime_error("kinematic calibration: the covariance is rank deficient");
  }
  Eigen::Matrix<double, kKinematicParameterCount, kKinematicParameterCount, Eigen::RowMajor> C;
  covariance.GetCovarianceBlock(x, x, C.data());
  for (int c = 0; c < kKinematicParameterCount; ++c) {
    KinematicParameter& p = result.parameters[c];
    p.sigma = p.estimated ? result.residual_sigma_m * std::sqrt(std::max(C(c, c), 0.0)) : 0.0;
  }
}

// The calibrated model, frames and parameter values from the solution.
void store_solution(const KinematicModel& nominal, const Eigen::Matrix3d& R0, const Vector& x,
                    KinematicCalibration& result) {
  result.model = nominal;
  for (int i = 0; i < kJointCount; ++i) {
    DhParameters& p = result.model.dh[i];
    p.offset_rad += x(kDhIndex + 4 * i);
    p.d_m += x(kDhIndex + 4 * i + 1);
    p.a_m += x(kDhIndex + 4 * i + 2);
    p.alpha_rad += x(kDhIndex + 4 * i + 3);
  }
  const Eigen::Vector3d w = x.segment<3>(kBaseRotationIndex);
  const Eigen::Matrix3d dR = w.norm() > 0.0
                                 ? Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix()
                                 : Eigen::Matrix3d::Identity();
  result.T_tracker_base.linear() = dR * R0;
  result.T_tracker_base.translation() = x.segment<3>(kBaseTranslationIndex);
  result.p_H_target_m = x.segment<3>(kTargetIndex);
  for (int c = 0; c < kKinematicParameterCount; ++c) result.parameters[c].value = x(c);
}

}  // namespace

KinematicCalibration calibrate_kinematics(const KinematicModel& nominal,
                                          const std::vector<TrackerPose>& poses,
                                          const KinematicCalibrationOptions& options) {
  Eigen::Matrix3d R0;
  Vector x = Vector::Zero();
  Eigen::Vector3d t, target;
  if (poses.size() < 10) throw std::invalid_argument("kinematic calibration: fewer than 10 poses");
  initial_frames(nominal, poses, R0, t, target);
  x.segment<3>(kBaseTranslationIndex) = t;
  x.segment<3>(kTargetIndex) = target;
  std::vector<std::unique_ptr<ResidualCost>> costs;
  for (const TrackerPose& p : poses) {
    costs.push_back(std::make_unique<ResidualCost>(
        new TrackerPositionResidual{&nominal, R0, p.q_rad, p.p_tracker_m}));
  }
  KinematicCalibration result;
  result.pose_count = static_cast<int>(poses.size());
  result.parameters = parameter_table(independence(costs, x, options.min_independence), options);
  std::vector<int> fixed;
  for (int c = 0; c < kKinematicParameterCount; ++c) {
    if (!result.parameters[c].estimated) fixed.push_back(c);
  }
  for (int c = 0; c < kDhIndex; ++c) {
    if (!result.parameters[c].estimated) {
      throw std::invalid_argument(
          "kinematic calibration: the poses do not determine the tracker "
          "frame and the target (" +
          result.parameters[c].name + " has no effect of its own): too little motion");
    }
  }
  result.estimated_count = kKinematicParameterCount - static_cast<int>(fixed.size());
  if (3 * poses.size() < 2 * static_cast<std::size_t>(result.estimated_count)) {
    throw std::invalid_argument("kinematic calibration: too few poses for the parameters");
  }
  ceres::Problem::Options problem_options;
  problem_options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  for (auto& cost : costs) problem.AddResidualBlock(cost.get(), nullptr, x.data());
  if (!fixed.empty()) {
    problem.SetManifold(x.data(), new ceres::SubsetManifold(kKinematicParameterCount, fixed));
  }
  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_QR;
  solver_options.max_num_iterations = options.max_iterations;
  solver_options.num_threads = 1;
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);
  result.solver_summary = summary.BriefReport();
  if (!summary.IsSolutionUsable()) {
    throw std::runtime_error("kinematic calibration: the solver failed: " + summary.message);
  }
  add_covariance(problem, x.data(), static_cast<int>(3 * poses.size()), result);
  store_solution(nominal, R0, x, result);
  return result;
}

Eigen::Vector3d predicted_target_m(const KinematicCalibration& calibration, const JointVector& q) {
  return calibration.T_tracker_base *
         (forward_kinematics<double>(calibration.model, q) * calibration.p_H_target_m);
}

std::vector<double> position_errors_m(const KinematicCalibration& calibration,
                                      const std::vector<TrackerPose>& poses) {
  std::vector<double> out;
  for (const TrackerPose& p : poses) {
    out.push_back((predicted_target_m(calibration, p.q_rad) - p.p_tracker_m).norm());
  }
  return out;
}

}  // namespace imscal::calib
