#include "calib/calibration_json.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/units.hpp"
#include "ims/so3.hpp"

namespace imscal::calib {

using nlohmann::json;

namespace {}  // namespace

json vector_json(const Eigen::VectorXd& v, double scale) {
  json a = json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i)
    a.push_back(std::isfinite(v[i]) ? json(v[i] * scale) : json(nullptr));
  return a;
}

json matrix_json(const Eigen::MatrixXd& m) {
  json rows = json::array();
  for (Eigen::Index r = 0; r < m.rows(); ++r) rows.push_back(vector_json(m.row(r).transpose()));
  return rows;
}

Eigen::Vector3d roll_pitch_yaw(const Eigen::Matrix3d& R) {
  const double pitch = std::asin(std::clamp(-R(2, 0), -1.0, 1.0));
  return {std::atan2(R(2, 1), R(2, 2)), pitch, std::atan2(R(1, 0), R(0, 0))};
}

json pose_json(const Eigen::Isometry3d& T) {
  const Eigen::Quaterniond q(T.linear());
  return {{"xyz_mm", vector_json(T.translation(), 1e3)},
          {"quaternion_wxyz", {q.w(), q.x(), q.y(), q.z()}},
          {"rpy_deg", vector_json(roll_pitch_yaw(T.linear()), 1.0 / kRadPerDeg)},
          {"rotation_vector_deg", vector_json(ims::quat_log<double>(q), 1.0 / kRadPerDeg)}};
}

json estimate_json(const EstimatedVector& e) {
  return {{"name", e.name},
          {"unit", e.unit},
          {"components", e.components},
          {"value", vector_json(e.value)},
          {"sigma", vector_json(e.sigma)}};
}

json weak_json(const WeakDirection& w) {
  return {{"description", w.description},
          {"sigma", w.sigma},
          {"unit", w.unit},
          {"suggestion", w.suggestion}};
}

Eigen::VectorXd vector_of(const JsonField& field, std::size_t n, double scale) {
  if (field.size() != n) field.refuse(fmt::format("not a list of {} numbers", n));
  const std::vector<double> values = field.numbers_or_nan();
  Eigen::VectorXd v(static_cast<Eigen::Index>(n));
  for (std::size_t k = 0; k < n; ++k) v[Eigen::Index(k)] = values[k] / scale;
  return v;
}

Eigen::Isometry3d pose_of(const JsonField& pose) {
  const JsonField quaternion = pose["quaternion_wxyz"];
  if (quaternion.size() != 4) quaternion.refuse("not a list of 4 numbers");
  const std::vector<double> q = quaternion.numbers();
  const Eigen::Quaterniond rotation(q[0], q[1], q[2], q[3]);
  if (std::abs(rotation.norm() - 1.0) > 1e-6)
    quaternion.refuse(fmt::format("not a unit quaternion (norm {})", rotation.norm()));
  const JsonField xyz = pose["xyz_mm"];
  if (xyz.size() != 3) xyz.refuse("not a list of 3 numbers");
  const std::vector<double> p = xyz.numbers();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = rotation.normalized().toRotationMatrix();
  T.translation() = Eigen::Vector3d(p[0], p[1], p[2]) * 1e-3;
  return T;
}

WeakDirection weak_of(const JsonField& field) {
  return {field["description"].text(), field["sigma"].number_or_nan(), field["unit"].text(),
          field["suggestion"].text()};
}

}  // namespace imscal::calib
