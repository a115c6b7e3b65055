#include "calib/hand_eye.hpp"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <utility>

#include "ims/so3.hpp"

namespace imscal::calib {
namespace {

using Vector4 = Eigen::Vector4d;  // quaternion as (w, x, y, z)
using Matrix4 = Eigen::Matrix4d;

// q (x) p = left(q) p  and  p (x) q = right(q) p, quaternions as (w, x, y, z).
Matrix4 left_product(const Eigen::Quaterniond& q) {
  Matrix4 m;
  m << q.w(), -q.x(), -q.y(), -q.z(),  //
      q.x(), q.w(), -q.z(), q.y(),     //
      q.y(), q.z(), q.w(), -q.x(),     //
      q.z(), -q.y(), q.x(), q.w();
  return m;
}
Matrix4 right_product(const Eigen::Quaterniond& q) {
  Matrix4 m;
  m << q.w(), -q.x(), -q.y(), -q.z(),  //
      q.x(), q.w(), q.z(), -q.y(),     //
      q.y(), -q.z(), q.w(), q.x(),     //
      q.z(), q.y(), -q.x(), q.w();
  return m;
}

Eigen::Quaterniond positive_scalar(const Eigen::Matrix3d& rotation) {
  Eigen::Quaterniond q(rotation);
  q.normalize();
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();
  return q;
}

double rotation_angle(const Eigen::Matrix3d& rotation) {
  return ims::quat_log(Eigen::Quaterniond(rotation).normalized()).norm();
}

std::string axis_text(const Eigen::Vector3d& axis) {
  return fmt::format("({:.3f}, {:.3f}, {:.3f})", axis.x(), axis.y(), axis.z());
}

std::vector<std::string> single_axis_directions(const Eigen::Vector3d& axis_S) {
  return {fmt::format("rotation of S_T_H about the S axis {} (and with it of T_R_W)",
                      axis_text(axis_S)),
          fmt::format("translation of S_T_H along the S axis {} (and with it of T_R_W)",
                      axis_text(axis_S))};
}

void check_rotation(const Eigen::Isometry3d& pose, const std::string& source,
                    const std::string& field) {
  const Eigen::Matrix3d& r = pose.linear();
  // 1e-6: rotations from FK and navigation are orthonormal to ~1e-15; anything worse is not a
  // rotation matrix (a scaled or sheared input), not round-off.
  if (!r.allFinite() || !pose.translation().allFinite() ||
      (r.transpose() * r - Eigen::Matrix3d::Identity()).norm() > 1e-6 || r.determinant() < 0.0) {
    throw InputError(source, 0, field, "is not a rigid transform (rotation not orthonormal)");
  }
}

// Weighted residuals of all poses for Z, X: per pose log(R_A^T R_Z R_B R_X) / sigma_att and
// (Z B X).t - A.t over sigma_pos.
Eigen::VectorXd weighted_residuals(const std::vector<Eigen::Isometry3d>& T_R_H,
                                   const std::vector<Eigen::Isometry3d>& T_W_S,
                                   const Eigen::Isometry3d& Z, const Eigen::Isometry3d& X,
                                   const HandEyeOptions& options) {
  Eigen::VectorXd r(6 * T_R_H.size());
  for (std::size_t i = 0; i < T_R_H.size(); ++i) {
    const Eigen::Isometry3d predicted = Z * T_W_S[i] * X;
    const auto row = static_cast<Eigen::Index>(6 * i);
    r.segment<3>(row) =
        ims::quat_log(
            Eigen::Quaterniond(T_R_H[i].linear().transpose() * predicted.linear()).normalized()) /
        options.attitude_sigma_rad;
    r.segment<3>(row + 3) =
        (predicted.translation() - T_R_H[i].translation()) / options.position_sigma_m;
  }
  return r;
}

// Z, X moved by delta = (rotation Z, translation Z, rotation X, translation X); rotations applied
// on the right: R <- R exp(phi).
void apply_step(const Eigen::Matrix<double, 12, 1>& delta, Eigen::Isometry3d& Z,
                Eigen::Isometry3d& X) {
  Z.linear() = Z.linear() * ims::quat_exp(Eigen::Vector3d(delta.segment<3>(0))).toRotationMatrix();
  Z.translation() += delta.segment<3>(3);
  X.linear() = X.linear() * ims::quat_exp(Eigen::Vector3d(delta.segment<3>(6))).toRotationMatrix();
  X.translation() += delta.segment<3>(9);
}

// Gauss-Newton with a central-difference Jacobian (12 columns: cheap, and its accuracy only
// affects the convergence rate, not the point converged to). Returns the iterations taken.
int refine_jointly(const std::vector<Eigen::Isometry3d>& T_R_H,
                   const std::vector<Eigen::Isometry3d>& T_W_S, const HandEyeOptions& options,
                   Eigen::Isometry3d& Z, Eigen::Isometry3d& X) {
  // Steps: 1e-7 rad and 1e-7 m keep truncation (~1e-14 relative) and round-off (~1e-9
  // relative) of the differences small.
  constexpr double kStep = 1e-7;
  int iterations = 0;
  for (; iterations < options.max_gauss_newton_iterations; ++iterations) {
    const Eigen::VectorXd r0 = weighted_residuals(T_R_H, T_W_S, Z, X, options);
    Eigen::MatrixXd jacobian(r0.size(), 12);
    for (int k = 0; k < 12; ++k) {
      Eigen::Matrix<double, 12, 1> delta = Eigen::Matrix<double, 12, 1>::Zero();
      delta(k) = kStep;
      Eigen::Isometry3d z_plus = Z, x_plus = X, z_minus = Z, x_minus = X;
      apply_step(delta, z_plus, x_plus);
      apply_step(-delta, z_minus, x_minus);
      jacobian.col(k) = (weighted_residuals(T_R_H, T_W_S, z_plus, x_plus, options) -
                         weighted_residuals(T_R_H, T_W_S, z_minus, x_minus, options)) /
                        (2.0 * kStep);
    }
    const Eigen::Matrix<double, 12, 12> normal = jacobian.transpose() * jacobian;
    const Eigen::Matrix<double, 12, 1> step = normal.ldlt().solve(-jacobian.transpose() * r0);
    if (!step.allFinite()) break;
    apply_step(step, Z, X);
    // 1e-13 rad / m: far below any noise, at the level of round-off in the poses.
    if (step.norm() < 1e-13) {
      ++iterations;
      break;
    }
  }
  return iterations;
}

}  // namespace

HandEyeUnobservable::HandEyeUnobservable(const std::string& source, const std::string& problem,
                                         std::vector<std::string> missing_directions)
    : InputError(source, 0, "poses",
                 [&] {
                   std::string text = problem + "; undetermined:";
                   for (const auto& d : missing_directions) text += " [" + d + "]";
                   return text;
                 }()),
      missing_directions_(std::move(missing_directions)) {}

Eigen::Matrix3d nearest_rotation(const Eigen::Matrix3d& m) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(m, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
  d(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0.0 ? -1.0 : 1.0;
  return svd.matrixU() * d * svd.matrixV().transpose();
}

HandEyeResult solve_robot_world_hand_eye(const std::vector<Eigen::Isometry3d>& T_R_H,
                                         const std::vector<Eigen::Isometry3d>& T_W_S,
                                         const HandEyeOptions& options) {
  const std::string& source = options.source;
  if (T_R_H.size() != T_W_S.size()) {
    throw InputError(source, 0, "poses",
                     fmt::format("{} robot poses but {} IMS poses; they must pair up", T_R_H.size(),
                                 T_W_S.size()));
  }
  const std::size_t n = T_R_H.size();
  for (std::size_t i = 0; i < n; ++i) {
    check_rotation(T_R_H[i], source, fmt::format("T_R_H[{}]", i));
    check_rotation(T_W_S[i], source, fmt::format("T_W_S[{}]", i));
  }
  if (n < 2) {
    throw HandEyeUnobservable(
        source,
        fmt::format("{} pose(s) given; at least 3 poses (2 relative rotations about different "
                    "axes) are needed",
                    n),
        {"rotation of S_T_H and T_R_W about all three axes",
         "translation of S_T_H and T_R_W in all three directions"});
  }

  HandEyeResult result;
  // 1. Relative motions -> R_H_S (q_Y) from q_A_ij q_Y = q_Y q_B_ij.
  Matrix4 normal = Matrix4::Zero();
  Eigen::Matrix3d axis_scatter = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) {
      const Eigen::Matrix3d a_ij = T_R_H[i].linear().transpose() * T_R_H[j].linear();
      const Eigen::Matrix3d b_ij = T_W_S[i].linear().transpose() * T_W_S[j].linear();
      const Eigen::Quaterniond q_a = positive_scalar(a_ij);
      const Eigen::Quaterniond q_b = positive_scalar(b_ij);
      const double angle_a = rotation_angle(a_ij);
      const double angle_b = rotation_angle(b_ij);
      if (std::min(angle_a, angle_b) < options.min_relative_rotation_rad) {
        result.dropped_motions.push_back({i, j, angle_a, angle_b});
        continue;
      }
      const Matrix4 m = left_product(q_a) - right_product(q_b);
      normal += m.transpose() * m;
      const Eigen::Vector3d axis_S = ims::quat_log(q_b).normalized();
      axis_scatter += axis_S * axis_S.transpose();
      ++result.used_motion_count;
    }
  }
  if (result.used_motion_count == 0) {
    throw HandEyeUnobservable(
        source,
        fmt::format("no relative motion among the {} poses rotates by {:.3f} deg or more (the "
                    "poses are nearly identical in orientation); add poses rotated about all "
                    "three axes",
                    n, options.min_relative_rotation_rad * 180.0 / M_PI),
        {"rotation of S_T_H and T_R_W about all three axes",
         "translation of S_T_H and T_R_W in all three directions"});
  }
  axis_scatter /= static_cast<double>(result.used_motion_count);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> scatter_eigen(axis_scatter);
  result.axis_scatter_eigenvalues = scatter_eigen.eigenvalues();
  const double spread_rad =
      std::asin(std::sqrt(std::max(0.0, result.axis_scatter_eigenvalues(1)) /
                          std::max(result.axis_scatter_eigenvalues(2), 1e-300)));
  if (n < 3 || spread_rad < options.min_axis_spread_rad) {
    const Eigen::Vector3d axis_S = scatter_eigen.eigenvectors().col(2);
    throw HandEyeUnobservable(
        source,
        fmt::format("{} poses, {} relative motions kept: all rotate about nearly one S axis {} "
                    "(spread {:.4f} deg, at least {:.4f} deg needed){}; add poses rotated about "
                    "an axis perpendicular to it",
                    n, result.used_motion_count, axis_text(axis_S), spread_rad * 180.0 / M_PI,
                    options.min_axis_spread_rad * 180.0 / M_PI,
                    n < 3 ? " and at least 3 poses are needed" : ""),
        single_axis_directions(axis_S));
  }
  const Eigen::SelfAdjointEigenSolver<Matrix4> normal_eigen(normal);
  const Vector4 q_y = normal_eigen.eigenvectors().col(0);
  const Eigen::Matrix3d R_H_S =
      Eigen::Quaterniond(q_y(0), q_y(1), q_y(2), q_y(3)).normalized().toRotationMatrix();

  // 2. R_Z from the absolute poses, then alternating chordal means.
  Eigen::Matrix3d R_X = R_H_S.transpose();
  auto mean_Z = [&](const Eigen::Matrix3d& r_x) {
    Eigen::Matrix3d sum = Eigen::Matrix3d::Zero();
    for (std::size_t i = 0; i < n; ++i) {
      sum += T_R_H[i].linear() * r_x.transpose() * T_W_S[i].linear().transpose();
    }
    return nearest_rotation(sum);
  };
  auto mean_X = [&](const Eigen::Matrix3d& r_z) {
    Eigen::Matrix3d sum = Eigen::Matrix3d::Zero();
    for (std::size_t i = 0; i < n; ++i) {
      sum += T_W_S[i].linear().transpose() * r_z.transpose() * T_R_H[i].linear();
    }
    return nearest_rotation(sum);
  };
  Eigen::Matrix3d R_Z = mean_Z(R_X);
  for (int iteration = 0; iteration < options.max_refinement_iterations; ++iteration) {
    const Eigen::Matrix3d next_X = mean_X(R_Z);
    const Eigen::Matrix3d next_Z = mean_Z(next_X);
    const double change = std::max(rotation_angle(R_X.transpose() * next_X),
                                   rotation_angle(R_Z.transpose() * next_Z));
    R_X = next_X;
    R_Z = next_Z;
    result.refinement_iterations = iteration + 1;
    if (change <= options.refinement_tolerance_rad) break;
  }

  // 3. Translations: t_A_i - R_Z t_B_i = t_Z + R_Z R_B_i t_X.
  Eigen::MatrixXd design(3 * n, 6);
  Eigen::VectorXd rhs(3 * n);
  for (std::size_t i = 0; i < n; ++i) {
    const auto rows = static_cast<Eigen::Index>(3 * i);
    design.block<3, 3>(rows, 0).setIdentity();
    design.block<3, 3>(rows, 3) = R_Z * T_W_S[i].linear();
    rhs.segment<3>(rows) = T_R_H[i].translation() - R_Z * T_W_S[i].translation();
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(design, Eigen::ComputeThinU | Eigen::ComputeThinV);
  // JacobiSVD sorts descending; the result holds them ascending.
  result.translation_singular_values = svd.singularValues().reverse() / std::sqrt(double(n));
  if (result.translation_singular_values(0) < options.min_translation_singular_value) {
    const Eigen::Vector3d d_x = svd.matrixV().col(5).tail<3>();
    const Eigen::Vector3d axis_S =
        d_x.norm() > 1e-9 ? Eigen::Vector3d(d_x.normalized()) : Eigen::Vector3d::UnitX();
    throw HandEyeUnobservable(
        source,
        fmt::format("the translations are not determined (smallest scaled singular value {:.3g} "
                    "< {:.3g}); add poses rotated about an axis perpendicular to S axis {}",
                    result.translation_singular_values(0), options.min_translation_singular_value,
                    axis_text(axis_S)),
        {fmt::format("translation of S_T_H along the S axis {} (and with it of T_R_W)",
                     axis_text(axis_S))});
  }
  const Eigen::Matrix<double, 6, 1> t = svd.solve(rhs);
  result.T_R_W.linear() = R_Z;
  result.T_R_W.translation() = t.head<3>();
  result.T_S_H.linear() = R_X;
  result.T_S_H.translation() = t.tail<3>();

  // 4. Joint weighted refinement.
  if (options.joint_refinement && options.max_gauss_newton_iterations > 0) {
    if (!(options.attitude_sigma_rad > 0.0) || !(options.position_sigma_m > 0.0)) {
      throw InputError(source, 0, "attitude_sigma_rad/position_sigma_m",
                       "the noise levels weighting the refinement must be positive");
    }
    result.gauss_newton_iterations =
        refine_jointly(T_R_H, T_W_S, options, result.T_R_W, result.T_S_H);
  }

  // 5. Residuals.
  double rotation_sq = 0.0;
  double translation_sq = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Isometry3d predicted = result.T_R_W * T_W_S[i] * result.T_S_H;
    HandEyePoseResidual r;
    r.rotation_rad = rotation_angle(T_R_H[i].linear().transpose() * predicted.linear());
    r.translation_m = (T_R_H[i].translation() - predicted.translation()).norm();
    rotation_sq += r.rotation_rad * r.rotation_rad;
    translation_sq += r.translation_m * r.translation_m;
    result.residuals.push_back(r);
  }
  result.rms_rotation_residual_rad = std::sqrt(rotation_sq / double(n));
  result.rms_translation_residual_m = std::sqrt(translation_sq / double(n));
  return result;
}

}  // namespace imscal::calib
