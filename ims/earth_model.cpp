#include "ims/earth_model.hpp"

#include <GeographicLib/Constants.hpp>
#include <GeographicLib/Ellipsoid.hpp>
#include <GeographicLib/Geocentric.hpp>
#include <GeographicLib/NormalGravity.hpp>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace imscal::ims {
namespace {
void check_site(const Site& site) {
  if (!(std::abs(site.latitude_deg) <= 90.0) || !(std::abs(site.longitude_deg) <= 540.0) ||
      !std::isfinite(site.height_m) || std::abs(site.height_m) > 1e5) {
    throw std::invalid_argument(
        "site: latitude must be in [-90, 90] deg, longitude finite, "
        "height within +-100 km");
  }
}
}  // namespace

EarthModel::EarthModel(const Site& site) : site_(site) {
  check_site(site);
  std::vector<double> rotation(9);  // row-major M: geocentric = M * local ENU at the site
  GeographicLib::Geocentric::WGS84().Forward(site.latitude_deg, site.longitude_deg, site.height_m,
                                             origin_E_.x(), origin_E_.y(), origin_E_.z(), rotation);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) R_E_W_(r, c) = rotation[3 * r + c];

  g0_W_ = gravity_exact_W(Eigen::Vector3d::Zero());
  // Central differences over +-1 m: truncation error ~ third derivative * 1 m^2 ~ 1e-18 s^-2,
  // rounding ~ 1e-16 * 10 / 2 m ~ 5e-16 s^-2; both far below the gradient (~3e-6 s^-2).
  const double step_m = 1.0;
  for (int axis = 0; axis < 3; ++axis) {
    Eigen::Vector3d d = Eigen::Vector3d::Zero();
    d[axis] = step_m;
    G_W_.col(axis) = (gravity_exact_W(d) - gravity_exact_W(-d)) / (2.0 * step_m);
  }

  const double phi = site.latitude_deg * M_PI / 180.0;
  omega_ie_W_ = Eigen::Vector3d(0.0, std::cos(phi), std::sin(phi)) * earth_rate_magnitude();

  const GeographicLib::Ellipsoid& ellipsoid = GeographicLib::Ellipsoid::WGS84();
  meridian_radius_m_ = ellipsoid.MeridionalCurvatureRadius(site.latitude_deg);
  transverse_radius_m_ = ellipsoid.TransverseCurvatureRadius(site.latitude_deg);
}

double EarthModel::earth_rate_magnitude() {
  return GeographicLib::Constants::WGS84_omega();
}

Eigen::Vector3d EarthModel::ecef_from_W(const Eigen::Vector3d& p_W) const {
  return origin_E_ + R_E_W_ * p_W;
}

Eigen::Vector3d EarthModel::gravity_exact_W(const Eigen::Vector3d& p_W) const {
  const Eigen::Vector3d p_E = ecef_from_W(p_W);
  Eigen::Vector3d g_E;
  // U() returns the gravity potential and the gravity vector (gravitation + centrifugal).
  GeographicLib::NormalGravity::WGS84().U(p_E.x(), p_E.y(), p_E.z(), g_E.x(), g_E.y(), g_E.z());
  return R_E_W_.transpose() * g_E;
}

Eigen::Vector3d EarthModel::transport_rate_enu(const Eigen::Vector3d& v_enu,
                                               double height_m) const {
  const double phi = site_.latitude_deg * M_PI / 180.0;
  const double rn = transverse_radius_m_ + height_m;
  const double rm = meridian_radius_m_ + height_m;
  return {-v_enu.y() / rm, v_enu.x() / rn, v_enu.x() * std::tan(phi) / rn};
}

Eigen::Vector3d EarthModel::W_from_geodetic(double latitude_deg, double longitude_deg,
                                            double height_m) const {
  Eigen::Vector3d p_E;
  GeographicLib::Geocentric::WGS84().Forward(latitude_deg, longitude_deg, height_m, p_E.x(),
                                             p_E.y(), p_E.z());
  return R_E_W_.transpose() * (p_E - origin_E_);
}

}  // namespace imscal::ims
