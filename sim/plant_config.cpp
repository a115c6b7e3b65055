#include "sim/plant_config.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "core/config_node.hpp"
#include "core/units.hpp"

namespace imscal::sim {
namespace {

void read_shape(const ConfigNode& node, TransmissionErrorShape& shape) {
  node.require_only_keys({"amplitude_arcsec", "harmonic_per_motor_rev", "phase_deg"});
  if (node.has("amplitude_arcsec")) {
    const double arcsec = node.child("amplitude_arcsec").as_double();
    if (arcsec < 0.0) node.child("amplitude_arcsec").fail("must be >= 0");
    shape.amplitude_rad = arcsec * kRadPerArcsec;
  }
  if (node.has("harmonic_per_motor_rev")) {
    const double harmonic = node.child("harmonic_per_motor_rev").as_double();
    if (harmonic <= 0.0) node.child("harmonic_per_motor_rev").fail("must be > 0");
    shape.harmonic_per_motor_rev = harmonic;
  }
  if (node.has("phase_deg")) shape.phase_rad = node.child("phase_deg").as_double() * M_PI / 180.0;
}

// `transmission_error_shapes: [{...}, ...]`: the first replaces the joint's shape, the others are
// its further orders (summed).
void read_shapes(const ConfigNode& node, JointEffects& effects) {
  const std::vector<ConfigNode> items = node.as_sequence();
  if (items.empty()) node.fail("expected at least one shape");
  effects.further_transmission_error_shapes.clear();
  for (std::size_t k = 0; k < items.size(); ++k) {
    TransmissionErrorShape shape;
    read_shape(items[k], shape);
    if (k == 0)
      effects.transmission_error_shape = shape;
    else
      effects.further_transmission_error_shapes.push_back(shape);
  }
}

// Applies the keys present in `node` on top of `effects` (for `all` and per joint).
void read_effects(const ConfigNode& node, bool per_joint, JointEffects& effects) {
  if (per_joint) {
    node.require_only_keys({"motor_inertia", "elastic_gear", "gear_damping", "backlash",
                            "coulomb_friction", "viscous_friction", "transmission_error",
                            "dead_time_s", "coulomb_velocity_scale_rad_s", "friction_at_link",
                            "link_friction_fraction", "transmission_error_shape",
                            "transmission_error_shapes"});
    if (const auto shape = node.optional_child("transmission_error_shape")) {
      read_shape(*shape, effects.transmission_error_shape);
    }
    if (const auto shapes = node.optional_child("transmission_error_shapes")) {
      read_shapes(*shapes, effects);
    }
  } else {
    node.require_only_keys({"motor_inertia", "elastic_gear", "gear_damping", "backlash",
                            "coulomb_friction", "viscous_friction", "transmission_error",
                            "dead_time_s", "coulomb_velocity_scale_rad_s", "friction_at_link",
                            "link_friction_fraction"});
  }
  effects.motor_inertia = node.get_bool("motor_inertia", effects.motor_inertia);
  effects.elastic_gear = node.get_bool("elastic_gear", effects.elastic_gear);
  effects.gear_damping = node.get_bool("gear_damping", effects.gear_damping);
  effects.backlash = node.get_bool("backlash", effects.backlash);
  effects.coulomb_friction = node.get_bool("coulomb_friction", effects.coulomb_friction);
  effects.viscous_friction = node.get_bool("viscous_friction", effects.viscous_friction);
  effects.transmission_error = node.get_bool("transmission_error", effects.transmission_error);
  effects.friction_at_link = node.get_bool("friction_at_link", effects.friction_at_link);
  if (node.has("link_friction_fraction")) {
    const double fraction = node.child("link_friction_fraction").as_double();
    if (!(fraction >= 0.0 && fraction <= 1.0))
      node.child("link_friction_fraction").fail("must be in [0, 1]");
    effects.link_friction_fraction = fraction;
  }
  if (node.has("dead_time_s")) {
    const double dead_time = node.child("dead_time_s").as_double();
    if (dead_time < 0.0 || dead_time > 1.0) node.child("dead_time_s").fail("must be in [0, 1] s");
    effects.dead_time_s = dead_time;
  }
  if (node.has("coulomb_velocity_scale_rad_s")) {
    const double scale = node.child("coulomb_velocity_scale_rad_s").as_double();
    if (scale <= 0.0) node.child("coulomb_velocity_scale_rad_s").fail("must be > 0");
    effects.coulomb_velocity_scale_rad_s = scale;
  }
}

}  // namespace

PlantConfig make_plant_config(const calib::RobotDescription& robot,
                              const ConfigNode* effects_or_null,
                              const ConfigNode* integration_step_or_null) {
  PlantConfig config;
  config.robot = robot;
  if (integration_step_or_null) {
    const double step = integration_step_or_null->as_double();
    const double cycles = robot.controller_cycle_s / step;
    if (step <= 0.0 || std::abs(cycles - std::round(cycles)) > 1e-9 * cycles) {
      integration_step_or_null->fail("must be > 0 and divide the controller cycle of " +
                                     std::to_string(robot.controller_cycle_s) + " s");
    }
    config.integration_step_s = step;
  }
  if (!effects_or_null) return config;
  const ConfigNode& node = *effects_or_null;
  if (!node.is_map()) node.fail("expected a map: all, transmission_error, <joint name>");
  for (const std::string& key : node.keys()) {
    bool known = key == "all" || key == "transmission_error";
    for (const auto& joint : robot.joints) known = known || key == joint.name;
    if (!known) {
      node.child(key).fail("unknown key: expected all, transmission_error or a joint name");
    }
  }
  JointEffects common;
  if (const auto shape = node.optional_child("transmission_error")) {
    read_shape(*shape, common.transmission_error_shape);
  }
  if (const auto all = node.optional_child("all")) read_effects(*all, false, common);
  for (int i = 0; i < calib::kJointCount; ++i) {
    config.effects[i] = common;
    const auto joint_node = node.optional_child(robot.joints[i].name);
    if (joint_node) read_effects(*joint_node, true, config.effects[i]);
    const JointEffects& e = config.effects[i];
    if (!e.elastic_gear && (e.backlash || e.gear_damping)) {
      (joint_node ? *joint_node : node)
          .fail("joint " + robot.joints[i].name +
                ": backlash and gear_damping need elastic_gear (set them false for a rigid gear)");
    }
  }
  return config;
}

void validate_plant_config(const PlantConfig& config) {
  const double step = config.integration_step_s;
  const double cycle = config.robot.controller_cycle_s;
  if (!(step > 0.0) || !(cycle > 0.0)) {
    throw std::invalid_argument("plant: integration step and controller cycle must be > 0");
  }
  const double ratio = cycle / step;
  if (std::abs(ratio - std::round(ratio)) > 1e-9 * ratio) {
    throw std::invalid_argument("plant: integration step " + std::to_string(step) +
                                " s does not divide the controller cycle " + std::to_string(cycle) +
                                " s");
  }
  for (int i = 0; i < calib::kJointCount; ++i) {
    const JointEffects& e = config.effects[i];
    const std::string& name = config.robot.joints[i].name;
    if (!e.elastic_gear && (e.backlash || e.gear_damping)) {
      throw std::invalid_argument("plant: joint " + name +
                                  ": backlash and gear_damping need elastic_gear");
    }
    if (e.elastic_gear && !(config.robot.joints[i].drive.stiffness_nm_per_rad > 0.0)) {
      throw std::invalid_argument("plant: joint " + name + ": elastic gear without stiffness");
    }
    if (e.dead_time_s < 0.0 || !(e.coulomb_velocity_scale_rad_s > 0.0) ||
        !(e.link_friction_fraction >= 0.0 && e.link_friction_fraction <= 1.0)) {
      throw std::invalid_argument("plant: joint " + name +
                                  ": bad dead time, Coulomb scale or link friction fraction");
    }
  }
}

}  // namespace imscal::sim
