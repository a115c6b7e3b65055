#include "eval/gap_nominal_plant.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/units.hpp"
#include "sim/plant_simulator.hpp"

namespace imscal::eval {
namespace {

const calib::DriveParameters& drive_of(const NominalPlant& plant, std::size_t joint) {
  return plant.config.robot.joints[joint].drive;
}

// The nominal model's own value of the parameter (0 when the effect is off there).
double nominal_value(const NominalPlant& plant, const NominalParameter& parameter) {
  const auto& effects = plant.config.effects[parameter.joint];
  const auto& drive = drive_of(plant, parameter.joint);
  switch (parameter.kind) {
    case EffectKind::kCoulombFriction:
      return effects.coulomb_friction ? drive.coulomb_nm : 0.0;
    case EffectKind::kBacklash:
      return effects.backlash ? drive.backlash_rad : 0.0;
    case EffectKind::kPayloadMismatch: {
      double lightest = std::numeric_limits<double>::infinity();
      for (const auto& p : plant.path.payloads) lightest = std::min(lightest, p.body.mass_kg);
      return lightest;
    }
    default:
      return 0.0;
  }
}

// The robot's value of the parameter whether the nominal model has it on or not: the scale of the
// finite-difference step.
double typical_value(const NominalPlant& plant, const NominalParameter& parameter) {
  const auto& drive = drive_of(plant, parameter.joint);
  switch (parameter.kind) {
    case EffectKind::kCoulombFriction:
      return drive.coulomb_nm > 0.0 ? drive.coulomb_nm : 1.0;
    case EffectKind::kBacklash:
      return drive.backlash_rad > 0.0 ? drive.backlash_rad : 1e-4;
    case EffectKind::kTransmissionError:
      return 20.0 * kRadPerArcsec;  // typical of RV gears
    default:
      return 1.0;  // payload: 1 kg
  }
}

void apply_change(const NominalParameter& parameter, const double* p, sim::PlantConfig& config,
                  sim::DesiredJointPath& path) {
  auto& effects = config.effects[parameter.joint];
  auto& drive = config.robot.joints[parameter.joint].drive;
  switch (parameter.kind) {
    case EffectKind::kCoulombFriction:
      drive.coulomb_nm = std::max(0.0, (effects.coulomb_friction ? drive.coulomb_nm : 0.0) + p[0]);
      effects.coulomb_friction = true;
      break;
    case EffectKind::kBacklash:
      drive.backlash_rad = std::max(0.0, (effects.backlash ? drive.backlash_rad : 0.0) + p[0]);
      effects.backlash = true;
      break;
    case EffectKind::kTransmissionError:
      if (!effects.transmission_error) effects.transmission_error_shape.amplitude_rad = 0.0;
      effects.transmission_error = true;
      effects.further_transmission_error_shapes.push_back(
          {std::hypot(p[0], p[1]), parameter.harmonic_per_motor_rev, std::atan2(p[1], p[0])});
      break;
    case EffectKind::kPayloadMismatch:
      for (auto& payload : path.payloads)
        payload.body.mass_kg = std::max(0.0, payload.body.mass_kg + p[0]);
      break;
    default:
      break;
  }
}

}  // namespace

bool has_nominal_parameter(const NominalPlant& plant, EffectKind kind, std::size_t joint) {
  if (joint >= plant.config.effects.size()) return false;
  switch (kind) {
    case EffectKind::kCoulombFriction:
    case EffectKind::kTransmissionError:
    case EffectKind::kPayloadMismatch:
      return true;
    case EffectKind::kBacklash:  // the play lives in the elastic gear (sim/plant_config.hpp)
      return plant.config.effects[joint].elastic_gear;
    default:
      return false;
  }
}

Eigen::VectorXd nominal_steps(const NominalPlant& plant,
                              const std::vector<NominalParameter>& parameters,
                              const Eigen::VectorXd& p) {
  Eigen::VectorXd step(p.size());
  Eigen::Index i = 0;
  for (const NominalParameter& parameter : parameters)
    for (Eigen::Index k = 0; k < parameter.size(); ++k, ++i)
      step[i] = std::max(0.1 * typical_value(plant, parameter), 0.1 * std::abs(p[i]));
  return step;
}

Eigen::VectorXd physical_parameters(const NominalPlant& plant,
                                    const std::vector<NominalParameter>& parameters,
                                    Eigen::VectorXd p) {
  Eigen::Index i = 0;
  for (const NominalParameter& parameter : parameters) {
    if (parameter.kind != EffectKind::kTransmissionError)
      p[i] = std::max(p[i], -nominal_value(plant, parameter));
    i += parameter.size();
  }
  return p;
}

std::vector<std::vector<double>> simulate_links(const NominalPlant& plant,
                                                const std::vector<NominalParameter>& parameters,
                                                const Eigen::VectorXd& p) {
  sim::PlantConfig config = plant.config;
  sim::DesiredJointPath path = plant.path;
  Eigen::Index i = 0;
  for (const NominalParameter& parameter : parameters) {
    apply_change(parameter, p.data() + i, config, path);
    i += parameter.size();
  }
  const sim::PlantLog log = sim::simulate_plant(config, path, path.cycle_s);
  const std::size_t n = std::min(log.samples.size(), path.samples.size());
  const std::size_t rows = plant.samples.empty() ? n : plant.samples.size();
  std::vector<std::vector<double>> q(config.effects.size(), std::vector<double>(rows));
  for (std::size_t k = 0; k < rows; ++k) {
    const std::size_t i = plant.samples.empty() ? k : std::min(plant.samples[k], n - 1);
    for (std::size_t j = 0; j < q.size(); ++j) q[j][k] = log.samples[i].q_link_rad[Eigen::Index(j)];
  }
  return q;
}

std::string describe_nominal_change(const NominalPlant& plant, const NominalParameter& parameter,
                                    const Eigen::VectorXd& p_own) {
  const std::string& joint = plant.config.robot.joints[parameter.joint].name;
  const double nominal = nominal_value(plant, parameter);
  switch (parameter.kind) {
    case EffectKind::kCoulombFriction:
      return fmt::format("{} Coulomb friction {:.3g} N m (nominal {:.3g} N m)", joint,
                         nominal + p_own[0], nominal);
    case EffectKind::kBacklash:
      return fmt::format("{} backlash {:.3g} arcmin (nominal {:.3g} arcmin)", joint,
                         (nominal + p_own[0]) / kRadPerArcmin, nominal / kRadPerArcmin);
    case EffectKind::kTransmissionError:
      return fmt::format("{} transmission error of order {:g} per motor revolution, {:.3g} arcsec",
                         joint, parameter.harmonic_per_motor_rev,
                         std::hypot(p_own[0], p_own[1]) / kRadPerArcsec);
    default:
      return fmt::format("payload {:.3g} kg (nominal {:.3g} kg)", nominal + p_own[0], nominal);
  }
}

}  // namespace imscal::eval
