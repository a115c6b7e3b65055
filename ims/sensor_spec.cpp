#include "ims/sensor_spec.hpp"

#include "core/units.hpp"
#include "ims/sensor_error_model.hpp"

namespace imscal::ims {
namespace {
using namespace sensor_units;

double non_negative(const ConfigNode& node, std::string_view key, double unit_si) {
  const ConfigNode c = node.child(key);
  const double v = c.as_double();
  if (v < 0.0) c.fail("expected a value >= 0");
  return v * unit_si;
}

// Keys of one triad, with their SI conversion factors.
struct TriadKeys {
  const char* white_noise;
  double white_noise_unit;
  const char* gm_sigma;
  const char* turn_on;
  double bias_unit;
  const char* lsb;
  double lsb_unit;
  const char* range;
  double range_unit;
};

TriadSpec parse_triad(const ConfigNode& node, const TriadKeys& k) {
  node.require_only_keys({k.white_noise, "bias_instability", k.turn_on, "scale_factor_sigma_ppm",
                          "misalignment_sigma_arcsec", k.lsb, k.range});
  TriadSpec t;
  t.white_noise_density = non_negative(node, k.white_noise, k.white_noise_unit);
  if (auto bi = node.optional_child("bias_instability")) {
    for (const ConfigNode& term : bi->as_sequence()) {
      term.require_only_keys({k.gm_sigma, "correlation_time_s"});
      GaussMarkovTerm gm;
      gm.sigma = non_negative(term, k.gm_sigma, k.bias_unit);
      gm.correlation_time_s = term.child("correlation_time_s").as_double();
      if (!(gm.correlation_time_s > 0.0)) {
        term.child("correlation_time_s").fail("expected a positive correlation time");
      }
      t.bias_instability.push_back(gm);
    }
  }
  t.turn_on_bias_sigma = non_negative(node, k.turn_on, k.bias_unit);
  t.scale_factor_sigma = non_negative(node, "scale_factor_sigma_ppm", kPerPpm);
  t.misalignment_sigma = non_negative(node, "misalignment_sigma_arcsec", kRadPerArcsec);
  t.quantization_lsb = non_negative(node, k.lsb, k.lsb_unit);
  t.range = non_negative(node, k.range, k.range_unit);
  return t;
}
}  // namespace

SensorSpec parse_sensor_spec(const ConfigNode& config) {
  config.require_only_keys({"name", "gyro", "accelerometer"});
  SensorSpec spec;
  spec.name = config.child("name").as_string();
  // ARW [deg/sqrt(h)] -> [rad/sqrt(s)]: deg -> rad, sqrt(h) = 60 sqrt(s).
  spec.gyro =
      parse_triad(config.child("gyro"),
                  {"angle_random_walk_deg_per_sqrt_h", kRadPerDeg / 60.0, "sigma_deg_per_h",
                   "turn_on_bias_sigma_deg_per_h", kRadPerSecPerDegPerHour,
                   "quantization_lsb_arcsec", kRadPerArcsec, "range_deg_per_s", kRadPerDeg});
  // VRW [ug/sqrt(Hz)] -> [m/s^2/sqrt(Hz)].
  spec.acc = parse_triad(config.child("accelerometer"),
                         {"velocity_random_walk_ug_per_sqrt_hz", kMetrePerSec2PerMicroG, "sigma_ug",
                          "turn_on_bias_sigma_ug", kMetrePerSec2PerMicroG,
                          "quantization_lsb_m_per_s", 1.0, "range_g", kStandardGravity_m_s2});
  return spec;
}

SensorSpec load_sensor_spec(const std::filesystem::path& file) {
  return parse_sensor_spec(ConfigNode::load_file(file));
}

}  // namespace imscal::ims
