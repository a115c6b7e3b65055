#include "calib/frames_json.hpp"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <nlohmann/json.hpp>
#include <numbers>

#include "calib/calibration_json.hpp"
#include "core/input_error.hpp"
#include "core/input_file.hpp"
#include "core/json_input.hpp"
#include "core/sha256.hpp"
#include "core/units.hpp"
#include "ims/sensor_error_model.hpp"

namespace imscal::calib {
namespace {

using nlohmann::json;

// The bundle's first nine parameters, whose covariance block frames.json must start with.
constexpr std::array<const char*, 9> kFrameParameters = {"R_W_R.east", "R_W_R.north", "R_W_R.up",
                                                         "R_S_H.x",    "R_S_H.y",     "R_S_H.z",
                                                         "p_S_H.x",    "p_S_H.y",     "p_S_H.z"};

// Typed access to one parsed frames.json: every refusal names the file and the JSON path.
class FramesJson {
 public:
  FramesJson(std::string file, json root) : file_(std::move(file)), root_(std::move(root)) {}

  const json& root() const { return root_; }

  [[noreturn]] void refuse(const std::string& field, const std::string& why) const {
    throw InputError(file_, 0, field, why);
  }

  double number(const json& node, const std::string& field) const {
    if (!node.is_number())
      refuse(field, node.is_null() ? std::string("not a finite number (NaN or missing)")
                                   : "not a number: " + node.dump());
    const double v = node.get<double>();
    if (!std::isfinite(v)) refuse(field, "not a finite number");
    return v;
  }

  const json& at(const json& node, const std::string& key, const std::string& field) const {
    if (!node.is_object() || !node.contains(key)) refuse(field, "missing");
    return node[key];
  }

  Eigen::VectorXd vector(const json& node, std::size_t n, const std::string& field) const {
    if (!node.is_array() || node.size() != n)
      refuse(field, fmt::format("not a list of {} numbers", n));
    Eigen::VectorXd v(static_cast<Eigen::Index>(n));
    for (std::size_t k = 0; k < n; ++k)
      v[Eigen::Index(k)] = number(node[k], fmt::format("{}[{}]", field, k));
    return v;
  }

  // frame.quaternion_wxyz as a rotation matrix; a quaternion off unit norm by > 1e-6 is refused
  // (frames.json writes them normalised to double precision).
  Eigen::Matrix3d rotation(const std::string& frame) const {
    const std::string field = frame + ".quaternion_wxyz";
    const Eigen::VectorXd q =
        vector(at(at(root_, frame, frame), "quaternion_wxyz", field), 4, field);
    if (std::abs(q.norm() - 1.0) > 1e-6)
      refuse(field, fmt::format("not a unit quaternion (norm {})", q.norm()));
    return Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized().toRotationMatrix();
  }

 private:
  std::string file_;
  json root_;
};

FramesJson parse(const std::filesystem::path& file) {
  const std::string text = read_input_file(file);
  return FramesJson(file.string(), parse_json_refusing_duplicate_keys(text, file.string()));
}

// The version key and the robot, before anything else: a file of another kind or robot is
// refused for that, not for a field it happens to lack.
std::string checked_robot(const FramesJson& f, const std::string& robot_name) {
  const json& j = f.root();
  if (!j.is_object() || !j.contains("imscal-frames"))
    f.refuse("imscal-frames", "not an imscal frames.json (no 'imscal-frames' version key)");
  if (!(j["imscal-frames"].is_number_integer() && j["imscal-frames"].get<long long>() == 1))
    f.refuse("imscal-frames", fmt::format("unknown format version {} (this imscal reads version 1)",
                                          j["imscal-frames"].dump()));
  if (!j.contains("robot") || !j["robot"].is_string())
    f.refuse("robot",
             "no robot name: the file does not say which robot it was calibrated on (written by "
             "an imscal before --frames existed); recalibrate the frames");
  const std::string robot = j["robot"].get<std::string>();
  if (robot != robot_name)
    f.refuse("robot", fmt::format("the frames are for robot '{}', this record is of robot '{}'",
                                  robot, robot_name));
  return robot;
}

// The covariance of the frames: the first nine parameters, in the bundle's order.
Eigen::Matrix<double, 9, 9> frames_covariance(const FramesJson& f) {
  const json& listed = f.at(f.root(), "parameter_names", "parameter_names");
  for (std::size_t k = 0; k < kFrameParameters.size(); ++k)
    if (!listed.is_array() || listed.size() <= k || listed[k] != kFrameParameters[k])
      f.refuse("parameter_names",
               fmt::format("parameter {} is not '{}': not the bundle's covariance layout", k + 1,
                           kFrameParameters[k]));
  const json& covariance = f.at(f.root(), "covariance_si", "covariance_si");
  const std::size_t n = kFrameParameters.size();
  if (!covariance.is_array() || covariance.size() < n)
    f.refuse("covariance_si", fmt::format("fewer than {} rows", n));
  Eigen::Matrix<double, 9, 9> out;
  for (std::size_t r = 0; r < n; ++r) {
    const std::string row = fmt::format("covariance_si[{}]", r);
    if (!covariance[r].is_array() || covariance[r].size() < n)
      f.refuse(row, fmt::format("fewer than {} columns", n));
    for (std::size_t c = 0; c < n; ++c)
      out(Eigen::Index(r), Eigen::Index(c)) =
          f.number(covariance[r][c], fmt::format("{}[{}]", row, c));
  }
  for (Eigen::Index k = 0; k < 9; ++k)
    if (out(k, k) < 0.0) f.refuse(fmt::format("covariance_si[{}][{}]", k, k), "negative variance");
  return out;
}

// Optional: estimates[].name "link_share (...)" with value[0] and sigma[0].
void read_link_share(const FramesJson& f, SessionFrames& out) {
  const json& j = f.root();
  if (!j.contains("estimates") || !j["estimates"].is_array()) return;
  for (std::size_t k = 0; k < j["estimates"].size(); ++k) {
    const json& e = j["estimates"][k];
    if (!e.is_object() || !e.contains("name") || !e["name"].is_string() ||
        e["name"].get<std::string>().rfind("link_share", 0) != 0)
      continue;
    const std::string field = fmt::format("estimates[{}]", k);
    out.link_share = f.vector(f.at(e, "value", field + ".value"), 1, field + ".value")[0];
    out.link_share_sigma = f.vector(f.at(e, "sigma", field + ".sigma"), 1, field + ".sigma")[0];
    if (!(*out.link_share_sigma > 0.0)) f.refuse(field + ".sigma[0]", "not a positive 1-sigma");
  }
}

json solver_json(const FrameCalibrationResult& result) {
  return {{"converged", result.converged},
          {"iterations", result.iterations},
          {"final_cost", result.final_cost},
          {"brief_report", result.solver_brief_report}};
}

json initial_values_json(const FrameCalibrationResult& result, const FramesJsonContext& context) {
  return {{"T_R_W", pose_json(result.initial_T_R_W)},
          {"T_S_H", pose_json(result.initial_T_S_H)},
          {"time_offset_ms", result.initial_time_offset_s * 1e3},
          {"time_offset_peak_correlation", context.time_offset_peak_correlation}};
}

const json& conventions_and_units() {
  static const json kept = {
      {"conventions",
       {{"transforms", "T_A_B maps coordinates in B into A (p_A = T_A_B p_B)"},
        {"W", "Earth-fixed ENU at the site; origin at the sensor's position at rest 1"},
        {"rpy", "R = Rz(yaw) Ry(pitch) Rx(roll)"},
        {"time_offset", "t_ims = t_robot + time_offset"}}},
      {"units",
       {{"xyz", "mm"},
        {"angles", "deg"},
        {"gyro_bias", "deg/h"},
        {"acc_bias", "ug"},
        {"time_offset", "ms"},
        {"covariance_si", "rad, m, rad/s, m/s^2, s (order of parameter_names)"}}}};
  return kept;
}

// With a heading reference: the base's heading with it, the reference, and the IMS alone's.
json heading_json(const HeadingEstimate& h) {
  const HeadingReference& reference = *h.reference;
  return {
      {"yaw_deg", h.yaw_rad / kRadPerDeg},
      {"sigma_deg", h.sigma_rad / kRadPerDeg},
      {"reference",
       {{"yaw_deg", reference.yaw_rad / kRadPerDeg},
        {"sigma_deg", reference.sigma_rad / kRadPerDeg},
        {"source", reference.source}}},
      {"ims_only",
       {{"yaw_deg", h.ims_only_yaw_rad / kRadPerDeg},
        {"sigma_deg", std::isfinite(h.ims_only_sigma_rad) ? json(h.ims_only_sigma_rad / kRadPerDeg)
                                                          : json(nullptr)}}}};
}

}  // namespace

json frames_json(const FrameCalibrationResult& result, const FramesJsonContext& context) {
  json estimates = json::array();
  for (const auto& e : result.estimates) estimates.push_back(estimate_json(e));
  json weak = json::array();
  for (const auto& w : result.weak_directions) weak.push_back(weak_json(w));
  json out = {{"imscal-frames", 1},
              {"created_by", context.created_by},
              {"robot", context.robot},
              {"frames_from", context.frames_from},
              {"conventions", conventions_and_units()["conventions"]},
              {"units", conventions_and_units()["units"]},
              {"T_R_W", pose_json(result.T_R_W)},
              {"T_S_H", pose_json(result.T_S_H)},
              {"gyro_bias_deg_per_h", vector_json(result.biases.gyro_rad_s, 3600.0 / kRadPerDeg)},
              {"acc_bias_ug", vector_json(result.biases.acc_m_s2, 1e6 / kStandardGravity_m_s2)},
              {"time_offset_ms", result.time_offset_s * 1e3},
              {"gyro_scale_factor_ppm", vector_json(result.gyro_scale_factor, 1e6)},
              {"acc_scale_factor_ppm", vector_json(result.acc_scale_factor, 1e6)},
              {"estimates", estimates},
              {"parameter_names", result.parameter_names},
              {"covariance_si", matrix_json(result.covariance)},
              {"correlation", matrix_json(result.correlation)},
              {"covariance_rank_deficient", result.covariance_rank_deficient},
              {"weak_directions", weak},
              {"solver", solver_json(result)},
              {"initial_values", initial_values_json(result, context)},
              {"rests",
               {{"used", context.rests_used},
                {"rejected", context.rests_rejected},
                {"trimmed", context.rests_trimmed}}},
              {"inputs", context.inputs}};
  // Only with a reference: without one the heading is R_W_R.up's (weak_directions).
  if (result.heading && result.heading->reference)
    out["heading_of_base"] = heading_json(*result.heading);
  return out;
}

SessionFrames read_frames_json(const std::filesystem::path& file, const std::string& robot_name) {
  const FramesJson f = parse(file);
  SessionFrames out;
  out.robot = checked_robot(f, robot_name);
  out.path = file.string();
  out.sha256 = sha256_hex_of_file(file);
  out.frames.source = file.string();
  out.frames.R_W_R = f.rotation("T_R_W").transpose();
  out.frames.T_S_H.linear() = f.rotation("T_S_H");
  out.frames.T_S_H.translation() =
      f.vector(f.at(f.at(f.root(), "T_S_H", "T_S_H"), "xyz_mm", "T_S_H.xyz_mm"), 3,
               "T_S_H.xyz_mm") *
      1e-3;
  out.frames.covariance = frames_covariance(f);
  read_link_share(f, out);
  return out;
}

}  // namespace imscal::calib
