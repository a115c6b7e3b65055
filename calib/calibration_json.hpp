#pragma once
// The JSON forms of a calibration's values shared by frames.json and mounting_report.json
// (datasets/FORMAT.md §16): vectors with NaN written as null, poses as xyz in mm with the rotation
// as quaternion, roll/pitch/yaw and rotation vector in degrees, and the way back for the readers.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "calib/frame_calibration.hpp"
#include "core/json_fields.hpp"

namespace imscal::calib {

// Each component times `scale`; a non-finite one as null.
nlohmann::json vector_json(const Eigen::VectorXd& v, double scale = 1.0);
nlohmann::json matrix_json(const Eigen::MatrixXd& m);
// R = Rz(yaw) Ry(pitch) Rx(roll) (as pose_from_xyz_rpy) [rad].
Eigen::Vector3d roll_pitch_yaw(const Eigen::Matrix3d& R);
// {xyz_mm, quaternion_wxyz, rpy_deg, rotation_vector_deg}.
nlohmann::json pose_json(const Eigen::Isometry3d& T);
nlohmann::json estimate_json(const EstimatedVector& e);
nlohmann::json weak_json(const WeakDirection& w);

// A pose written by pose_json, from its xyz_mm and quaternion_wxyz; refuses (naming the field) a
// quaternion off unit norm by more than 1e-6 (they are written normalised to double precision).
Eigen::Isometry3d pose_of(const JsonField& pose);
// `n` numbers (null read as NaN), each divided by `scale`.
Eigen::VectorXd vector_of(const JsonField& field, std::size_t n, double scale = 1.0);
WeakDirection weak_of(const JsonField& field);

}  // namespace imscal::calib
