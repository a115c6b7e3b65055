#include "eval/gap_nominal_plant.hpp"

#include <algorithm>
#include <cmath>

#include "sim/plant_simulator.hpp"

namespace imscal::eval {
namespace {

const NominalParameterDefinition& definition_of(const NominalParameter& parameter) {
  return *effect_definition(parameter.kind).nominal;
}

// The nominal model's own value of the parameter (0 when the effect is off there or the
// parameter has no bound).
double nominal_value(const NominalPlant& plant, const NominalParameter& parameter) {
  const auto value = definition_of(parameter).nominal_value;
  return value ? value(plant, parameter.joint) : 0.0;
}

}  // namespace

Eigen::Index NominalParameter::size() const {
  const NominalParameterDefinition* nominal = effect_definition(kind).nominal;
  return nominal ? nominal->parameter_count : 0;
}

bool has_nominal_parameter(const NominalPlant& plant, EffectKind kind, std::size_t joint) {
  if (joint >= plant.config.effects.size()) return false;
  const NominalParameterDefinition* nominal = effect_definition(kind).nominal;
  return nominal && nominal->applies(plant, joint);
}

Eigen::VectorXd nominal_steps(const NominalPlant& plant,
                              const std::vector<NominalParameter>& parameters,
                              const Eigen::VectorXd& p) {
  Eigen::VectorXd step(p.size());
  Eigen::Index i = 0;
  for (const NominalParameter& parameter : parameters)
    for (Eigen::Index k = 0; k < parameter.size(); ++k, ++i)
      step[i] = std::max(0.1 * definition_of(parameter).typical_value(plant, parameter.joint),
                         0.1 * std::abs(p[i]));
  return step;
}

Eigen::VectorXd physical_parameters(const NominalPlant& plant,
                                    const std::vector<NominalParameter>& parameters,
                                    Eigen::VectorXd p) {
  Eigen::Index i = 0;
  for (const NominalParameter& parameter : parameters) {
    if (definition_of(parameter).nominal_value)  // bounded: value + p >= 0
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
    definition_of(parameter).apply(parameter, p.data() + i, config, path);
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
  return definition_of(parameter).describe(joint, parameter, p_own,
                                           nominal_value(plant, parameter));
}

}  // namespace imscal::eval
