#include "calib/calibration_config.hpp"

#include <fmt/format.h>

#include <cmath>
#include <numbers>

#include "core/input_error.hpp"
#include "core/units.hpp"

namespace imscal::calib {
namespace {

namespace fs = std::filesystem;

// A number from `key` that satisfies `ok`, or `fallback` when the key is absent.
template <typename Predicate>
double number(const ConfigNode& node, const char* key, double fallback, Predicate ok,
              const char* expected) {
  const auto child = node.optional_child(key);
  if (!child) return fallback;
  const double v = child->as_double();
  if (!ok(v)) child->fail(fmt::format("expected {}, got {}", expected, v));
  return v;
}

double positive(const ConfigNode& node, const char* key, double fallback) {
  return number(
      node, key, fallback, [](double v) { return v > 0.0; }, "a number > 0");
}

double non_negative(const ConfigNode& node, const char* key, double fallback) {
  return number(
      node, key, fallback, [](double v) { return v >= 0.0; }, "a number >= 0");
}

std::optional<fs::path> existing_file(const ConfigNode& root, const char* key) {
  const auto child = root.optional_child(key);
  if (!child) return std::nullopt;
  return child->as_existing_file();
}

void parse_thresholds(const ConfigNode& node, MountingValidationOptions& v) {
  node.require_only_keys({"halves", "segments", "segment_rests", "max_outliers_pass",
                          "max_outlier_fraction_warn", "repeat_warn_sigma", "repeat_fail_sigma",
                          "repeat_rotation_floor_deg", "repeat_translation_floor_mm", "slip_sigma",
                          "max_rotation_sigma_deg", "max_translation_sigma_mm"});
  auto& t = v.thresholds;
  v.check_halves = node.get_bool("halves", v.check_halves);
  v.check_segments = node.get_bool("segments", v.check_segments);
  if (auto c = node.optional_child("segment_rests")) {
    const long k = c->as_int();
    if (k < 3) c->fail("expected an integer >= 3 (the bundle needs 3 rests)");
    v.segment_rests = std::size_t(k);
  }
  if (auto c = node.optional_child("max_outliers_pass")) {
    const long k = c->as_int();
    if (k < 0) c->fail("expected an integer >= 0");
    t.max_outliers_pass = std::size_t(k);
  }
  t.max_outlier_fraction_warn = number(
      node, "max_outlier_fraction_warn", t.max_outlier_fraction_warn,
      [](double x) { return x >= 0.0 && x <= 1.0; }, "a fraction in [0, 1]");
  t.repeat_warn_sigma = positive(node, "repeat_warn_sigma", t.repeat_warn_sigma);
  t.repeat_fail_sigma = positive(node, "repeat_fail_sigma", t.repeat_fail_sigma);
  if (t.repeat_fail_sigma < t.repeat_warn_sigma)
    node.child("repeat_fail_sigma").fail("must not be below repeat_warn_sigma");
  t.repeat_rotation_floor_rad =
      non_negative(node, "repeat_rotation_floor_deg", t.repeat_rotation_floor_rad / kRadPerDeg) *
      kRadPerDeg;
  t.repeat_translation_floor_m =
      non_negative(node, "repeat_translation_floor_mm", t.repeat_translation_floor_m * 1e3) * 1e-3;
  t.slip_sigma = positive(node, "slip_sigma", t.slip_sigma);
  t.max_rotation_sigma_rad =
      positive(node, "max_rotation_sigma_deg", t.max_rotation_sigma_rad / kRadPerDeg) * kRadPerDeg;
  t.max_translation_sigma_m =
      positive(node, "max_translation_sigma_mm", t.max_translation_sigma_m * 1e3) * 1e-3;
}

// priors: the bias sigmas (default: the sensor spec's) and the rest joint-angle priors.
void parse_priors(const ConfigNode& p, PriorConfig& priors) {
  p.require_only_keys({"gyro_bias_sigma_deg_per_h", "acc_bias_sigma_ug",
                       "deflection_uncertainty_fraction", "joint_sigma_floor_urad"});
  if (p.has("gyro_bias_sigma_deg_per_h"))
    priors.gyro_bias_sigma_rad_s =
        positive(p, "gyro_bias_sigma_deg_per_h", 1.0) * kRadPerDeg / 3600.0;
  if (p.has("acc_bias_sigma_ug"))
    priors.acc_bias_sigma_m_s2 =
        positive(p, "acc_bias_sigma_ug", 1.0) * 1e-6 * kStandardGravity_m_s2;
  priors.deflection_uncertainty_fraction =
      non_negative(p, "deflection_uncertainty_fraction", priors.deflection_uncertainty_fraction);
  priors.joint_sigma_floor_rad =
      non_negative(p, "joint_sigma_floor_urad", priors.joint_sigma_floor_rad * 1e6) * 1e-6;
}

// heading_reference: {yaw_deg, sigma_deg}, both required.
HeadingReference heading_reference(const ConfigNode& h) {
  h.require_only_keys({"yaw_deg", "sigma_deg"});
  HeadingReference reference;
  reference.yaw_rad = h.child("yaw_deg").as_double() * kRadPerDeg;
  const ConfigNode sigma = h.child("sigma_deg");
  if (!(sigma.as_double() > 0.0)) sigma.fail("expected a number > 0 (the reference's 1-sigma)");
  reference.sigma_rad = sigma.as_double() * kRadPerDeg;
  reference.source = fmt::format("{} line {} heading_reference", h.file(), h.line());
  return reference;
}

}  // namespace

CalibrationConfig parse_calibration_config(const ConfigNode& root) {
  root.require_only_keys({"imscal-calibration-config", "sensor", "robot", "payload", "rests",
                          "time_offset", "bundle", "priors", "validation", "joint_errors",
                          "first_rest_position_m", "unit_calibration", "heading_reference"});
  const ConfigNode version = root.child("imscal-calibration-config");
  if (version.as_int() != 1) version.fail("unknown config version; expected 1");
  CalibrationConfig c;
  c.file = root.file();
  c.sensor_file = existing_file(root, "sensor");
  c.robot_file = existing_file(root, "robot");
  c.unit_calibration_file = existing_file(root, "unit_calibration");

  if (auto p = root.optional_child("payload")) {
    p->require_only_keys({"mass_kg", "com_mm"});
    c.payload.mass_kg = non_negative(*p, "mass_kg", 0.0);
    if (auto com = p->optional_child("com_mm")) c.payload.com_T_m = com->as_vector3() * 1e-3;
  }
  if (auto r = root.optional_child("rests")) {
    r->require_only_keys({"min_duration_s", "trim_s", "max_joint_spread_deg",
                          "detector_threshold_sigmas", "settle_tolerance_deg"});
    c.rests.min_duration_s = positive(*r, "min_duration_s", c.rests.min_duration_s);
    c.rests.trim_s = non_negative(*r, "trim_s", c.rests.trim_s);
    c.rests.max_joint_spread_rad =
        positive(*r, "max_joint_spread_deg", c.rests.max_joint_spread_rad / kRadPerDeg) *
        kRadPerDeg;
    c.rests.settle_tolerance_rad =
        non_negative(*r, "settle_tolerance_deg", c.rests.settle_tolerance_rad / kRadPerDeg) *
        kRadPerDeg;
    c.rests.detector_threshold_sigmas =
        positive(*r, "detector_threshold_sigmas", c.rests.detector_threshold_sigmas);
    if (2.0 * c.rests.trim_s >= c.rests.min_duration_s)
      r->fail(fmt::format("trim_s ({} s at each end) leaves nothing of a {} s rest", c.rests.trim_s,
                          c.rests.min_duration_s));
  }
  if (auto t = root.optional_child("time_offset")) {
    t->require_only_keys({"max_abs_offset_s"});
    c.max_abs_time_offset_s = positive(*t, "max_abs_offset_s", c.max_abs_time_offset_s);
  }
  if (auto b = root.optional_child("bundle")) {
    b->require_only_keys({"estimate_time_offset", "estimate_scale_factors", "huber_scale_sigma",
                          "outlier_threshold_sigma", "rate_window_s", "min_rate_deg_s",
                          "max_iterations", "sparse", "estimate_deflection_scale",
                          "deflection_scale_sigma"});
    auto& o = c.bundle;
    o.estimate_time_offset = b->get_bool("estimate_time_offset", o.estimate_time_offset);
    o.estimate_scale_factors = b->get_bool("estimate_scale_factors", o.estimate_scale_factors);
    o.huber_scale_sigma = positive(*b, "huber_scale_sigma", o.huber_scale_sigma);
    o.outlier_threshold_sigma = positive(*b, "outlier_threshold_sigma", o.outlier_threshold_sigma);
    o.rate_window_s = positive(*b, "rate_window_s", o.rate_window_s);
    o.min_rate_rad_s =
        non_negative(*b, "min_rate_deg_s", o.min_rate_rad_s / kRadPerDeg) * kRadPerDeg;
    if (auto it = b->optional_child("max_iterations")) {
      const long n = it->as_int();
      if (n < 1 || n > 10000) it->fail("expected an integer in [1, 10000]");
      o.max_iterations = int(n);
    }
    o.sparse = b->get_bool("sparse", o.sparse);
    o.estimate_deflection_scale =
        b->get_bool("estimate_deflection_scale", o.estimate_deflection_scale);
    o.deflection_scale_sigma = positive(*b, "deflection_scale_sigma", o.deflection_scale_sigma);
  }
  if (auto p = root.optional_child("priors")) parse_priors(*p, c.priors);
  if (auto v = root.optional_child("validation")) parse_thresholds(*v, c.validation);
  c.joint_errors = root.get_bool("joint_errors", c.joint_errors);
  if (auto p = root.optional_child("first_rest_position_m"))
    c.first_rest_position_W_m = p->as_vector3();
  if (auto h = root.optional_child("heading_reference"))
    c.heading_reference = heading_reference(*h);
  return c;
}

CalibrationConfig load_calibration_config(const std::filesystem::path& file) {
  return parse_calibration_config(ConfigNode::load_file(file));
}

ImuNoiseModel imu_noise_model(const ims::SensorSpec& spec, const PriorConfig& priors) {
  auto bias_sigma = [](const ims::TriadSpec& triad) {
    double variance = triad.turn_on_bias_sigma * triad.turn_on_bias_sigma;
    for (const auto& term : triad.bias_instability) variance += term.sigma * term.sigma;
    return std::sqrt(variance);
  };
  ImuNoiseModel m;
  m.gyro_noise_density_rad_per_sqrt_s = spec.gyro.white_noise_density;
  m.acc_noise_density_m_s_per_sqrt_s = spec.acc.white_noise_density;
  m.gyro_bias_sigma_rad_s = priors.gyro_bias_sigma_rad_s.value_or(bias_sigma(spec.gyro));
  m.acc_bias_sigma_m_s2 = priors.acc_bias_sigma_m_s2.value_or(bias_sigma(spec.acc));
  for (const auto& term : spec.acc.bias_instability)
    m.acc_bias_drift_psd += 2.0 * term.sigma * term.sigma / term.correlation_time_s;
  m.gyro_quantization_rad = spec.gyro.quantization_lsb;
  m.acc_quantization_m_s = spec.acc.quantization_lsb;
  return m;
}

}  // namespace imscal::calib
