#pragma once
// The Earth as the IMS sees it at one site, from GeographicLib (WGS84): normal gravity (with the
// centrifugal part) as a vector field over W, the Earth rotation vector in W, the curvature radii
// and the transport rate of a local-level frame. No gravity formula is written by hand here.
//
// W is the Earth-fixed ENU frame at the site (ims/frames.hpp). Inside the small volume a robot
// covers, gravity is evaluated by its first-order expansion about the site origin,
//   g_W(p) = g_W(0) + G_W * p,
// with the gradient G_W taken from GeographicLib by central differences. The neglected
// second-order term is about 3 g / r^2 * |p|^2 ~ 7e-13 m/s^2 for |p| = 1 m.
//
// References (docs/references.md): [GeographicLib], [WGS84].
#include <Eigen/Core>

namespace imscal::ims {

struct Site {
  double latitude_deg = 0.0;   // geodetic, WGS84
  double longitude_deg = 0.0;  // WGS84
  double height_m = 0.0;       // above the ellipsoid
};

class EarthModel {
 public:
  explicit EarthModel(const Site& site);

  const Site& site() const { return site_; }

  // Gravity (gravitation + centrifugal) at p_W [m], expressed in W [m/s^2]; linearised (above).
  Eigen::Vector3d gravity_W(const Eigen::Vector3d& p_W) const { return g0_W_ + G_W_ * p_W; }
  // The same evaluated by GeographicLib at the point itself (slow; for checks).
  Eigen::Vector3d gravity_exact_W(const Eigen::Vector3d& p_W) const;
  const Eigen::Vector3d& gravity_origin_W() const { return g0_W_; }
  const Eigen::Matrix3d& gravity_gradient_W() const { return G_W_; }
  // |g| at the site origin [m/s^2]: what a static accelerometer triad should read.
  double normal_gravity_magnitude() const { return g0_W_.norm(); }

  // Earth rotation vector omega_ie expressed in W [rad/s].
  const Eigen::Vector3d& earth_rate_W() const { return omega_ie_W_; }
  static double earth_rate_magnitude();  // WGS84 Omega [rad/s]

  // Radii of curvature of the ellipsoid at the site latitude [m].
  double meridian_radius() const { return meridian_radius_m_; }
  double transverse_radius() const { return transverse_radius_m_; }
  // Transport rate omega_en of a local-level ENU frame moving with v_enu [m/s] at height h [m]
  // over the ellipsoid at the site latitude, in ENU [rad/s]. Zero for the Earth-fixed W itself.
  Eigen::Vector3d transport_rate_enu(const Eigen::Vector3d& v_enu, double height_m) const;

  // Geometry between W and the Earth-centred Earth-fixed frame E.
  const Eigen::Matrix3d& R_E_W() const { return R_E_W_; }
  Eigen::Vector3d ecef_from_W(const Eigen::Vector3d& p_W) const;
  Eigen::Vector3d W_from_geodetic(double latitude_deg, double longitude_deg, double height_m) const;

 private:
  Site site_;
  Eigen::Vector3d origin_E_;
  Eigen::Matrix3d R_E_W_;
  Eigen::Vector3d g0_W_;
  Eigen::Matrix3d G_W_;
  Eigen::Vector3d omega_ie_W_;
  double meridian_radius_m_ = 0.0;
  double transverse_radius_m_ = 0.0;
};

}  // namespace imscal::ims
