#pragma once
// Frames and conventions of imscal, stated once (see docs/ARCHITECTURE.md).
//
// - T_A_B maps coordinates in frame B into frame A: p_A = T_A_B * p_B. Rotations likewise
//   (R_A_B, q_A_B).
// - W: the Earth-fixed local-level frame at the site, axes East-North-Up (ENU), origin at the
//   site's geodetic point (latitude, longitude, height on WGS84). W rotates with the Earth; it is
//   not inertial: the Earth rate omega_ie appears in W as (0, Omega cos(lat), Omega sin(lat)).
// - S: the IMS sensor frame (accelerometer/gyro triad axes after misalignment correction).
// - R: robot base frame; H: hand (flange) frame.
// - Navigation states are expressed in W: attitude q_W_S, velocity v_W relative to the Earth,
//   position p_W.
//
// Units are SI everywhere inside the code: m, s, rad, m/s, m/s^2, rad/s.
namespace imscal::ims {
inline constexpr const char* kWorldFrameAxes = "ENU";
}  // namespace imscal::ims
