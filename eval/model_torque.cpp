#include "eval/model_torque.hpp"

#include <fmt/format.h>

#include <cmath>
#include <optional>
#include <stdexcept>

#include "core/input_error.hpp"

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

ModelTorqueSource load_model_torque_source(
    const std::string& robot_file, const Eigen::Vector3d& gravity_in_base_m_s2,
    const std::string& data_robot, const std::string& data_file, const std::string& needed_by_file,
    const std::string& needed_by_field, double data_cycle_s) {
  if (robot_file.empty())
    throw InputError(needed_by_file, 0, needed_by_field,
                     "the models take the model torque: give the robot description (--robot, or "
                     "robot= in Python; e.g. datasets/robots/kr16.yaml)");
  ModelTorqueSource model;
  model.robot = calib::load_robot_description(robot_file);
  if (model.robot.name != data_robot)
    throw InputError(robot_file, 0, "name",
                     fmt::format("robot '{}', but {} is of robot '{}'", model.robot.name, data_file,
                                 data_robot));
  const double robot_cycle_s = model.robot.controller_cycle_s;
  if (data_cycle_s > 0.0 && std::abs(robot_cycle_s - data_cycle_s) > 1e-9 * data_cycle_s)
    throw InputError(robot_file, 0, "controller_cycle_s",
                     fmt::format("the robot's controller cycle is {} s, but {} is sampled every "
                                 "{} s: a log of another controller or a robot file of another "
                                 "robot",
                                 robot_cycle_s, data_file, data_cycle_s));
  model.gravity_in_base_m_s2 = gravity_in_base_m_s2;
  return model;
}

ModelTorqueSource with_table_links(ModelTorqueSource model, const ident::ParameterTable& table,
                                   const std::string& table_file) {
  if (table.model_torque_links.empty()) return model;
  if (table.model_torque_links.size() != model.robot.joints.size())
    throw InputError(table_file, 0, "model_torque_links",
                     fmt::format("{} links, but robot '{}' has {}", table.model_torque_links.size(),
                                 model.robot.name, model.robot.joints.size()));
  for (std::size_t i = 0; i < model.robot.joints.size(); ++i) {
    const ident::LinkMassParameters& l = table.model_torque_links[i];
    calib::RigidBodyParameters& link = model.robot.joints[i].link;
    const Eigen::Vector3d nominal_com(l.nominal_com_m[0], l.nominal_com_m[1], l.nominal_com_m[2]);
    // The table's nominal values are the robot file's, written with 17 digits.
    if (std::abs(l.nominal_mass_kg - link.mass_kg) > 1e-9 * link.mass_kg ||
        (nominal_com - link.com_m).norm() > 1e-9)
      throw InputError(table_file, 0, fmt::format("model_torque_links/{}", i),
                       fmt::format("refined from a nominal link of {} kg, but robot '{}' has "
                                   "{} kg: the table was identified with another robot file",
                                   l.nominal_mass_kg, model.robot.name, link.mass_kg));
    if (!l.refined) continue;
    link.mass_kg = l.mass_kg;
    link.com_m = Eigen::Vector3d(l.com_m[0], l.com_m[1], l.com_m[2]);
  }
  return model;
}

}  // namespace imscal::eval
