// ISO 9283 path characteristics on paths whose answers are computed by hand (in the comments).
#include "core/units.hpp"
#include "eval/iso9283_path.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace imscal::eval {
namespace {

// A straight line along +x at speed v from x = 0 to x = 0.8 m, sampled every dt, displaced by
// `offset`, rotated by `rotation` relative to the commanded (identity) attitude.
PoseSeries line(double v, double dt, const Eigen::Vector3d& offset,
                const Eigen::Quaterniond& rotation = Eigen::Quaterniond::Identity()) {
  PoseSeries poses;
  const double duration = 0.8 / v;
  for (double t = 0.0; t <= duration + 1e-12; t += dt) {
    poses.push_back({t, Eigen::Vector3d(v * t, 0.0, 0.0) + offset, rotation});
  }
  return poses;
}

TEST(Iso9283Path, AccuracyAndRepeatabilityOfThreeParallelCycles) {
  const PoseSeries commanded = line(0.5, 0.002, Eigen::Vector3d::Zero());
  const std::vector<PoseSeries> cycles = {line(0.5, 0.001, {0, 0.001, 0}),
                                          line(0.5, 0.001, {0, 0.003, 0}),
                                          line(0.5, 0.001, {0, 0.002, 0})};
  const Iso9283PathResult r = iso9283_path(commanded, cycles, 0.5);
  // Barycentre 2 mm off: AT_p = 2 mm. l_ij = 1, 1, 0 mm, l̄ = 2/3 mm,
  // S_l = sqrt(((1/3)^2 + (1/3)^2 + (2/3)^2) / 2) = sqrt(1/3) mm, RT_p = 2/3 + 3 sqrt(1/3) mm.
  // Tolerance 1e-12 m: interpolation on straight lines is exact up to rounding.
  EXPECT_NEAR(r.AT_p_m, 0.002, 1e-12);
  EXPECT_NEAR(r.RT_p_m, (2.0 / 3.0 + 3.0 * std::sqrt(1.0 / 3.0)) * 1e-3, 1e-12);
  EXPECT_NEAR(r.length_m, 0.8, 1e-12);
  EXPECT_EQ(r.missed_crossings, 0);
  EXPECT_NEAR(r.AV_percent, 0.0, 1e-9);  // every cycle at 0.5 m/s exactly (rounding of dt)
}

TEST(Iso9283Path, OrientationAccuracyAndRepeatability) {
  const PoseSeries commanded = line(0.5, 0.002, Eigen::Vector3d::Zero());
  const auto about_z = [](double deg) {
    return Eigen::Quaterniond(Eigen::AngleAxisd(deg * kRadPerDeg, Eigen::Vector3d::UnitZ()));
  };
  const std::vector<PoseSeries> cycles = {line(0.5, 0.001, {0, 0, 0}, about_z(0.1)),
                                          line(0.5, 0.001, {0, 0, 0}, about_z(0.3))};
  const Iso9283PathResult r = iso9283_path(commanded, cycles, 0.5);
  // c: mean 0.2 deg -> AT_c = 0.2 deg; RT_c = 3 sqrt((0.1^2 + 0.1^2) / 1) deg = 0.42426 deg.
  EXPECT_NEAR(r.AT_abc_rad.z(), 0.2 * kRadPerDeg, 1e-12);
  EXPECT_NEAR(r.RT_abc_rad.z(), 3.0 * std::sqrt(0.02) * kRadPerDeg, 1e-12);
  EXPECT_NEAR(r.AT_abc_rad.x(), 0.0, 1e-15);
  EXPECT_NEAR(r.AT_p_m, 0.0, 1e-12);
}

TEST(Iso9283Path, VelocityAccuracyRepeatabilityAndFluctuation) {
  const double v_c = 0.5;
  const PoseSeries commanded = line(v_c, 0.002, Eigen::Vector3d::Zero());
  // Cycles at 0.49, 0.50, 0.52 m/s (on the commanded clock they are early or late; a wide window
  // still finds the one crossing of each plane).
  std::vector<PoseSeries> cycles = {line(0.49, 0.001, {0, 0, 0}), line(0.50, 0.001, {0, 0, 0}),
                                    line(0.52, 0.001, {0, 0, 0})};
  Iso9283Options options;
  options.time_window_s = 10.0;
  const Iso9283PathResult r = iso9283_path(commanded, cycles, v_c, options);
  // v̄ = 0.503333, AV = 0.6667 %; S_v = sqrt((0.013333^2 + 0.003333^2 + 0.016667^2) / 2)
  // = 0.0152753 m/s, RV = 3 S_v / v_c = 9.1652 %; constant speeds: FV = 0.
  EXPECT_NEAR(r.AV_percent, (1.51 / 3.0 - 0.5) / 0.5 * 100.0, 1e-9);  // 0.6667 %
  EXPECT_NEAR(r.RV_percent, 3.0 * 0.015275252316519466 / 0.5 * 100.0, 1e-9);
  EXPECT_NEAR(r.FV_m_s, 0.0, 1e-9);

  // One cycle whose speed steps from 0.45 to 0.55 m/s halfway: FV = 0.1 m/s.
  PoseSeries stepped;
  double x = 0.0;
  for (double t = 0.0; x <= 0.8; t += 0.001) {
    stepped.push_back({t, Eigen::Vector3d(x, 0, 0), Eigen::Quaterniond::Identity()});
    x += (x < 0.4 ? 0.45 : 0.55) * 0.001;
  }
  const Iso9283PathResult s = iso9283_path(commanded, {stepped}, v_c, options);
  EXPECT_NEAR(s.FV_m_s, 0.1, 1e-9);
  EXPECT_TRUE(std::isnan(s.RT_p_m));  // one cycle: no repeatability
}

TEST(Iso9283Path, ThereAndBackIsMeasuredPassByPass) {
  // Commanded: 0.8 m along +x in 2 s, rest 1 s, back in 2 s. Attained: on the way back 1 mm
  // high, on the way there exact. AT_p = 1 mm, found on the way back.
  auto path = [](double dz_back) {
    PoseSeries p;
    for (int k = 0; k <= 2500; ++k) {
      const double t = k * 0.002;
      double x = t < 2.0 ? 0.4 * t : (t < 3.0 ? 0.8 : 0.8 - 0.4 * (t - 3.0));
      p.push_back(
          {t, Eigen::Vector3d(x, 0, t > 3.0 ? dz_back : 0.0), Eigen::Quaterniond::Identity()});
    }
    return p;
  };
  const Iso9283PathResult r = iso9283_path(path(0.0), {path(0.001)}, 0.0);
  EXPECT_NEAR(r.AT_p_m, 0.001, 1e-12);
  EXPECT_NEAR(r.length_m, 1.6, 1e-9);
  EXPECT_GT(r.arc_length_m[std::distance(
                r.accuracy_m.begin(), std::max_element(r.accuracy_m.begin(), r.accuracy_m.end()))],
            0.8);
}

PathPose at(double x, double y) {
  return {0.0, Eigen::Vector3d(x, y, 0.0), Eigen::Quaterniond::Identity()};
}

TEST(Iso9283Corner, RoundOffAndOvershoot) {
  // Legs +x then +y with the corner at the origin.
  const Eigen::Vector3d start(-0.1, 0, 0), corner(0, 0, 0), end(0, 0.1, 0);
  // Attained 1: the corner replaced by a quarter circle of radius 10 mm tangent to both legs,
  // centre (-0.01, 0.01): CR = r (sqrt(2) - 1) = 4.142 mm, CO = 0.
  PoseSeries rounded;
  for (double x = -0.1; x < -0.01; x += 0.0005) rounded.push_back(at(x, 0));
  for (int k = 0; k <= 900; ++k) {
    const double phi = -M_PI / 2 + (M_PI / 2) * k / 900.0;
    rounded.push_back(at(-0.01 + 0.01 * std::cos(phi), 0.01 + 0.01 * std::sin(phi)));
  }
  for (double y = 0.0105; y <= 0.1; y += 0.0005) rounded.push_back(at(0, y));
  // Attained 2: passes the corner, overshoots to x = +3 mm, returns to the leg at y = 20 mm.
  PoseSeries overshooting;
  for (double x = -0.1; x <= 0.003 + 1e-12; x += 0.0005) overshooting.push_back(at(x, 0));
  for (double y = 0.0005; y <= 0.02; y += 0.0005) {
    overshooting.push_back(at(0.003 * (1.0 - y / 0.02), y));
  }
  const Iso9283CornerResult one = iso9283_corner(start, corner, end, {rounded});
  // The arc is sampled at 0.1 deg: chords lie inside by r (1 - cos(0.05 deg)) = 4e-9 m.
  EXPECT_NEAR(one.CR_m, 0.01 * (std::sqrt(2.0) - 1.0), 1e-8);
  EXPECT_NEAR(one.CO_m, 0.0, 1e-15);
  const Iso9283CornerResult two = iso9283_corner(start, corner, end, {rounded, overshooting});
  EXPECT_NEAR(two.CO_m, 0.003, 1e-12);
  EXPECT_NEAR(two.CR_m, one.CR_m, 1e-15);  // the overshooting cycle passes through the corner
}

TEST(Iso9283Path, RefusesUnusableInput) {
  const PoseSeries commanded = line(0.5, 0.002, Eigen::Vector3d::Zero());
  EXPECT_THROW(iso9283_path(commanded, {}, 0.5), std::invalid_argument);
  EXPECT_THROW(iso9283_path({commanded.front()}, {commanded}, 0.5), std::invalid_argument);
  // An attained path elsewhere in time never crosses within the window.
  PoseSeries late = commanded;
  for (auto& p : late) p.t_s += 100.0;
  EXPECT_THROW(iso9283_path(commanded, {late}, 0.5), std::invalid_argument);
  EXPECT_THROW(iso9283_corner({0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {commanded}), std::invalid_argument);
}

}  // namespace
}  // namespace imscal::eval
