#include "eval/model_torque.hpp"

#include <fmt/format.h>

#include <optional>
#include <stdexcept>

namespace imscal::eval {
PayloadDynamics::PayloadDynamics(const ModelTorqueSource& model)
    : dynamics_(model.robot, std::nullopt, model.gravity_in_base_m_s2) {}

calib::JointVector PayloadDynamics::torque(double payload_kg, const calib::JointVector& q,
                                           const calib::JointVector& qd,
                                           const calib::JointVector& qdd) {
  if (payload_kg != payload_kg_) {
    payload_kg_ = payload_kg;
    std::optional<calib::RigidBodyParameters> body;
    if (payload_kg > 0.0) {
      calib::RigidBodyParameters point_mass;  // centre of mass at T's origin, no inertia
      point_mass.mass_kg = payload_kg;
      body = point_mass;
    }
    dynamics_.set_payload(body);
  }
  return dynamics_.inverse_dynamics(q, qd, qdd);
}

std::vector<std::vector<double>> model_torques_along(
    const ModelTorqueSource& model, double cycle_s, const std::vector<std::vector<double>>& q_rad,
    std::span<const double> payload_kg,
    std::span<const std::pair<std::size_t, std::size_t>> segments) {
  if (q_rad.size() != std::size_t(calib::kJointCount))
    throw std::invalid_argument(
        fmt::format("model_torques_along: {} joints, the robot has 6", q_rad.size()));
  const std::size_t n = payload_kg.size();
  for (const auto& q : q_rad)
    if (q.size() != n) throw std::invalid_argument("model_torques_along: signal lengths differ");
  if (!(cycle_s > 0.0)) throw std::invalid_argument("model_torques_along: cycle must be > 0");
  PayloadDynamics dynamics(model);
  std::vector<std::vector<double>> torque(q_rad.size(), std::vector<double>(n, 0.0));
  for (const auto& [begin, end] : segments) {
    if (end > n || begin >= end)
      throw std::invalid_argument("model_torques_along: segment outside the signals");
    for (std::size_t k = begin; k < end; ++k) {
      // Central differences inside the segment, one-sided at its ends (zero for one sample).
      const std::size_t lo = k > begin ? k - 1 : k, hi = k + 1 < end ? k + 1 : k;
      calib::JointVector q, qd = calib::JointVector::Zero(), qdd = calib::JointVector::Zero();
      for (int j = 0; j < calib::kJointCount; ++j) {
        const auto& x = q_rad[std::size_t(j)];
        q(j) = x[k];
        if (hi > lo) qd(j) = (x[hi] - x[lo]) / (double(hi - lo) * cycle_s);
        if (hi - lo == 2) qdd(j) = (x[hi] - 2.0 * x[k] + x[lo]) / (cycle_s * cycle_s);
      }
      const calib::JointVector t = dynamics.torque(payload_kg[k], q, qd, qdd);
      for (int j = 0; j < calib::kJointCount; ++j) torque[std::size_t(j)][k] = t(j);
    }
  }
  return torque;
}

std::vector<calib::JointVector> model_torques_along(const ModelTorqueSource& model,
                                                    const sim::DesiredJointPath& path) {
  PayloadDynamics dynamics(model);
  std::vector<calib::JointVector> torque;
  torque.reserve(path.samples.size());
  for (const sim::DesiredJointSample& s : path.samples) {
    const double payload_kg =
        path.payloads.empty() ? 0.0 : path.payloads[std::size_t(s.payload_index)].body.mass_kg;
    torque.push_back(dynamics.torque(payload_kg, s.q_rad, s.qd_rad_s, s.qdd_rad_s2));
  }
  return torque;
}

bool torque_along_measured_path(const ident::JointIdentificationOptions& options) {
  return options.form == ident::ArxModelForm::kInverse;
}

void attach_model_torques(ident::JointErrorLog& log, const ModelTorqueSource& model,
                          const ident::JointIdentificationOptions& options) {
  if (!options.model_torque_input) return;
  const auto& path = torque_along_measured_path(options) ? log.q_measured_rad : log.q_desired_rad;
  log.model_torque_nm =
      model_torques_along(model, log.cycle_s, path, log.payload_kg, log.segments());
}

}  // namespace imscal::eval
