#include "eval/transmission_error_gear_mode.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <stdexcept>

#include "ident/identify_joints.hpp"
#include "sim/rigid_body_dynamics.hpp"

namespace imscal::eval {

namespace {

constexpr std::size_t kInertiaStride = 10;  // samples; M changes with the pose, slowly
// The data's stiffness is taken where it stands > 4σ from zero and within this factor of the
// nominal robot's (a real gear's stiffness is within ±30 % of its data sheet).
constexpr double kMinDataSignificance = 4.0;
constexpr double kMaxFactorFromNominal = 2.0;

double median(std::vector<double> values) {
  if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
  const auto middle = values.begin() + std::ptrdiff_t(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

}  // namespace

std::vector<double> median_link_inertia_kg_m2(const ident::JointErrorLog& log,
                                              const ModelTorqueSource& model,
                                              double min_speed_rad_s) {
  if (log.joint_count() != std::size_t(calib::kJointCount))
    throw std::invalid_argument("median_link_inertia_kg_m2: the log needs the robot's 6 joints");
  sim::RigidBodyDynamics dynamics(model.robot, std::nullopt, Eigen::Vector3d::Zero());
  double payload_kg = -1.0;
  std::vector<std::vector<double>> moving(calib::kJointCount), all(calib::kJointCount);
  for (const auto& [begin, end] : log.segments())
    for (std::size_t k = begin + 1; k < end; k += kInertiaStride) {
      const double mass_kg = log.payload_kg[k];
      if (mass_kg != payload_kg) {
        payload_kg = mass_kg;
        std::optional<calib::RigidBodyParameters> body;
        if (mass_kg > 0.0) {
          calib::RigidBodyParameters point_mass;  // at T's origin, as eval/model_torque.hpp's
          point_mass.mass_kg = mass_kg;
          body = point_mass;
        }
        dynamics.set_payload(body);
      }
      calib::JointVector q;
      for (int j = 0; j < calib::kJointCount; ++j) q(j) = log.q_desired_rad[std::size_t(j)][k];
      const sim::JointMatrix m = dynamics.mass_matrix(q);
      for (int j = 0; j < calib::kJointCount; ++j) {
        const auto& x = log.q_desired_rad[std::size_t(j)];
        const double speed = (x[k] - x[k - 1]) / log.cycle_s;
        all[std::size_t(j)].push_back(m(j, j));
        if (std::abs(speed) > min_speed_rad_s) moving[std::size_t(j)].push_back(m(j, j));
      }
    }
  std::vector<double> inertia;
  for (int j = 0; j < calib::kJointCount; ++j)
    inertia.push_back(
        median(moving[std::size_t(j)].empty() ? all[std::size_t(j)] : moving[std::size_t(j)]));
  return inertia;
}

JointGearMode gear_mode_of(double inertia_kg_m2, double data_stiffness_nm_per_rad,
                           double data_stiffness_sigma_nm_per_rad,
                           const calib::DriveParameters& nominal_drive) {
  JointGearMode mode;
  mode.inertia_kg_m2 = inertia_kg_m2;
  mode.data_stiffness_nm_per_rad = data_stiffness_nm_per_rad;
  mode.data_stiffness_sigma_nm_per_rad = data_stiffness_sigma_nm_per_rad;
  const double nominal_k = nominal_drive.stiffness_nm_per_rad;
  if (!(inertia_kg_m2 > 0.0) || !(nominal_k > 0.0)) return mode;  // a rigid drive: no mode
  const double k = data_stiffness_nm_per_rad;
  mode.stiffness_from_data = k > kMinDataSignificance * data_stiffness_sigma_nm_per_rad &&
                             k < kMaxFactorFromNominal * nominal_k &&
                             k > nominal_k / kMaxFactorFromNominal;
  mode.stiffness_nm_per_rad = mode.stiffness_from_data ? k : nominal_k;
  mode.damping_ratio =
      nominal_drive.damping_nm_s_per_rad / (2.0 * std::sqrt(nominal_k * inertia_kg_m2));
  if (!(mode.damping_ratio > 0.0)) return mode;  // an undamped nominal drive: no prior
  mode.natural_frequency_rad_s = std::sqrt(mode.stiffness_nm_per_rad / inertia_kg_m2);
  return mode;
}

std::vector<JointGearMode> set_transmission_error_gear_modes(ident::IdentificationConfig& config,
                                                             const ident::JointErrorLog& log,
                                                             const ModelTorqueSource& model) {
  if (!config.transmission_error_gear_mode || !config.options.transmission_error_input) return {};
  config.transmission_error_mode_rad_s.clear();
  config.transmission_error_mode_damping.clear();
  const std::vector<double> inertia = median_link_inertia_kg_m2(log, model);
  spdlog::info("identify: the gear modes' stiffness from an identification without them");
  const std::vector<ident::JointOutcome> first = ident::identify_joints(log, config);
  std::vector<JointGearMode> modes;
  for (std::size_t j = 0; j < log.joint_count(); ++j) {
    const ident::StructureEstimate& k = first[j].structure.stiffness_nm_per_rad;
    modes.push_back(gear_mode_of(inertia[j], k.value, k.sigma, model.robot.joints[j].drive));
    spdlog::info("identify: {} gear mode: {}", log.joint_names[j], describe_gear_mode(modes[j]));
    config.transmission_error_mode_rad_s.push_back(modes[j].natural_frequency_rad_s);
    config.transmission_error_mode_damping.push_back(modes[j].damping_ratio);
  }
  return modes;
}

std::string describe_gear_mode(const JointGearMode& mode) {
  if (!(mode.natural_frequency_rad_s > 0.0)) return "none (rigid or undamped nominal drive)";
  return fmt::format(
      "{:.2f} Hz, damping {:.3f}, M {:.3g} kg m^2, k {:.4g} N m/rad ({}; data {:.4g} ± {:.2g})",
      mode.natural_frequency_rad_s / (2.0 * std::numbers::pi), mode.damping_ratio,
      mode.inertia_kg_m2, mode.stiffness_nm_per_rad,
      mode.stiffness_from_data ? "from the data" : "nominal", mode.data_stiffness_nm_per_rad,
      mode.data_stiffness_sigma_nm_per_rad);
}

}  // namespace imscal::eval
