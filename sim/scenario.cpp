#include "sim/scenario.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <cstdlib>
#include <string>
#include <string_view>

#include "core/input_error.hpp"
#include "core/path_checks.hpp"
#include "core/payload_plausibility.hpp"
#include "core/units.hpp"
#include "robot/robot_description.hpp"

#ifndef IMSCAL_DATASETS_DIR
#define IMSCAL_DATASETS_DIR ""
#endif

namespace imscal::sim {
namespace {

namespace fs = std::filesystem;

double non_negative(const ConfigNode& node) {
  const double value = node.as_double();
  if (value < 0.0) node.fail("must not be negative");
  return value;
}

// A plant deviation factor: > 0 and finite (a factor 0 would remove the part from the plant, which
// the effects switch does explicitly).
double factor(const ConfigNode& node, std::string_view key, double fallback) {
  if (!node.has(key)) return fallback;
  const double value = node.child(key).as_double();
  if (!(value > 0.0)) node.child(key).fail("must be a factor > 0");
  return value;
}

// The factors of one joint (or `all`), each multiplying the robot file's value; 1 = as in it.
struct DeviationFactors {
  double link_mass = 1.0;  // the link's mass and its inertia tensor (centre of mass kept)
  double gear_stiffness = 1.0;
  double backlash = 1.0;
  double coulomb_friction = 1.0;
  double viscous_friction = 1.0;
  double position_gain = 1.0;  // the controller's kp_position
  double velocity_gain = 1.0;  // the velocity PI's kp and ki (its corner kept)
  // Not a factor: added to the link's centre of mass, in the link's DH frame [m].
  Eigen::Vector3d centre_of_mass_offset_m = Eigen::Vector3d::Zero();
};

DeviationFactors read_factors(const ConfigNode& node, const DeviationFactors& fallback) {
  node.require_only_keys({"link_mass", "gear_stiffness", "backlash", "coulomb_friction",
                          "viscous_friction", "position_gain", "velocity_gain",
                          "centre_of_mass_offset_mm"});
  DeviationFactors f;
  f.link_mass = factor(node, "link_mass", fallback.link_mass);
  f.gear_stiffness = factor(node, "gear_stiffness", fallback.gear_stiffness);
  f.backlash = factor(node, "backlash", fallback.backlash);
  f.coulomb_friction = factor(node, "coulomb_friction", fallback.coulomb_friction);
  f.viscous_friction = factor(node, "viscous_friction", fallback.viscous_friction);
  f.position_gain = factor(node, "position_gain", fallback.position_gain);
  f.velocity_gain = factor(node, "velocity_gain", fallback.velocity_gain);
  f.centre_of_mass_offset_m =
      node.has("centre_of_mass_offset_mm")
          ? Eigen::Vector3d(node.child("centre_of_mass_offset_mm").as_vector3() * 1e-3)
          : fallback.centre_of_mass_offset_m;
  return f;
}

void apply(const DeviationFactors& f, calib::JointDescription& joint) {
  joint.link.mass_kg *= f.link_mass;
  joint.link.inertia_kg_m2 *= f.link_mass;
  joint.link.com_m += f.centre_of_mass_offset_m;
  joint.drive.stiffness_nm_per_rad *= f.gear_stiffness;
  joint.drive.backlash_rad *= f.backlash;
  joint.drive.coulomb_nm *= f.coulomb_friction;
  joint.drive.viscous_nm_s_per_rad *= f.viscous_friction;
  joint.controller.kp_position_1_s *= f.position_gain;
  joint.controller.kp_velocity_nm_s_per_rad *= f.velocity_gain;
  joint.controller.ki_velocity_nm_per_rad *= f.velocity_gain;
}

// `plant_deviations:` on the robot file's description: `all` first, then each joint's own keys
// (a joint's key replaces the `all` value). `payload_mass` is read by payload_mass_factor.
void apply_deviations(const ConfigNode& node, calib::RobotDescription& robot) {
  if (!node.is_map()) node.fail("expected a map: all, payload_mass, <joint name>");
  for (const std::string& key : node.keys()) {
    bool known = key == "all" || key == "payload_mass";
    for (const auto& joint : robot.joints) known = known || key == joint.name;
    if (!known)
      node.child(key).fail("unknown key: expected all, payload_mass or a joint name of the robot");
  }
  DeviationFactors common;
  if (const auto all = node.optional_child("all")) common = read_factors(*all, common);
  for (auto& joint : robot.joints) {
    const auto own = node.optional_child(joint.name);
    apply(own ? read_factors(*own, common) : common, joint);
  }
}

// The program's payloads (the one carried at the start and every change), times the plant's
// payload factor, against the plant robot's rating (core/payload_plausibility.hpp), naming the
// program file and the line of each mass.
void check_program_payloads(const Scenario& s, const calib::RobotDescription& robot) {
  const ConfigNode program = ConfigNode::load_file(s.program_file);
  std::vector<ConfigNode> masses;
  if (const auto initial = program.optional_child("payload"); initial && initial->is_map())
    if (const auto mass = initial->optional_child("mass_kg")) masses.push_back(*mass);
  if (const auto segments = program.optional_child("segments"))
    for (const ConfigNode& item : segments->as_sequence())
      if (item.is_map() && item.has("payload") && item.child("payload").is_map())
        if (const auto mass = item.child("payload").optional_child("mass_kg"))
          masses.push_back(*mass);
  const std::string rating_of = fmt::format("robot {} ({})", robot.name, robot.source);
  const std::string factor =
      s.plant_payload_mass_factor == 1.0
          ? std::string()
          : fmt::format("(x {} from {}'s plant_deviations.payload_mass)",
                        s.plant_payload_mass_factor, s.file.filename().string());
  for (const ConfigNode& mass : masses)
    check_payload_plausible(mass.as_double() * s.plant_payload_mass_factor,
                            robot.nominal_payload_kg,
                            {mass.file(), mass.line(), mass.path(), rating_of}, factor);
}

}  // namespace

Scenario load_scenario(const fs::path& file) {
  const ConfigNode root = ConfigNode::load_file(file);
  root.require_only_keys({"imscal-scenario", "name", "description", "robot", "nominal_robot",
                          "plant_deviations", "program", "sensor", "imu", "site", "base_in_world",
                          "sensor_mount", "effects", "plant", "seed"});
  if (root.child("imscal-scenario").as_int() != 1) {
    root.child("imscal-scenario").fail("unknown scenario version (this reader: 1)");
  }
  Scenario s;
  s.file = file;
  s.name = root.child("name").as_string();
  s.description = root.get_string("description", "");
  s.plant_robot_file = root.child("robot").as_existing_file();
  s.nominal_robot_given = root.has("nominal_robot");
  s.nominal_robot_file =
      s.nominal_robot_given ? root.child("nominal_robot").as_existing_file() : s.plant_robot_file;
  s.plant_deviations = root.optional_child("plant_deviations");
  s.program_file = root.child("program").as_existing_file();
  s.sensor_file = root.child("sensor").as_existing_file();

  const ConfigNode imu = root.child("imu");
  imu.require_only_keys({"rate_hz", "clock_offset_s", "format"});
  s.imu_rate_hz = imu.child("rate_hz").as_double();
  if (!(s.imu_rate_hz >= 10.0 && s.imu_rate_hz <= 10000.0)) {
    imu.child("rate_hz").fail("expected an IMS rate between 10 and 10000 Hz");
  }
  s.imu_clock_offset_s = imu.get_double("clock_offset_s", 0.0);
  if (std::abs(s.imu_clock_offset_s) > 1.0) {
    imu.child("clock_offset_s").fail("expected |offset| <= 1 s");
  }
  s.imu_format = imu.get_string("format", "csv");
  if (s.imu_format != "csv" && s.imu_format != "imsb") {
    imu.child("format").fail("expected csv or imsb");
  }

  const ConfigNode site = root.child("site");
  site.require_only_keys({"latitude_deg", "longitude_deg", "height_m"});
  s.site = {site.child("latitude_deg").as_double(), site.child("longitude_deg").as_double(),
            site.child("height_m").as_double()};
  if (std::abs(s.site.latitude_deg) > 90.0) site.child("latitude_deg").fail("must be within +-90");

  const ConfigNode base = root.child("base_in_world");
  base.require_only_keys({"xyz_m", "rpy_deg", "random_yaw"});
  s.T_W_R = calib::pose_from_xyz_rpy(base.child("xyz_m").as_vector3(),
                                     base.child("rpy_deg").as_vector3() * kRadPerDeg);
  s.random_base_yaw = base.get_bool("random_yaw", false);

  if (const auto mount = root.optional_child("sensor_mount")) {
    mount->require_only_keys({"offset_xyz_mm", "offset_rpy_deg", "random_position_sigma_mm",
                              "random_rotation_sigma_deg"});
    const Eigen::Vector3d xyz_mm = mount->has("offset_xyz_mm")
                                       ? mount->child("offset_xyz_mm").as_vector3()
                                       : Eigen::Vector3d::Zero();
    const Eigen::Vector3d rpy_deg = mount->has("offset_rpy_deg")
                                        ? mount->child("offset_rpy_deg").as_vector3()
                                        : Eigen::Vector3d::Zero();
    s.mount_offset = calib::pose_from_xyz_rpy(xyz_mm * 1e-3, rpy_deg * kRadPerDeg);
    if (mount->has("random_position_sigma_mm")) {
      s.mount_random_position_sigma_m =
          non_negative(mount->child("random_position_sigma_mm")) * 1e-3;
    }
    if (mount->has("random_rotation_sigma_deg")) {
      s.mount_random_rotation_sigma_rad =
          non_negative(mount->child("random_rotation_sigma_deg")) * kRadPerDeg;
    }
  }
  s.effects = root.optional_child("effects");
  if (const auto plant = root.optional_child("plant")) {
    plant->require_only_keys({"output_interval_s", "integration_step_s"});
    if (plant->has("output_interval_s")) {
      s.plant_output_interval_s = plant->child("output_interval_s").as_double();
      if (!(s.plant_output_interval_s > 0.0 && s.plant_output_interval_s <= 0.002)) {
        plant->child("output_interval_s").fail("expected 0 < interval <= 0.002 s");
      }
    }
    s.integration_step = plant->optional_child("integration_step_s");
  }
  if (root.has("seed")) {
    const long seed = root.child("seed").as_int();
    if (seed < 0) root.child("seed").fail("must not be negative");
    s.seed = static_cast<std::uint64_t>(seed);
  }
  // The deviations' and the effects' keys and values checked here, with the file's lines.
  const calib::RobotDescription plant = load_plant_robot(s);
  make_plant_config(plant, s);
  if (s.plant_deviations && s.plant_deviations->is_map())
    s.plant_payload_mass_factor = factor(*s.plant_deviations, "payload_mass", 1.0);
  check_program_payloads(s, plant);
  if (!s.nominal_robot_given) {
    spdlog::info(
        "scenario {}: no nominal_robot given; the chain believes the plant's robot file "
        "{}{}",
        s.name, s.plant_robot_file.string(),
        s.plant_deviations ? " (without the plant_deviations)" : "");
  }
  return s;
}

namespace {
// A plant needs every joint's drive and controller; a robot file may leave them out (a nominal
// robot, a URDF without its side file's joints). Given, both have a stiffness and a position gain
// > 0 (robot_description.cpp), so zero means absent.
void require_drives(const calib::RobotDescription& robot) {
  for (const calib::JointDescription& joint : robot.joints) {
    const bool drive = joint.drive.stiffness_nm_per_rad > 0.0;
    if (drive && joint.controller.kp_position_1_s > 0.0) continue;
    throw InputError(robot.source, 0,
                     fmt::format("{}.{}", joint.name, drive ? "controller" : "drive"),
                     "the simulator's plant needs a drive and a controller for every joint; this "
                     "robot file describes kinematics and masses only (use it as nominal_robot)");
  }
}
}  // namespace

calib::RobotDescription load_plant_robot(const Scenario& scenario) {
  calib::RobotDescription robot = calib::load_robot_description(scenario.plant_robot_file);
  require_drives(robot);
  if (scenario.plant_deviations) apply_deviations(*scenario.plant_deviations, robot);
  return robot;
}

NominalRobot load_nominal_robot(const Scenario& scenario) {
  return {calib::load_robot_description(scenario.nominal_robot_file)};
}

fs::path resolve_scenario(const std::string& name_or_file) {
  if (is_existing_file(name_or_file)) return name_or_file;
  const bool looks_like_path =
      name_or_file.find('/') != std::string::npos || name_or_file.ends_with(".yaml");
  if (looks_like_path) {
    throw InputError(name_or_file, 0, "--scenario", "no such scenario file");
  }
  const char* env = std::getenv("IMSCAL_DATASETS");
  const fs::path datasets = env && *env ? fs::path(env) : fs::path(IMSCAL_DATASETS_DIR);
  const fs::path file = datasets / "scenarios" / (name_or_file + ".yaml");
  if (!is_existing_file(file)) {
    std::string known;
    if (is_existing_folder(datasets / "scenarios")) {
      for (const auto& entry : fs::directory_iterator(datasets / "scenarios")) {
        if (entry.path().extension() == ".yaml") known.append(" ").append(entry.path().stem());
      }
    }
    std::string problem = "no shipped scenario '";
    problem.append(name_or_file)
        .append("'; known:")
        .append(known.empty() ? " (none found)" : known);
    throw InputError(file.string(), 0, "--scenario", problem);
  }
  return file;
}

PlantConfig make_plant_config(const calib::RobotDescription& plant_robot,
                              const Scenario& scenario) {
  PlantConfig config =
      make_plant_config(plant_robot, scenario.effects ? &*scenario.effects : nullptr,
                        scenario.integration_step ? &*scenario.integration_step : nullptr);
  config.payload_mass_factor = scenario.plant_payload_mass_factor;
  return config;
}

}  // namespace imscal::sim
