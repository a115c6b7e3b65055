#include "sim/scenario.hpp"

#include <cmath>
#include <cstdlib>

#include "calib/robot_description.hpp"
#include "core/input_error.hpp"
#include "core/path_checks.hpp"

#ifndef IMSCAL_DATASETS_DIR
#define IMSCAL_DATASETS_DIR ""
#endif

namespace imscal::sim {
namespace {

namespace fs = std::filesystem;
constexpr double kDegToRad = M_PI / 180.0;

double non_negative(const ConfigNode& node) {
  const double value = node.as_double();
  if (value < 0.0) node.fail("must not be negative");
  return value;
}

}  // namespace

Scenario load_scenario(const fs::path& file) {
  const ConfigNode root = ConfigNode::load_file(file);
  root.require_only_keys({"imscal-scenario", "name", "description", "robot", "program", "sensor",
                          "imu", "site", "base_in_world", "sensor_mount", "effects", "plant",
                          "seed"});
  if (root.child("imscal-scenario").as_int() != 1) {
    root.child("imscal-scenario").fail("unknown scenario version (this reader: 1)");
  }
  Scenario s;
  s.file = file;
  s.name = root.child("name").as_string();
  s.description = root.get_string("description", "");
  s.robot_file = root.child("robot").as_existing_file();
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
                                     base.child("rpy_deg").as_vector3() * kDegToRad);
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
    s.mount_offset = calib::pose_from_xyz_rpy(xyz_mm * 1e-3, rpy_deg * kDegToRad);
    if (mount->has("random_position_sigma_mm")) {
      s.mount_random_position_sigma_m =
          non_negative(mount->child("random_position_sigma_mm")) * 1e-3;
    }
    if (mount->has("random_rotation_sigma_deg")) {
      s.mount_random_rotation_sigma_rad =
          non_negative(mount->child("random_rotation_sigma_deg")) * kDegToRad;
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
  return s;
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

PlantConfig make_plant_config(const calib::RobotDescription& robot, const Scenario& scenario) {
  return make_plant_config(robot, scenario.effects ? &*scenario.effects : nullptr,
                           scenario.integration_step ? &*scenario.integration_step : nullptr);
}

}  // namespace imscal::sim
