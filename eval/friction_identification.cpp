#include "eval/friction_identification.hpp"

#include <fmt/format.h>

#include <cmath>
#include <limits>
#include <stdexcept>

namespace imscal::eval {

void path_derivatives(const std::vector<double>& x, double cycle_s,
                      const std::vector<std::pair<std::size_t, std::size_t>>& segments,
                      std::vector<double>& speed, std::vector<double>& acceleration) {
  speed.assign(x.size(), 0.0);
  acceleration.assign(x.size(), 0.0);
  for (const auto& [begin, end] : segments)
    for (std::size_t k = begin; k < end; ++k) {
      const std::size_t lo = k > begin ? k - 1 : k, hi = k + 1 < end ? k + 1 : k;
      if (hi > lo) speed[k] = (x[hi] - x[lo]) / (double(hi - lo) * cycle_s);
      if (hi - lo == 2) acceleration[k] = (x[hi] - 2.0 * x[k] + x[lo]) / (cycle_s * cycle_s);
    }
}

std::vector<ident::JointFrictionLevels> identify_friction_levels(
    const ident::JointErrorLog& log, const ModelTorqueSource& nominal,
    const ident::FrictionLevelOptions& options) {
  const std::size_t joints = log.joint_count();
  if (joints != nominal.robot.joints.size())
    throw std::invalid_argument(fmt::format("friction levels: the log has {} joints, {} has {}",
                                            joints, nominal.robot.name,
                                            nominal.robot.joints.size()));
  std::vector<ident::JointFrictionLevels> out(joints);
  for (std::size_t j = 0; j < joints; ++j) {
    const calib::DriveParameters& drive = nominal.robot.joints[j].drive;
    out[j].coulomb_nm.nominal = drive.coulomb_nm;
    out[j].viscous_nm_s_per_rad.nominal = drive.viscous_nm_s_per_rad;
    out[j].reflected_inertia_kg_m2.nominal =
        drive.gear_ratio * drive.gear_ratio * drive.motor_inertia_kg_m2;
  }
  if (!log.has_q_internal()) {
    for (auto& joint : out) joint.not_estimated = "the record has no motor encoders (q_internal)";
    return out;
  }
  const auto segments = log.segments();
  const auto torque =
      model_torques_along(nominal, log.cycle_s, log.q_desired_rad, log.payload_kg, segments);
  ident::FrictionLevelOptions at_rate = options;
  at_rate.cycle_s = log.cycle_s;
  std::vector<std::vector<double>> speed(joints), acceleration(joints);
  std::vector<double> unused;
  for (std::size_t j = 0; j < joints; ++j) {
    path_derivatives(log.q_internal_rad[j], log.cycle_s, segments, speed[j], unused);
    path_derivatives(log.q_desired_rad[j], log.cycle_s, segments, unused, acceleration[j]);
  }
  // One dead time for the controller: the δ with the least Σ_j (1 − fit_j)² over the joints.
  std::vector<ident::JointFrictionLevels> best;
  double best_loss = std::numeric_limits<double>::infinity();
  for (int delay = 0; delay <= options.max_dead_time_cycles; ++delay) {
    std::vector<ident::JointFrictionLevels> at(joints);
    double loss = 0.0;
    for (std::size_t j = 0; j < joints; ++j) {
      const ident::FrictionPrior prior{out[j].coulomb_nm.nominal,
                                       out[j].viscous_nm_s_per_rad.nominal,
                                       out[j].reflected_inertia_kg_m2.nominal};
      at[j] = ident::estimate_friction_levels({log.q_desired_rad[j], log.q_internal_rad[j],
                                               torque[j], speed[j], acceleration[j], segments},
                                              prior, at_rate, delay);
      if (std::isfinite(at[j].torque_fit_percent))
        loss += std::pow(1.0 - at[j].torque_fit_percent / 100.0, 2);
    }
    if (loss < best_loss) best = std::move(at), best_loss = loss;
  }
  if (!best.empty()) out = std::move(best);
  return out;
}

std::string describe_friction_levels(const ident::JointFrictionLevels& l) {
  if (!l.estimated)
    return fmt::format("friction not estimated: {} (model torque RMS {:.3g} N m)", l.not_estimated,
                       l.torque_rms_nm);
  return fmt::format(
      "Coulomb {:.3g} ± {:.2g} N m (nominal {:.3g}), viscous {:.3g} ± {:.2g} N m s/rad (nominal "
      "{:.3g}), reflected inertia {:.3g} ± {:.2g} kg m² (nominal {:.3g}), balance fit {:.1f} %, "
      "dead time {} cycles",
      l.coulomb_nm.value, l.coulomb_nm.sigma, l.coulomb_nm.nominal, l.viscous_nm_s_per_rad.value,
      l.viscous_nm_s_per_rad.sigma, l.viscous_nm_s_per_rad.nominal, l.reflected_inertia_kg_m2.value,
      l.reflected_inertia_kg_m2.sigma, l.reflected_inertia_kg_m2.nominal, l.torque_fit_percent,
      l.dead_time_cycles);
}

}  // namespace imscal::eval
