#include "eval/iso9283_pose.hpp"

#include <Eigen/SVD>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace imscal::eval {
namespace {

// Rotation vector of R_attained R_commandedᵀ: the deviation about the base axes.
Eigen::Vector3d attitude_deviation(const Eigen::Matrix3d& commanded,
                                   const Eigen::Matrix3d& attained) {
  const Eigen::AngleAxisd deviation(attained * commanded.transpose());
  return deviation.angle() * deviation.axis();
}

}  // namespace

Iso9283PoseResult iso9283_pose(const Eigen::Isometry3d& commanded,
                               const std::vector<Eigen::Isometry3d>& attained) {
  if (attained.empty()) throw std::invalid_argument("iso9283_pose: no attained pose");
  const auto n = static_cast<double>(attained.size());
  Iso9283PoseResult r;
  r.cycles = static_cast<int>(attained.size());
  std::vector<Eigen::Vector3d> abc;
  for (const Eigen::Isometry3d& x : attained) {
    r.barycentre_m += x.translation() / n;
    abc.push_back(attitude_deviation(commanded.linear(), x.linear()));
    r.AP_abc_rad += abc.back() / n;
  }
  r.AP_xyz_m = r.barycentre_m - commanded.translation();
  r.AP_p_m = r.AP_xyz_m.norm();
  if (attained.size() < 2) {
    r.RP_l_m = std::numeric_limits<double>::quiet_NaN();
    r.RP_abc_rad.setConstant(std::numeric_limits<double>::quiet_NaN());
    return r;
  }
  std::vector<double> l;
  double l_mean = 0.0;
  for (const Eigen::Isometry3d& x : attained) {
    l.push_back((x.translation() - r.barycentre_m).norm());
    l_mean += l.back() / n;
  }
  double l_square_sum = 0.0;
  Eigen::Vector3d abc_square_sum = Eigen::Vector3d::Zero();
  for (std::size_t j = 0; j < attained.size(); ++j) {
    l_square_sum += (l[j] - l_mean) * (l[j] - l_mean);
    abc_square_sum += (abc[j] - r.AP_abc_rad).cwiseAbs2();
  }
  r.RP_l_m = l_mean + 3.0 * std::sqrt(l_square_sum / (n - 1.0));
  r.RP_abc_rad = 3.0 * (abc_square_sum / (n - 1.0)).cwiseSqrt();
  return r;
}

std::vector<std::vector<std::size_t>> group_repeated_poses(
    const std::vector<Eigen::Isometry3d>& commanded, double position_tolerance_m,
    double angle_tolerance_rad) {
  std::vector<std::vector<std::size_t>> groups;
  for (std::size_t k = 0; k < commanded.size(); ++k) {
    bool placed = false;
    for (auto& group : groups) {
      const Eigen::Isometry3d& first = commanded[group.front()];
      const double gap_m = (commanded[k].translation() - first.translation()).norm();
      const double angle_rad =
          Eigen::AngleAxisd(first.linear().transpose() * commanded[k].linear()).angle();
      if (gap_m <= position_tolerance_m && angle_rad <= angle_tolerance_rad) {
        group.push_back(k);
        placed = true;
        break;
      }
    }
    if (!placed) groups.push_back({k});
  }
  return groups;
}

std::vector<Eigen::Isometry3d> register_to_commanded(
    const std::vector<Eigen::Isometry3d>& commanded,
    const std::vector<Eigen::Isometry3d>& measured) {
  if (commanded.size() != measured.size() || commanded.size() < 3) {
    throw std::invalid_argument("register_to_commanded: need >= 3 pairs of poses");
  }
  const auto n = static_cast<Eigen::Index>(commanded.size());
  Eigen::Matrix3Xd from(3, n), to(3, n);
  for (Eigen::Index k = 0; k < n; ++k) {
    from.col(k) = measured[k].translation();
    to.col(k) = commanded[k].translation();
  }
  Eigen::Isometry3d T_base_measuring(Eigen::umeyama(from, to, false));
  Eigen::Matrix3d sum = Eigen::Matrix3d::Zero();
  for (Eigen::Index k = 0; k < n; ++k) {
    sum += (T_base_measuring.linear() * measured[k].linear()).transpose() * commanded[k].linear();
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(sum, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d R_offset = svd.matrixU() * svd.matrixV().transpose();
  if (R_offset.determinant() < 0.0) {
    Eigen::Matrix3d flip = Eigen::Matrix3d::Identity();
    flip(2, 2) = -1.0;
    R_offset = svd.matrixU() * flip * svd.matrixV().transpose();
  }
  std::vector<Eigen::Isometry3d> out;
  for (const Eigen::Isometry3d& m : measured) {
    Eigen::Isometry3d attained = T_base_measuring * m;
    attained.linear() = attained.linear() * R_offset;
    out.push_back(attained);
  }
  return out;
}

}  // namespace imscal::eval
