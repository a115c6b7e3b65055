#include "calib/frame_covariance.hpp"

#include <ceres/covariance.h>
#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <utility>

#include "core/units.hpp"
#include "ims/so3.hpp"

namespace imscal::calib {
namespace {

bool try_covariance(ceres::Problem& problem, const std::vector<CovarianceBlock>& blocks,
                    const ceres::Covariance::Options& options, Eigen::MatrixXd* out) {
  ceres::Covariance covariance(options);
  std::vector<const double*> pointers;
  for (const auto& b : blocks) pointers.push_back(b.parameters);
  if (!covariance.Compute(pointers, &problem)) return false;
  int size = 0;
  for (const auto& b : blocks) size += b.tangent_size;
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> m(size, size);
  if (!covariance.GetCovarianceMatrixInTangentSpace(pointers, m.data())) return false;
  *out = m;
  return true;
}

std::string axis_words(const Eigen::Vector3d& axis) {
  return fmt::format("({:.3f}, {:.3f}, {:.3f})", axis.x(), axis.y(), axis.z());
}

}  // namespace

FrameCovariance compute_frame_covariance(ceres::Problem& problem,
                                         const std::vector<CovarianceBlock>& blocks) {
  FrameCovariance out;
  for (const auto& b : blocks) {
    for (const auto& c : b.components) out.parameter_names.push_back(b.name + "." + c);
  }
  Eigen::MatrixXd tangent;
  ceres::Covariance::Options options;
  options.algorithm_type = ceres::SPARSE_QR;
  if (!try_covariance(problem, blocks, options, &tangent)) {
    // Rank deficient (or numerically so): pseudo-inverse.
    ceres::Covariance::Options fallback;
    fallback.algorithm_type = ceres::DENSE_SVD;
    fallback.null_space_rank = -1;
    fallback.min_reciprocal_condition_number = 1e-14;
    if (!try_covariance(problem, blocks, fallback, &tangent)) {
      out.message = "ceres::Covariance failed with SPARSE_QR and with DENSE_SVD";
      return out;
    }
    out.rank_deficient = true;
  }
  Eigen::VectorXd scale(tangent.rows());
  int row = 0;
  for (const auto& b : blocks) {
    for (int k = 0; k < b.tangent_size; ++k) scale[row++] = b.tangent_to_si;
  }
  out.covariance = scale.asDiagonal() * tangent * scale.asDiagonal();
  const Eigen::VectorXd sigma = out.covariance.diagonal().cwiseMax(0.0).cwiseSqrt();
  out.correlation = out.covariance;
  for (int i = 0; i < sigma.size(); ++i) {
    for (int j = 0; j < sigma.size(); ++j) {
      const double d = sigma[i] * sigma[j];
      out.correlation(i, j) = d > 0.0 ? out.covariance(i, j) / d : (i == j ? 1.0 : 0.0);
    }
  }
  out.computed = true;
  return out;
}

std::vector<WeakDirection> describe_weak_directions(
    const FrameCovariance& covariance, int offset_R_W_R, int offset_R_S_H, int offset_p_S_H,
    int offset_dt, bool time_offset_observed, const Eigen::Matrix3d& R_S_H,
    const std::vector<Eigen::Matrix3d>& flange_rotations, const WeakDirectionLimits& limits) {
  std::vector<WeakDirection> out;
  if (covariance.computed) {
    // Heading: the up component of R_W_R's small angles (W = ENU).
    const double heading_sigma =
        std::sqrt(std::max(0.0, covariance.covariance(offset_R_W_R + 2, offset_R_W_R + 2)));
    out.push_back(
        {"heading of R in W (rotation of T_R_W about the vertical): seen only through "
         "the Earth rate (gyrocompassing)",
         heading_sigma * kDegPerRad, "deg",
         "add rest time (sigma falls as 1/sqrt(total rest time)) or use an external "
         "heading reference for the robot base"});
    // T_S_H rotation and translation: eigen-directions above the limits (axes in S).
    auto weak_eigen = [&](int offset, double limit, double to_unit, const char* unit,
                          const char* what, const char* suggestion) {
      const Eigen::Matrix3d block = covariance.covariance.block<3, 3>(offset, offset);
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(block);
      for (int k = 2; k >= 0; --k) {
        const double sigma = std::sqrt(std::max(0.0, eig.eigenvalues()[k]));
        if (sigma <= limit) continue;
        const Eigen::Vector3d axis_S = eig.eigenvectors().col(k);
        const Eigen::Vector3d axis_H = R_S_H.transpose() * axis_S;
        out.push_back({fmt::format("{} along S axis {} (flange axis {})", what, axis_words(axis_S),
                                   axis_words(axis_H)),
                       sigma * to_unit, unit, suggestion});
      }
    };
    weak_eigen(offset_R_S_H, limits.rotation_sigma_rad, kDegPerRad, "deg", "rotation of T_S_H",
               "add poses that turn the flange about this axis");
    weak_eigen(offset_p_S_H, limits.translation_sigma_m, 1e3, "mm", "translation of T_S_H",
               "add motions turning the flange about axes across this direction (lever arm)");
  }
  // Flange rotation axes of the motions between the rests.
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const Eigen::Matrix3d& R : flange_rotations) {
    const Eigen::Vector3d phi = ims::quat_log<double>(Eigen::Quaterniond(R));
    scatter += phi * phi.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(scatter);
  const double largest = eig.eigenvalues()[2];
  for (int k = 0; k < 2; ++k) {
    const double ratio = largest > 0.0 ? eig.eigenvalues()[k] / largest : 0.0;
    if (ratio >= limits.axis_spread_ratio) continue;
    const Eigen::Vector3d axis_H = eig.eigenvectors().col(k);
    out.push_back({fmt::format("the poses hardly turn the flange about its axis {} (rotation "
                               "scatter {:.3g} of the largest): T_S_H's rotation about it and the "
                               "lever arm along it are poorly determined",
                               axis_words(axis_H), ratio),
                   std::sqrt(std::max(0.0, eig.eigenvalues()[k] /
                                               std::max<std::size_t>(1, flange_rotations.size()))) *
                       kDegPerRad,
                   "deg (rms rotation about the axis)",
                   fmt::format("add poses that turn the flange about {} (e.g. with the wrist's "
                               "joints 4 and 5 for axes across the flange, joint 6 for its z axis)",
                               axis_words(axis_H))});
  }
  if (!time_offset_observed) {
    out.push_back(
        {"time offset between robot and IMS clocks: no usable motion (or no robot joint "
         "series) to observe it; held at its initial value",
         0.0, "ms",
         "record the robot joint series and move the flange faster than "
         "the minimum rate"});
  }
  (void)offset_dt;  // dt's sigma is reported with the estimates, not as a weak direction
  if (covariance.rank_deficient) {
    out.push_back(
        {"the covariance is rank deficient: some combination of the unknowns is not "
         "determined by the data (pseudo-inverse used)",
         0.0, "",
         "see the other weak directions; add poses with rotations about all "
         "flange axes"});
  }
  return out;
}

}  // namespace imscal::calib
