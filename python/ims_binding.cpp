// imscal.read_imu and imscal.mechanize: raw IMS files (ims/imu_file.hpp) and their strapdown
// mechanization (ims/mechanization_start.hpp, ims/strapdown.hpp), as `imscal mechanize` does it.
#include <array>
#include <optional>
#include <string>

#include "ims/imu_file.hpp"
#include "ims/mechanization_start.hpp"
#include "ims/strapdown.hpp"
#include "python/bindings.hpp"

namespace imscal::python {
namespace {

using namespace pybind11::literals;

py::dict imu_dict(const ims::ImuSeries& series) {
  const auto& s = series.samples;
  py::dict metadata;
  for (const auto& [key, value] : series.metadata) metadata[py::str(key)] = value;
  py::object site = py::none();
  if (series.site)
    site = py::make_tuple(series.site->latitude_deg, series.site->longitude_deg,
                          series.site->height_m);
  const bool increments = series.quantity == ims::ImuQuantity::kIncrements;
  return py::dict(
      "t_s"_a =
          matrix(s.size(), 1, [&](std::size_t r, std::size_t) { return s[r].t_s; }).attr("ravel")(),
      "gyro"_a =
          matrix(s.size(), 3, [&](std::size_t r, std::size_t c) { return s[r].gyro[long(c)]; }),
      "acc"_a =
          matrix(s.size(), 3, [&](std::size_t r, std::size_t c) { return s[r].acc[long(c)]; }),
      "quantity"_a = increments ? "increments" : "rates",
      "units"_a = increments ? py::make_tuple("rad", "m/s") : py::make_tuple("rad/s", "m/s^2"),
      "nominal_dt_s"_a = series.nominal_dt_s, "site"_a = site, "metadata"_a = metadata);
}

py::dict read_imu(const std::string& file) {
  return imu_dict(ims::read_imu_file(file));
}

py::dict mechanize(const std::string& file, std::optional<double> align_s,
                   std::optional<std::array<double, 3>> initial_attitude_deg,
                   std::optional<std::array<double, 3>> site, const std::string& sensor_errors,
                   std::optional<double> heading_deg, double heading_sigma_deg) {
  ims::MechanizationRequest request;
  request.input = file;
  request.align_s = align_s;
  if (initial_attitude_deg) {
    const auto& a = *initial_attitude_deg;
    request.initial_attitude_deg = Eigen::Vector3d(a[0], a[1], a[2]);
  }
  if (site) request.site = ims::Site{(*site)[0], (*site)[1], (*site)[2]};
  request.sensor_errors = sensor_errors;
  request.heading_deg = heading_deg;
  request.heading_sigma_deg = heading_sigma_deg;
  request.origin = "<python call>";
  const ims::MechanizationStart start = ims::prepare_mechanization(request);
  const std::vector<ims::NavState> s =
      ims::mechanize(start.increments, *start.earth, start.initial);
  return py::dict(
      "t_s"_a =
          matrix(s.size(), 1, [&](std::size_t r, std::size_t) { return s[r].t_s; }).attr("ravel")(),
      "p_W_m"_a =
          matrix(s.size(), 3, [&](std::size_t r, std::size_t c) { return s[r].p_W[long(c)]; }),
      "v_W_m_s"_a =
          matrix(s.size(), 3, [&](std::size_t r, std::size_t c) { return s[r].v_W[long(c)]; }),
      "q_W_S_wxyz"_a =
          matrix(s.size(), 4,
                 [&](std::size_t r, std::size_t c) { return quaternion_wxyz(s[r].q_W_S, c); }),
      "attitude_source"_a = start.attitude_source);
}

}  // namespace

void bind_ims(py::module_& m) {
  m.def("read_imu", &read_imu, "file"_a,
        "Reads a raw IMS file (.csv, .imsb, PSINS .imu) into numpy arrays: t_s (N,), gyro and acc "
        "(N, 3) in the sensor frame S, as increments [rad, m/s] or rates [rad/s, m/s^2] "
        "('quantity'), nominal_dt_s, site (lat_deg, lon_deg, h_m) or None, metadata.");
  m.def("mechanize", &mechanize, "file"_a, py::kw_only(), "align_s"_a = py::none(),
        "initial_attitude_deg"_a = py::none(), "site"_a = py::none(), "sensor_errors"_a = "",
        "heading_deg"_a = py::none(), "heading_sigma_deg"_a = 0.001,
        "Strapdown mechanization of a raw IMS file, as `imscal mechanize`: give align_s (coarse "
        "alignment over the first seconds, at rest) or initial_attitude_deg (roll, pitch, "
        "heading). Returns t_s, p_W_m, v_W_m_s, q_W_S_wxyz (W = ENU at the site; row 0 is the "
        "initial state) and attitude_source.");
}

}  // namespace imscal::python
