// Path deviation against closed forms: an offset parallel line, a late robot on the right line, a
// circle of another radius, the paper's line there and back, and the cycles' scatter floor.
#include "eval/path_deviation.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace imscal::eval {
namespace {

std::vector<TimedPoint> line(double t0, double t1, double dt, const Eigen::Vector3d& start,
                             const Eigen::Vector3d& velocity) {
  std::vector<TimedPoint> points;
  for (double t = t0; t <= t1 + 1e-12; t += dt) points.push_back({t, start + velocity * (t - t0)});
  return points;
}

TEST(PathDeviation, ParallelOffsetLineGivesTheOffset) {
  const Eigen::Vector3d v(0.0, -0.4, 0.0);
  const auto desired = line(0.0, 2.0, 0.002, Eigen::Vector3d(1.4, 0.4, 0.8), v);
  // Actual: 5 mm off in z and 3 mm off in x, at another sampling, within the line's extent.
  const auto actual = line(0.01, 1.99, 0.001, Eigen::Vector3d(1.403, 0.396, 0.805), v);
  const PathDeviation d = path_deviation(desired, actual);
  // Closed form: sqrt(3^2 + 5^2) mm for every point; rounding only (1e-12 m).
  for (double value : d.deviation_m) EXPECT_NEAR(value, std::hypot(0.003, 0.005), 1e-12);
  EXPECT_NEAR(d.max_m, std::hypot(0.003, 0.005), 1e-12);
}

TEST(PathDeviation, ALateRobotOnTheRightLineHasNoPathDeviation) {
  const Eigen::Vector3d v(0.3, 0.0, -0.1);
  const auto desired = line(0.0, 2.0, 0.002, Eigen::Vector3d::Zero(), v);
  // The actual point at time t is where the desired one was 50 ms earlier.
  std::vector<TimedPoint> actual;
  for (double t = 0.1; t < 1.9; t += 0.001) actual.push_back({t, v * (t - 0.05)});
  const PathDeviation d = path_deviation(desired, actual);
  EXPECT_LT(d.max_m, 1e-12);  // on the line: rounding only
}

TEST(PathDeviation, CircleOfAnotherRadius) {
  const double r = 0.1, dr = 0.002;  // desired radius, actual 2 mm larger
  std::vector<TimedPoint> desired, actual;
  for (int k = 0; k <= 2000; ++k) {
    const double t = k * 0.002, phi = t;  // 1 rad/s
    desired.push_back({t, Eigen::Vector3d(r * std::cos(phi), r * std::sin(phi), 0.5)});
  }
  for (int k = 20; k < 3990; ++k) {               // phi >= 0.007: within the desired arc
    const double t = k * 0.001, phi = t - 0.013;  // late, and off at another sampling
    actual.push_back({t, Eigen::Vector3d((r + dr) * std::cos(phi), (r + dr) * std::sin(phi), 0.5)});
  }
  const PathDeviation d = path_deviation(desired, actual);
  // The polyline's chords lie inside the circle by up to ds^2 / (8 r) = (2e-4)^2 / 0.8 = 5e-8 m.
  for (double value : d.deviation_m) EXPECT_NEAR(value, dr, 6e-8);
}

TEST(PathDeviation, ThereAndBackIsMatchedToTheRightPass) {
  // Line there (0..2 s), 1 s pause, back (3..5 s) displaced by 1 mm in z on the way back only;
  // the actual way there is exact. With a window the way back is compared with the way back.
  auto desired = line(0.0, 2.0, 0.002, Eigen::Vector3d(0, 0.4, 0), Eigen::Vector3d(0, -0.4, 0));
  for (double t = 2.002; t < 3.0; t += 0.002) desired.push_back({t, Eigen::Vector3d(0, -0.4, 0)});
  for (const auto& p :
       line(3.0, 5.0, 0.002, Eigen::Vector3d(0, -0.4, 0.01), Eigen::Vector3d(0, 0.4, 0))) {
    desired.push_back(p);
  }
  auto actual = line(0.0, 2.0, 0.002, Eigen::Vector3d(0, 0.4, 0), Eigen::Vector3d(0, -0.4, 0));
  for (const auto& p :
       line(3.5, 4.5, 0.002, Eigen::Vector3d(0, -0.2, 0.011), Eigen::Vector3d(0, 0.4, 0))) {
    actual.push_back(p);
  }
  const PathDeviation d = path_deviation(desired, actual, 0.5);
  // Way back 1 mm above its desired line (10 mm above the way there): 1 mm, not 11 mm or 0.
  EXPECT_NEAR(d.max_m, 0.001, 1e-12);
  EXPECT_GT(d.t_s[d.index_of_max], 3.0);
}

TEST(PathDeviation, RefusesTooFewPointsAndBadWindow) {
  EXPECT_THROW(path_deviation({{0.0, Eigen::Vector3d::Zero()}}, {}), std::invalid_argument);
  const auto desired = line(0.0, 1.0, 0.1, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX());
  EXPECT_THROW(path_deviation(desired, desired, 0.0), std::invalid_argument);
}

TEST(PathDeviation, ScatterFloorAndTheSplitAboutTheMeanFollowTheClosedForm) {
  // Three cycles on a line along y, offset by +0.3, -0.1 and +0.1 mm in x; cycle 1 also lifts by
  // 0.4 mm in z at one instant (t = 1 s) and runs late by 20 ms (along the line: no deviation).
  const Eigen::Vector3d v(0.0, 0.4, 0.0);
  const auto desired = line(0.0, 2.0, 0.002, Eigen::Vector3d::Zero(), v);
  auto cycle = [&](double dx_m, double late_s) {
    std::vector<TimedPoint> points;
    for (int k = 50; k <= 950; ++k) {
      const double t = 0.002 * k;
      Eigen::Vector3d p = v * (t - late_s) + Eigen::Vector3d(dx_m, 0, 0);
      if (k == 500 && late_s > 0) p.z() += 0.4e-3;
      points.push_back({t, p});
    }
    return points;
  };
  std::vector<PathDeviation> cycles;
  for (auto [dx, late] : {std::pair{0.3e-3, 0.0}, {-0.1e-3, 0.02}, {0.1e-3, 0.0}})
    cycles.push_back(path_deviation(desired, cycle(dx, late)));
  // Closed form: everywhere the widest pair is 0.4 mm apart (floor 0.2 mm); at t = 1 s cycles 0
  // and 1 are hypot(0.4, 0.4) mm apart. Rounding only (1e-12 m).
  EXPECT_NEAR(scatter_floor_m(cycles), 0.5 * std::hypot(0.4e-3, 0.4e-3), 1e-12);
  // The floor is a lower bound of the max deviation over the cycles, and one cycle has none.
  double max_m = 0.0;
  for (const auto& d : cycles) max_m = std::max(max_m, d.max_m);
  EXPECT_LE(scatter_floor_m(cycles), max_m);
  EXPECT_EQ(scatter_floor_m({cycles[0]}), 0.0);
  // A common shift of every cycle (a command the same in each) leaves the floor unchanged.
  std::vector<PathDeviation> shifted;
  for (auto [dx, late] : {std::pair{0.8e-3, 0.0}, {0.4e-3, 0.02}, {0.6e-3, 0.0}})
    shifted.push_back(path_deviation(desired, cycle(dx, late)));
  EXPECT_NEAR(scatter_floor_m(shifted), scatter_floor_m(cycles), 1e-12);

  // The split about the mean, closed form: the x offsets 0.3, -0.1, 0.1 mm have the mean 0.1 mm
  // everywhere; at t = 1 s cycle 1 adds 0.4 mm in z, so the mean is (0.1, 0, 0.4 / 3) mm there
  // and cycle 1 lies (-0.2, 0, 0.8 / 3) mm from it: 1/3 mm, the largest distance (elsewhere 0.2).
  // Rounding only (1e-12 m).
  const CycleSplit split = split_cycles(cycles);
  EXPECT_NEAR(split.systematic_max_m, std::hypot(0.1e-3, 0.4e-3 / 3.0), 1e-12);
  EXPECT_NEAR(split.about_mean_max_m, 1e-3 / 3.0, 1e-12);
  // A common shift moves the mean, not the distances from it; the latter are >= the floor.
  const CycleSplit shifted_split = split_cycles(shifted);
  EXPECT_NEAR(shifted_split.systematic_max_m, std::hypot(0.6e-3, 0.4e-3 / 3.0), 1e-12);
  EXPECT_NEAR(shifted_split.about_mean_max_m, split.about_mean_max_m, 1e-12);
  EXPECT_GE(split.about_mean_max_m, scatter_floor_m(cycles));
  EXPECT_EQ(split_cycles({cycles[0]}).about_mean_max_m, 0.0);
}

}  // namespace
}  // namespace imscal::eval
