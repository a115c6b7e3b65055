#include "eval/gap_measurement_prior.hpp"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <sstream>

#include "core/input_error.hpp"
#include "core/json_fields.hpp"
#include "ident/joint_error_io.hpp"

namespace imscal::eval {

const std::array<const char*, kMeasurementParameterCount> kMeasurementParameterNames = {
    "mount_t_x_m",       "mount_t_y_m",        "mount_t_z_m",        "mount_r_x_rad",
    "mount_r_y_rad",     "mount_r_z_rad",      "gyro_bias_x_rad_s",  "gyro_bias_y_rad_s",
    "gyro_bias_z_rad_s", "world_rate_x_rad_s", "world_rate_y_rad_s", "world_rate_z_rad_s",
    "clock_offset_s",    "windup_scale_A1",    "windup_scale_A2",    "windup_scale_A3",
    "windup_scale_A4",   "windup_scale_A5",    "windup_scale_A6",    "play_scale_A1",
    "play_scale_A2",     "play_scale_A3",      "play_scale_A4",      "play_scale_A5",
    "play_scale_A6"};

namespace {

// The Earth's rotation rate [rad/s] (WGS84).
constexpr double kEarthRateRadS = 7.292115e-5;

// The index of `name` in frames.json's parameter_names; none when absent.
std::optional<std::size_t> find_frames_index(const JsonField& names, const std::string& name) {
  for (std::size_t k = 0; k < names.size(); ++k)
    if (names[k].text() == name) return k;
  return std::nullopt;
}

// The same, refused when absent.
std::size_t frames_index(const JsonField& names, const std::string& name) {
  if (const auto k = find_frames_index(names, name)) return *k;
  names.refuse(fmt::format("no parameter '{}' (not calibrate's covariance layout)", name));
}

}  // namespace

std::string noise_floor_header_value(std::span<const double> floor_rad) {
  std::string value;
  for (std::size_t j = 0; j < floor_rad.size(); ++j)
    value += fmt::format("{}{:.6g}", j ? "," : "", floor_rad[j]);
  return value;
}

std::vector<double> noise_floor_from_log(const ident::JointErrorLog& log, const std::string& file) {
  for (const auto& [key, value] : log.metadata) {
    if (key != kNoiseFloorKey) continue;
    std::vector<double> floor;
    std::stringstream in(value);
    std::string item;
    while (std::getline(in, item, ',')) {
      char* end = nullptr;
      const double v = std::strtod(item.c_str(), &end);
      if (end == item.c_str() || *end != '\0' || !std::isfinite(v) || v <= 0.0)
        throw InputError(file, 0, key, fmt::format("'{}' is not a positive number [rad]", item));
      floor.push_back(v);
    }
    if (floor.size() != log.joint_count())
      throw InputError(file, 0, key,
                       fmt::format("{} numbers for {} joints", floor.size(), log.joint_count()));
    return floor;
  }
  return {};
}

Eigen::MatrixXd chain_covariance_from_frames(const std::filesystem::path& frames_json,
                                             const std::vector<std::string>& joint_names) {
  const JsonDocument doc = read_json_document(frames_json);
  doc.check_version("imscal-frames", 1, "a frames.json of imscal calibrate");
  const JsonField root = doc.root();
  const JsonField names = root["parameter_names"];
  const JsonField covariance = root["covariance_si"];
  const std::vector<double> q = root["T_S_H"]["quaternion_wxyz"].numbers();
  if (q.size() != 4) root["T_S_H"]["quaternion_wxyz"].refuse("not 4 numbers");
  const Eigen::Matrix3d R_H_S =
      Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized().toRotationMatrix().transpose();
  const auto block = [&](const std::string& prefix, const char* a, const char* b, const char* c) {
    return std::array<std::size_t, 3>{frames_index(names, prefix + a),
                                      frames_index(names, prefix + b),
                                      frames_index(names, prefix + c)};
  };
  const auto p = block("p_S_H.", "x", "y", "z"), r = block("R_S_H.", "x", "y", "z"),
             bias = block("gyro_bias.", "x", "y", "z"),
             base = block("R_W_R.", "east", "north", "up");
  const std::size_t dt = frames_index(names, "time_offset.dt");
  const std::size_t n = names.size();
  if (covariance.size() != n) covariance.refuse(fmt::format("not {} rows", n));
  Eigen::MatrixXd C = Eigen::MatrixXd::Zero(Eigen::Index(n), Eigen::Index(n));
  for (std::size_t i = 0; i < n; ++i) {
    const std::vector<double> row = covariance[i].numbers();
    if (row.size() != n) covariance[i].refuse(fmt::format("not {} columns", n));
    for (std::size_t k = 0; k < n; ++k) C(Eigen::Index(i), Eigen::Index(k)) = row[k];
  }
  // The budget's parameters as a linear map of the frames' tangent vector.
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(kMeasurementParameterCount, Eigen::Index(n));
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) {
      M(a, Eigen::Index(p[std::size_t(b)])) = R_H_S(a, b);
      M(3 + a, Eigen::Index(r[std::size_t(b)])) = R_H_S(a, b);
      M(6 + a, Eigen::Index(bias[std::size_t(b)])) = R_H_S(a, b);
    }
  M(12, Eigen::Index(dt)) = 1.0;
  // The first rest's deflection only where it was the record's one rest: several rests at other
  // poses tie the deflection's split to the tilts they see, one rest does not (the chain's error
  // then reaches ~0.13 of the wind-up on A3 and A5; the scales keep their prior of 1-sigma 1 in
  // that direction either way, so their covariance overstates what several rests leave).
  const auto rests = root.optional("rests");
  const auto used = rests ? rests->optional("used") : std::nullopt;
  const bool one_rest = used && used->count() <= 1;
  for (std::size_t j = 0; one_rest && j < joint_names.size() && j < 6; ++j) {
    const auto w = find_frames_index(names, "windup_scale_deviation." + joint_names[j]);
    const auto p_j = find_frames_index(names, "play_scale_deviation." + joint_names[j]);
    if (w) M(kFirstDeflectionParameter + Eigen::Index(j), Eigen::Index(*w)) = 1.0;
    if (p_j) M(kFirstDeflectionParameter + 6 + Eigen::Index(j), Eigen::Index(*p_j)) = 1.0;
  }
  Eigen::MatrixXd P = M * C * M.transpose();
  double base_trace = 0.0;
  for (std::size_t i : base) base_trace += C(Eigen::Index(i), Eigen::Index(i));
  for (int a = 0; a < 3; ++a) P(9 + a, 9 + a) = kEarthRateRadS * kEarthRateRadS * base_trace / 3.0;
  for (Eigen::Index i = 0; i < P.rows(); ++i)
    if (!std::isfinite(P(i, i)) || P(i, i) < 0.0)
      covariance.refuse(fmt::format("the variance of {} is not a finite non-negative number",
                                    kMeasurementParameterNames[std::size_t(i)]));
  return P;
}

}  // namespace imscal::eval
