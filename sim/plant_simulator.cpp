#include "sim/plant_simulator.hpp"

#include <Eigen/Cholesky>
#include <cmath>
#include <stdexcept>
#include <string>

namespace imscal::sim {
namespace {

constexpr int kN = calib::kJointCount;

// The body the plant carries: the program's payload, its mass and inertia times the plant's
// factor (the logged payload stays the program's).
std::optional<calib::RigidBodyParameters> payload_body(const DesiredJointPath& path, int index,
                                                       double mass_factor) {
  if (path.payloads.empty()) return std::nullopt;
  calib::RigidBodyParameters body = path.payloads[index].body;
  body.mass_kg *= mass_factor;
  body.inertia_kg_m2 *= mass_factor;
  return body;
}

// Largest slope of a joint's transmission error, sum of amplitude * harmonic * N over its orders.
double largest_te_slope(const JointEffects& effects, double gear_ratio) {
  double slope = effects.transmission_error_shape.amplitude_rad *
                 effects.transmission_error_shape.harmonic_per_motor_rev;
  for (const auto& shape : effects.further_transmission_error_shapes)
    slope += shape.amplitude_rad * shape.harmonic_per_motor_rev;
  return slope * gear_ratio;
}

}  // namespace

PlantSimulator::PlantSimulator(const PlantConfig& config, const DesiredJointPath& path)
    : config_(config),
      path_(path),
      dynamics_(config.robot, std::nullopt,
                config.gravity ? config.gravity_in_base_m_s2 : Eigen::Vector3d::Zero()) {
  validate_plant_config(config_);
  const double cycle = config_.robot.controller_cycle_s;
  if (path_.samples.empty()) throw std::invalid_argument("plant: empty desired path");
  if (std::abs(path_.cycle_s - cycle) > 1e-12) {
    throw std::invalid_argument("plant: desired path cycle " + std::to_string(path_.cycle_s) +
                                " s differs from the controller cycle " + std::to_string(cycle));
  }
  for (const DesiredJointSample& sample : path_.samples) {
    const bool ok = path_.payloads.empty()
                        ? sample.payload_index == 0
                        : sample.payload_index >= 0 &&
                              sample.payload_index < static_cast<int>(path_.payloads.size());
    if (!ok) throw std::invalid_argument("plant: payload index out of range");
  }
  steps_per_cycle_ = static_cast<int>(std::lround(cycle / config_.integration_step_s));
  for (int i = 0; i < kN; ++i) {
    const calib::JointDescription& joint = config_.robot.joints[i];
    drives_[i] = DriveModel(joint.drive, config_.effects[i]);
    // |te'| must stay well below 1 or the transmission is not monotonic.
    if (config_.effects[i].transmission_error &&
        largest_te_slope(config_.effects[i], joint.drive.gear_ratio) > 0.2) {
      throw std::invalid_argument(
          "plant: joint " + joint.name +
          ": transmission error slope, sum of amplitude * harmonic * N, > 0.2");
    }
    controllers_[i] = JointController(joint.controller, cycle);
    delay_cycles_[i] = static_cast<int>(std::lround(config_.effects[i].dead_time_s / cycle));
  }
  payload_index_ = path_.samples.front().payload_index;
  apply_payload(payload_index_);
  start_at_rest();
}

void PlantSimulator::apply_payload(int index) {
  payload_index_ = index;
  dynamics_.set_payload(payload_body(path_, index, config_.payload_mass_factor));
}

void PlantSimulator::start_at_rest() {
  const calib::JointVector theta = path_.samples.front().q_rad;
  PlantState s;
  s.theta_rad = theta;
  // Link angle q with k dz(theta - q - te(theta)) = G(q): fixed point, G changes little over
  // the sag (dG/dq / k < 1e-2 on the KR 16).
  calib::JointVector gravity = calib::JointVector::Zero();
  for (int iteration = 0; iteration < 6; ++iteration) {
    for (int i = 0; i < kN; ++i) {
      const DriveModel& d = drives_[i];
      const double sag = d.kind() == DriveKind::kRigid
                             ? 0.0
                             : d.inverse_dead_zone(gravity(i) / d.stiffness_nm_per_rad());
      s.q_rad(i) = theta(i) - d.te(theta(i)) - sag;
    }
    gravity = dynamics_.gravity_torque(s.q_rad);
  }
  state_ = s;
  for (int i = 0; i < kN; ++i) {
    const DriveModel& d = drives_[i];
    // Generalised holding torque on the motor: (1 - te') G for rigid and elastic drives.
    const double hold = d.kind() == DriveKind::kMasslessMotor
                            ? gravity(i)
                            : (1.0 - d.te_slope(theta(i))) * gravity(i);
    controllers_[i].preload(hold);
    torque_(i) = config_.controller ? hold : 0.0;
  }
}

PlantSimulator::StateVector PlantSimulator::pack(const PlantState& s) const {
  StateVector x;
  x << s.q_rad, s.qd_rad_s, s.theta_rad, s.thetad_rad_s;
  return x;
}

PlantState PlantSimulator::unpack(const StateVector& x, double t_s) const {
  PlantState s;
  s.t_s = t_s;
  s.q_rad = x.segment<kN>(0);
  s.qd_rad_s = x.segment<kN>(kN);
  s.theta_rad = x.segment<kN>(2 * kN);
  s.thetad_rad_s = x.segment<kN>(3 * kN);
  complete(s);
  return s;
}

void PlantSimulator::complete(PlantState& s) const {
  for (int i = 0; i < kN; ++i) {
    const DriveModel& d = drives_[i];
    if (d.kind() == DriveKind::kRigid) {
      s.q_rad(i) = s.theta_rad(i) - d.te(s.theta_rad(i));
      s.qd_rad_s(i) = (1.0 - d.te_slope(s.theta_rad(i))) * s.thetad_rad_s(i);
    } else if (d.kind() == DriveKind::kMasslessMotor) {
      const double link_torque = torque_(i) - d.friction_nm(s.qd_rad_s(i));
      s.theta_rad(i) = d.motor_angle_for(s.q_rad(i), link_torque);
      s.thetad_rad_s(i) = s.qd_rad_s(i) / (1.0 - d.te_slope(s.theta_rad(i)));
    }
  }
}

PlantSimulator::StateVector PlantSimulator::derivative(const PlantState& s,
                                                       calib::JointVector* qdd_out) {
  const JointMatrix mass = dynamics_.mass_matrix(s.q_rad);
  const calib::JointVector bias = dynamics_.bias_torque(s.q_rad, s.qd_rad_s);
  JointMatrix lhs = mass;
  calib::JointVector rhs = -bias;
  calib::JointVector gear_torque = calib::JointVector::Zero();
  calib::JointVector slope;
  for (int i = 0; i < kN; ++i) {
    const DriveModel& d = drives_[i];
    const double theta = s.theta_rad(i);
    const double thetad = s.thetad_rad_s(i);
    slope(i) = 1.0 - d.te_slope(theta);
    switch (d.kind()) {
      case DriveKind::kRigid: {
        const double j = d.reflected_inertia_kg_m2();
        const double inv_s = 1.0 / slope(i);
        lhs(i, i) += j * inv_s * inv_s;
        rhs(i) += (torque_(i) - d.friction_nm(thetad)) * inv_s -
                  j * d.te_curvature(theta) * thetad * thetad * inv_s * inv_s;
        break;
      }
      case DriveKind::kElastic: {
        const double deflection = theta - s.q_rad(i) - d.te(theta);
        const double rate = slope(i) * thetad - s.qd_rad_s(i);
        gear_torque(i) = d.gear_torque_nm(deflection, rate);
        rhs(i) += gear_torque(i);
        rhs(i) -= d.link_friction_nm(s.qd_rad_s(i));
        break;
      }
      case DriveKind::kMasslessMotor:
        rhs(i) += torque_(i) - d.friction_nm(s.qd_rad_s(i));
        break;
    }
  }
  const calib::JointVector qdd = lhs.ldlt().solve(rhs);
  if (qdd_out) *qdd_out = qdd;
  StateVector dx = StateVector::Zero();
  for (int i = 0; i < kN; ++i) {
    const DriveModel& d = drives_[i];
    const double thetad = s.thetad_rad_s(i);
    switch (d.kind()) {
      case DriveKind::kRigid:
        dx(2 * kN + i) = thetad;
        dx(3 * kN + i) = (qdd(i) + d.te_curvature(s.theta_rad(i)) * thetad * thetad) / slope(i);
        break;
      case DriveKind::kElastic:
        dx(i) = s.qd_rad_s(i);
        dx(kN + i) = qdd(i);
        dx(2 * kN + i) = thetad;
        dx(3 * kN + i) = (torque_(i) - d.motor_friction_nm(thetad) - slope(i) * gear_torque(i)) /
                         d.reflected_inertia_kg_m2();
        break;
      case DriveKind::kMasslessMotor:
        dx(i) = s.qd_rad_s(i);
        dx(kN + i) = qdd(i);
        break;
    }
  }
  return dx;
}

void PlantSimulator::rk4_step(calib::JointVector* qdd_at_start) {
  const double h = config_.integration_step_s;
  const double t0 = state_.t_s;
  const StateVector x0 = pack(state_);
  const StateVector k1 = derivative(state_, qdd_at_start);
  const StateVector k2 = derivative(unpack(x0 + 0.5 * h * k1, t0 + 0.5 * h), nullptr);
  const StateVector k3 = derivative(unpack(x0 + 0.5 * h * k2, t0 + 0.5 * h), nullptr);
  const StateVector k4 = derivative(unpack(x0 + h * k3, t0 + h), nullptr);
  ++step_index_;
  // Time from the step count (no accumulated rounding).
  state_ = unpack(x0 + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4),
                  static_cast<double>(step_index_) * h);
}

bool PlantSimulator::run_cycle(const std::function<void(const PlantSample&)>& per_step_sample) {
  if (finished()) return false;
  const DesiredJointSample& now = path_.samples[cycle_index_];
  if (now.payload_index != payload_index_) apply_payload(now.payload_index);
  for (int i = 0; i < kN; ++i) {
    const long delayed = static_cast<long>(cycle_index_) - delay_cycles_[i];
    const DesiredJointSample& desired = path_.samples[delayed < 0 ? 0 : delayed];
    const double u = controllers_[i].update(desired.q_rad(i), desired.qd_rad_s(i),
                                            state_.theta_rad(i), state_.thetad_rad_s(i));
    torque_(i) = config_.controller ? u : 0.0;
  }
  complete(state_);  // massless motors: the encoder angle depends on the new torque
  for (int step = 0; step < steps_per_cycle_; ++step) {
    calib::JointVector qdd;
    const PlantState before = state_;
    rk4_step(&qdd);
    if (per_step_sample) {
      PlantSample sample;
      sample.t_s = before.t_s;
      sample.q_link_rad = before.q_rad;
      sample.qd_link_rad_s = before.qd_rad_s;
      sample.qdd_link_rad_s2 = qdd;
      sample.q_motor_rad = before.theta_rad;
      sample.tau_drive_nm = torque_;
      per_step_sample(sample);
    }
  }
  ++cycle_index_;
  return true;
}

PlantSample PlantSimulator::current_sample() {
  PlantSample sample;
  sample.t_s = state_.t_s;
  sample.q_link_rad = state_.q_rad;
  sample.qd_link_rad_s = state_.qd_rad_s;
  derivative(state_, &sample.qdd_link_rad_s2);
  sample.q_motor_rad = state_.theta_rad;
  sample.tau_drive_nm = torque_;
  return sample;
}

void PlantSimulator::set_state(const PlantState& state) {
  state_ = state;
  complete(state_);
}

double PlantSimulator::mechanical_energy_j() {
  const JointMatrix mass = dynamics_.mass_matrix(state_.q_rad);
  double energy = 0.5 * state_.qd_rad_s.dot(mass * state_.qd_rad_s);
  energy += dynamics_.potential_energy_j(state_.q_rad);
  for (int i = 0; i < kN; ++i) {
    const DriveModel& d = drives_[i];
    const double thetad = state_.thetad_rad_s(i);
    energy += 0.5 * d.reflected_inertia_kg_m2() * thetad * thetad;
    if (d.kind() != DriveKind::kRigid) {
      const double theta = state_.theta_rad(i);
      energy += d.spring_energy_j(theta - state_.q_rad(i) - d.te(theta));
    }
  }
  return energy;
}

double mechanical_energy_j(PlantSimulator& simulator) {
  return simulator.mechanical_energy_j();
}

PlantLog simulate_plant(const PlantConfig& config, const DesiredJointPath& path,
                        double output_interval_s,
                        const std::function<void(double fraction_done)>& progress) {
  const double ratio = output_interval_s / config.integration_step_s;
  const long every = std::lround(ratio);
  if (every < 1 || std::abs(ratio - static_cast<double>(every)) > 1e-9 * ratio) {
    throw std::invalid_argument("plant: output interval " + std::to_string(output_interval_s) +
                                " s is not a multiple of the integration step");
  }
  PlantSimulator simulator(config, path);
  PlantLog log;
  const std::size_t cycles = path.samples.size() - 1;
  const long steps_per_cycle =
      std::lround(config.robot.controller_cycle_s / config.integration_step_s);
  log.samples.reserve(static_cast<std::size_t>(cycles * steps_per_cycle / every + 2));
  long step = 0;
  auto keep = [&](const PlantSample& sample) {
    if (step++ % every == 0) log.samples.push_back(sample);
  };
  const std::size_t report_every = std::max<std::size_t>(1, cycles / 100);
  for (std::size_t cycle = 0; simulator.run_cycle(keep); ++cycle) {
    if (progress && cycle % report_every == 0) {
      progress(static_cast<double>(cycle) / static_cast<double>(cycles));
    }
  }
  if (step % every == 0) log.samples.push_back(simulator.current_sample());
  if (progress) progress(1.0);
  return log;
}

}  // namespace imscal::sim
