#include "sim/drive_model.hpp"

#include <cmath>

namespace imscal::sim {

DriveModel::DriveModel(const calib::DriveParameters& drive, const JointEffects& effects) {
  const double n = drive.gear_ratio;
  inertia_ = effects.motor_inertia ? n * n * drive.motor_inertia_kg_m2 : 0.0;
  if (!effects.elastic_gear) {
    kind_ = DriveKind::kRigid;
  } else {
    kind_ = inertia_ > 0.0 ? DriveKind::kElastic : DriveKind::kMasslessMotor;
    stiffness_ = drive.stiffness_nm_per_rad;
    damping_ = effects.gear_damping ? drive.damping_nm_s_per_rad : 0.0;
    half_backlash_ = effects.backlash ? 0.5 * drive.backlash_rad : 0.0;
    if (kind_ == DriveKind::kElastic)
      link_share_ = effects.friction_at_link ? 1.0 : effects.link_friction_fraction;
  }
  coulomb_ = effects.coulomb_friction ? drive.coulomb_nm : 0.0;
  coulomb_scale_ = effects.coulomb_velocity_scale_rad_s;
  viscous_ = effects.viscous_friction ? drive.viscous_nm_s_per_rad : 0.0;
  if (effects.transmission_error) {
    const auto add = [&](const TransmissionErrorShape& shape) {
      if (shape.amplitude_rad != 0.0)
        te_.push_back({shape.amplitude_rad, shape.harmonic_per_motor_rev * n, shape.phase_rad});
    };
    add(effects.transmission_error_shape);
    for (const auto& shape : effects.further_transmission_error_shapes) add(shape);
  }
}

double DriveModel::te(double theta) const {
  double sum = 0.0;
  for (const auto& h : te_) sum += h.amplitude * std::sin(h.frequency * theta + h.phase);
  return sum;
}

double DriveModel::te_slope(double theta) const {
  double sum = 0.0;
  for (const auto& h : te_)
    sum += h.amplitude * h.frequency * std::cos(h.frequency * theta + h.phase);
  return sum;
}

double DriveModel::te_curvature(double theta) const {
  double sum = 0.0;
  for (const auto& h : te_)
    sum -= h.amplitude * h.frequency * h.frequency * std::sin(h.frequency * theta + h.phase);
  return sum;
}

double DriveModel::dead_zone(double x) const {
  if (x > half_backlash_) return x - half_backlash_;
  if (x < -half_backlash_) return x + half_backlash_;
  return 0.0;
}

double DriveModel::inverse_dead_zone(double y) const {
  if (y > 0.0) return y + half_backlash_;
  if (y < 0.0) return y - half_backlash_;
  return 0.0;
}

bool DriveModel::in_contact(double x) const {
  return std::abs(x) > half_backlash_;
}

double DriveModel::gear_torque_nm(double deflection, double deflection_rate) const {
  if (!in_contact(deflection)) return 0.0;
  return stiffness_ * dead_zone(deflection) + damping_ * deflection_rate;
}

double DriveModel::friction_nm(double v) const {
  double out = viscous_ * v;
  if (coulomb_ != 0.0) out += coulomb_ * std::tanh(v / coulomb_scale_);
  return out;
}

double DriveModel::spring_energy_j(double deflection) const {
  const double s = dead_zone(deflection);
  return 0.5 * stiffness_ * s * s;
}

double DriveModel::motor_angle_for(double q_link, double gear_torque) const {
  const double deflection =
      kind_ == DriveKind::kRigid ? 0.0 : inverse_dead_zone(gear_torque / stiffness_);
  double theta = q_link + deflection;
  // Fixed point theta = q + deflection + te(theta): contraction with factor |te'| (~0.02).
  for (int iteration = 0; iteration < 8 && !te_.empty(); ++iteration) {
    theta = q_link + deflection + te(theta);
  }
  return theta;
}

}  // namespace imscal::sim
