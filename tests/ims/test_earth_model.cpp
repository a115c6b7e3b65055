// EarthModel (GeographicLib) against closed forms: Somigliana's normal gravity with the
// second-order free-air reduction, the WGS84 Earth rate, curvature radii and transport rate.
#include <gtest/gtest.h>

#include <cmath>

#include "ims/earth_model.hpp"

using imscal::ims::EarthModel;
using imscal::ims::Site;

namespace {
// WGS84 defining and derived constants (NIMA TR8350.2, table 3.1 / 3.4).
constexpr double kA = 6378137.0;
constexpr double kF = 1.0 / 298.257223563;
constexpr double kE2 = 6.69437999014e-3;
constexpr double kGammaE = 9.7803253359;
constexpr double kSomiK = 0.00193185265241;
constexpr double kM = 0.00344978650684;
constexpr double kOmega = 7.292115e-5;

double somigliana_with_height(double lat_deg, double h) {
  const double s2 = std::pow(std::sin(lat_deg * M_PI / 180.0), 2);
  const double g0 = kGammaE * (1 + kSomiK * s2) / std::sqrt(1 - kE2 * s2);
  return g0 * (1 - 2.0 / kA * (1 + kF + kM - 2 * kF * s2) * h + 3 * h * h / (kA * kA));
}
}  // namespace

TEST(EarthModel, NormalGravityMatchesSomigliana) {
  // The free-air series is good to ~1e-8 m/s^2 below 10 km; allow 1e-6 m/s^2 (0.1 ugal-level
  // differences come from the series truncation, not from the model).
  for (double lat : {-80.0, -34.2, 0.0, 34.246048, 48.7, 89.0}) {
    for (double h : {0.0, 380.0, 2000.0}) {
      EarthModel earth(Site{lat, 108.9, h});
      EXPECT_NEAR(earth.normal_gravity_magnitude(), somigliana_with_height(lat, h), 1e-6)
          << "lat " << lat << " h " << h;
      // Normal gravity is along the ellipsoid normal on the surface; above it, the plumb line
      // curves towards the pole by at most ~8e-9 m/s^2 per metre of height (at 45 deg).
      EXPECT_LT(earth.gravity_origin_W().head<2>().norm(), 1e-8 * h + 1e-9);
      EXPECT_LT(earth.gravity_origin_W().z(), -9.7);
    }
  }
}

TEST(EarthModel, EarthRateInEnu) {
  const double lat = 34.246048;
  EarthModel earth(Site{lat, 108.9, 380});
  const double phi = lat * M_PI / 180.0;
  EXPECT_NEAR(EarthModel::earth_rate_magnitude(), kOmega, 1e-15);
  EXPECT_NEAR(earth.earth_rate_W().x(), 0.0, 1e-20);
  EXPECT_NEAR(earth.earth_rate_W().y(), kOmega * std::cos(phi), 1e-15);
  EXPECT_NEAR(earth.earth_rate_W().z(), kOmega * std::sin(phi), 1e-15);
}

TEST(EarthModel, GravityGradientIsFreeAirAndLinearisationHolds) {
  EarthModel earth(Site{48.7, 9.1, 300});
  // Vertical gradient of normal gravity: about +3.086e-6 s^-2 on g_z (g_z = -|g| weakens upwards).
  EXPECT_NEAR(earth.gravity_gradient_W()(2, 2), 3.086e-6, 0.02e-6);
  // Horizontal gradients are half as large and negative (convergence towards the centre).
  EXPECT_NEAR(earth.gravity_gradient_W()(0, 0), -1.54e-6, 0.05e-6);
  // Linearised field vs GeographicLib at the point, over a robot's workspace (2 m): < 1e-11.
  for (const Eigen::Vector3d& p :
       {Eigen::Vector3d(2, 0, 0), Eigen::Vector3d(-1, 1.5, 0.7), Eigen::Vector3d(0, 0, -2)}) {
    EXPECT_LT((earth.gravity_W(p) - earth.gravity_exact_W(p)).norm(), 1e-11);
  }
}

TEST(EarthModel, CurvatureRadiiAndTransportRate) {
  const double lat = 34.246048, h = 380.0;
  EarthModel earth(Site{lat, 108.9, h});
  const double s2 = std::pow(std::sin(lat * M_PI / 180.0), 2);
  const double rn = kA / std::sqrt(1 - kE2 * s2);
  const double rm = kA * (1 - kE2) / std::pow(1 - kE2 * s2, 1.5);
  EXPECT_NEAR(earth.transverse_radius(), rn, 1e-4);
  EXPECT_NEAR(earth.meridian_radius(), rm, 1e-4);
  const Eigen::Vector3d v(10.0, -5.0, 1.0);
  const Eigen::Vector3d w = earth.transport_rate_enu(v, h);
  EXPECT_NEAR(w.x(), 5.0 / (rm + h), 1e-18);
  EXPECT_NEAR(w.y(), 10.0 / (rn + h), 1e-18);
  EXPECT_NEAR(w.z(), 10.0 * std::tan(lat * M_PI / 180.0) / (rn + h), 1e-18);
}

TEST(EarthModel, GeodeticToWIsEnu) {
  EarthModel earth(Site{34.0, 108.0, 100.0});
  const Eigen::Vector3d up = earth.W_from_geodetic(34.0, 108.0, 110.0);
  EXPECT_NEAR(up.z(), 10.0, 1e-8);
  EXPECT_NEAR(up.head<2>().norm(), 0.0, 1e-8);
  const Eigen::Vector3d north = earth.W_from_geodetic(34.0001, 108.0, 100.0);
  EXPECT_GT(north.y(), 11.0);  // 1e-4 deg of latitude is ~11.09 m
  EXPECT_NEAR(north.x(), 0.0, 1e-6);
}

TEST(EarthModel, RejectsImpossibleSite) {
  EXPECT_THROW(EarthModel(Site{95.0, 0.0, 0.0}), std::invalid_argument);
  EXPECT_THROW(EarthModel(Site{NAN, 0.0, 0.0}), std::invalid_argument);
}
