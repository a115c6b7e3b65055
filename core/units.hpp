#pragma once
// Unit constants, one set for the whole code: multiply a value in the unit after "Per" to get
// the unit before it (x_deg * kRadPerDeg is in rad; x_rad * kDegPerRad in deg). Each is the
// correctly rounded quotient written out here, so that a product with it does not depend on
// where it is used.
#include <numbers>

namespace imscal {

inline constexpr double kRadPerDeg = std::numbers::pi / 180.0;
inline constexpr double kDegPerRad = 180.0 / std::numbers::pi;
inline constexpr double kRadPerArcmin = kRadPerDeg / 60.0;
inline constexpr double kRadPerArcsec = kRadPerDeg / 3600.0;
inline constexpr double kArcminPerRad = kDegPerRad * 60.0;
inline constexpr double kArcsecPerRad = kDegPerRad * 3600.0;
// Standard gravity, 1 g, by definition (3rd CGPM, 1901) [m/s^2].
inline constexpr double kStandardGravity_m_s2 = 9.80665;

}  // namespace imscal
