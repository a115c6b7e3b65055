#include "ims/sensor_error_model.hpp"

#include <fmt/format.h>
#include <utility>

#include <Eigen/LU>

#include "core/config_node.hpp"
#include "core/units.hpp"

namespace imscal::ims {

Eigen::Matrix3d TriadErrors::sensitivity() const {
  Eigen::Matrix3d a = Eigen::Matrix3d::Identity() + misalignment;
  a.diagonal() += scale_factor;
  return a;
}

Eigen::Vector3d TriadErrors::apply(const Eigen::Vector3d& true_value, double interval_s) const {
  return sensitivity() * true_value + bias * interval_s;
}

Eigen::Vector3d TriadErrors::correct(const Eigen::Vector3d& raw_value, double interval_s) const {
  // A is within ~1e-3 of I for any real sensor: LU with partial pivoting is exact to ~1e-16.
  return sensitivity().partialPivLu().solve(raw_value - bias * interval_s);
}

ImuSample SensorErrorModel::apply(const ImuSample& s, ImuQuantity quantity,
                                  double interval_s) const {
  const double dt = quantity == ImuQuantity::kIncrements ? interval_s : 1.0;
  return {s.t_s, gyro.apply(s.gyro, dt), acc.apply(s.acc, dt)};
}

ImuSample SensorErrorModel::correct(const ImuSample& s, ImuQuantity quantity,
                                    double interval_s) const {
  const double dt = quantity == ImuQuantity::kIncrements ? interval_s : 1.0;
  return {s.t_s, gyro.correct(s.gyro, dt), acc.correct(s.acc, dt)};
}

double sample_interval(const ImuSeries& series, std::size_t i) {
  return i == 0 ? series.nominal_dt_s : series.samples[i].t_s - series.samples[i - 1].t_s;
}

namespace {
template <typename Op>
ImuSeries map_samples(const ImuSeries& in, Op op) {
  ImuSeries out = in;
  for (std::size_t i = 0; i < in.samples.size(); ++i) {
    out.samples[i] = op(in.samples[i], in.quantity, sample_interval(in, i));
  }
  return out;
}
}  // namespace

ImuSeries apply(const ImuSeries& truth, const SensorErrorModel& errors) {
  return map_samples(
      truth, [&](const ImuSample& s, ImuQuantity q, double dt) { return errors.apply(s, q, dt); });
}

ImuSeries correct(const ImuSeries& raw, const SensorErrorModel& errors) {
  return correct(ImuSeries(raw), errors);
}

ImuSeries correct(ImuSeries&& raw, const SensorErrorModel& errors) {
  // A corrected sample keeps its time stamp, so the intervals after it read as before.
  for (std::size_t i = 0; i < raw.samples.size(); ++i)
    raw.samples[i] = errors.correct(raw.samples[i], raw.quantity, sample_interval(raw, i));
  return std::move(raw);
}

namespace {
Eigen::Matrix3d parse_misalignment(const ConfigNode& node) {
  const auto rows = node.as_sequence();
  if (rows.size() != 3) node.fail("expected 3 rows of 3 numbers");
  Eigen::Matrix3d m;
  for (int r = 0; r < 3; ++r) {
    m.row(r) = rows[static_cast<std::size_t>(r)].as_vector3().transpose();
    if (m(r, r) != 0.0) {
      rows[static_cast<std::size_t>(r)].fail(
          "the diagonal of a misalignment matrix must be 0 (scale factors are separate)");
    }
  }
  return m * kRadPerArcsec;
}

TriadErrors parse_triad(const ConfigNode& node, const char* bias_key, double bias_unit_si) {
  node.require_only_keys({bias_key, "scale_factor_ppm", "misalignment_arcsec"});
  TriadErrors t;
  if (auto b = node.optional_child(bias_key)) t.bias = b->as_vector3() * bias_unit_si;
  if (auto s = node.optional_child("scale_factor_ppm")) {
    t.scale_factor = s->as_vector3() * sensor_units::kPerPpm;
  }
  if (auto m = node.optional_child("misalignment_arcsec")) t.misalignment = parse_misalignment(*m);
  return t;
}

std::string vector_yaml(const Eigen::Vector3d& v) {
  return fmt::format("[{:.17g}, {:.17g}, {:.17g}]", v.x(), v.y(), v.z());
}

std::string triad_yaml(const TriadErrors& t, const char* bias_key, double bias_unit_si) {
  const Eigen::Matrix3d m = t.misalignment / kRadPerArcsec;
  return fmt::format("  {}: {}\n  scale_factor_ppm: {}\n  misalignment_arcsec: [{}, {}, {}]\n",
                     bias_key, vector_yaml(t.bias / bias_unit_si),
                     vector_yaml(t.scale_factor / sensor_units::kPerPpm),
                     vector_yaml(m.row(0).transpose()), vector_yaml(m.row(1).transpose()),
                     vector_yaml(m.row(2).transpose()));
}
}  // namespace

SensorErrorModel parse_sensor_error_model(const ConfigNode& config) {
  config.require_only_keys({"gyro", "accelerometer"});
  SensorErrorModel model;
  if (auto g = config.optional_child("gyro")) {
    model.gyro = parse_triad(*g, "bias_deg_per_h", sensor_units::kRadPerSecPerDegPerHour);
  }
  if (auto a = config.optional_child("accelerometer")) {
    model.acc = parse_triad(*a, "bias_ug", sensor_units::kMetrePerSec2PerMicroG);
  }
  return model;
}

SensorErrorModel load_sensor_error_model(const std::filesystem::path& file) {
  return parse_sensor_error_model(ConfigNode::load_file(file));
}

std::string to_yaml(const SensorErrorModel& errors) {
  return "# Sensor errors: raw = (I + diag(scale_factor) + misalignment) * true + bias\n"
         "gyro:\n" +
         triad_yaml(errors.gyro, "bias_deg_per_h", sensor_units::kRadPerSecPerDegPerHour) +
         "accelerometer:\n" +
         triad_yaml(errors.acc, "bias_ug", sensor_units::kMetrePerSec2PerMicroG);
}

}  // namespace imscal::ims
