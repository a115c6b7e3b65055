// Operating-point cells: assignment of samples to cells, runs of rows per cell, and the blending
// of neighbouring cells (continuous, reproduces cell values at the centres, multilinear).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>
#include <vector>

#include "ident/cell_blending.hpp"
#include "ident/operating_point.hpp"

namespace {
namespace ident = imscal::ident;
using ident::OperatingQuantity;

ident::CellGrid paper_grid() {
  // Paper, Table 2 for a joint with 2 rad/s max speed and 16 kg nominal payload.
  return ident::CellGrid({{OperatingQuantity::kSpeed, {0.0, 0.4, 1.6, 2.0}},
                          {OperatingQuantity::kPayload, {0.0, 8.0, 16.0}}});
}

TEST(CellGrid, IndexingAndLabels) {
  const auto grid = paper_grid();
  EXPECT_EQ(grid.cell_count(), 6);
  const std::vector<int> bands{2, 1};
  EXPECT_EQ(grid.flat_index(bands), 5);  // row-major, payload fastest
  EXPECT_EQ(grid.bands_of(3), (std::vector<int>{1, 1}));
  EXPECT_EQ(grid.label(1), "speed[0,0.4) payload[8,16)");
  EXPECT_EQ(grid.band_distance(0, 5), 3);
  EXPECT_THROW(ident::CellGrid({{OperatingQuantity::kSpeed, {0.0, 0.0}}}), std::invalid_argument);
  EXPECT_THROW(ident::CellGrid({{OperatingQuantity::kSpeed, {0.0, 1.0}},
                                {OperatingQuantity::kSpeed, {0.0, 1.0}}}),
               std::invalid_argument);
}

TEST(CellGrid, SamplesAssignedByTheirOperatingPoint) {
  // q_d(t) = 0.5 (t + 1 ms)² at 2 ms: speed t + 0.001 rad/s (central differences of a parabola
  // are exact), so no sample sits on a band bound.
  const double dt = 0.002;
  const std::size_t n = 1500;  // t up to 3 s: beyond the max speed of 2 rad/s
  std::vector<double> q(n), payload(n);
  for (std::size_t k = 0; k < n; ++k) {
    const double t = double(k) * dt;
    q[k] = 0.5 * (t + 0.001) * (t + 0.001);
    payload[k] = k < 700 ? 5.0 : 12.0;
  }
  const std::vector<std::pair<std::size_t, std::size_t>> segments{{0, n}};
  const auto signals = ident::operating_signals(q, segments, dt);
  EXPECT_NEAR(signals.speed_rad_s[500], 1.001, 1e-12);       // t = 1 s; rounding only
  EXPECT_NEAR(signals.acceleration_rad_s2[500], 1.0, 1e-6);  // second difference of t²/2
  const auto grid = paper_grid();
  const auto cells = ident::assign_cells(grid, q, payload, signals);
  for (std::size_t k = 1; k + 1 < n; ++k) {
    const double speed = double(k) * dt + 0.001;
    const int speed_band = speed < 0.4 ? 0 : speed < 1.6 ? 1 : 2;  // above 2 rad/s: the last
    const int payload_band = payload[k] < 8.0 ? 0 : 1;
    ASSERT_EQ(cells[k], speed_band * 2 + payload_band) << "sample " << k;
  }
  // Runs: speed crosses 0.4 at sample 200, payload changes at 700, speed crosses 1.6 at 800.
  const auto runs = ident::cell_runs(cells, grid.cell_count(), segments);
  ASSERT_EQ(runs[0].size(), 1u);
  EXPECT_EQ(runs[0][0].begin, 0u);
  EXPECT_EQ(runs[0][0].end, 200u);
  ASSERT_EQ(runs[2].size(), 1u);
  EXPECT_EQ(runs[2][0].begin, 200u);
  EXPECT_EQ(runs[2][0].end, 700u);
  ASSERT_EQ(runs[3].size(), 1u);
  EXPECT_EQ(runs[3][0].end, 800u);
  EXPECT_TRUE(runs[1].empty());
  // Views for ARX work reach `history` samples back into the previous cell.
  const auto views = ident::run_views(runs[2], q, q, 10);
  ASSERT_EQ(views.size(), 1u);
  EXPECT_EQ(views[0].input.data(), q.data() + 190);
  EXPECT_EQ(views[0].input.size(), 510u);
}

// Blending against an independent truth: a function that is multilinear in each cell-centre
// interval is reproduced exactly by multilinear interpolation of its values at the centres.
TEST(CellBlending, ReproducesCentresAndBilinearFunctions) {
  const std::vector<double> c0{0.2, 1.0, 1.8}, c1{4.0, 12.0};
  const std::array<std::span<const double>, 2> centres{c0, c1};
  auto value_at = [&](int i, int j) { return 3.0 * c0[i] - 2.0 * c1[j] + 0.5 * c0[i] * c1[j]; };
  auto blended = [&](double x, double y) {
    const std::array<double, 2> point{x, y};
    const auto b = ident::blend_cells(centres, point);
    double sum = 0.0, weights = 0.0;
    for (int k = 0; k < b.count; ++k) {
      sum += b.weight[k] * value_at(b.cell[k] / 2, b.cell[k] % 2);
      weights += b.weight[k];
    }
    EXPECT_NEAR(weights, 1.0, 1e-15);  // a partition of unity, up to rounding
    return sum;
  };
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 2; ++j) {
      const std::array<double, 2> point{c0[i], c1[j]};
      const auto b = ident::blend_cells(centres, point);
      ASSERT_EQ(b.count, 1);  // at a centre: that cell alone
      EXPECT_EQ(b.cell[0], i * 2 + j);
      EXPECT_EQ(b.weight[0], 1.0);
    }
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> x(0.2, 1.8), y(4.0, 12.0);
  for (int k = 0; k < 200; ++k) {
    const double px = x(rng), py = y(rng);
    const double truth = 3.0 * px - 2.0 * py + 0.5 * px * py;  // bilinear: exact inside
    EXPECT_NEAR(blended(px, py), truth, 1e-12);                // rounding of a few products
  }
  // Outside the centres: the outermost cells, constant.
  EXPECT_NEAR(blended(5.0, 20.0), value_at(2, 1), 1e-12);
  EXPECT_NEAR(blended(-1.0, 0.0), value_at(0, 0), 1e-12);
}

TEST(CellBlending, ContinuousAcrossCellBoundaries) {
  // Arbitrary (non-smooth) cell values; walking through the speed range in tiny steps, the
  // blended value never jumps: its change per step is bounded by the largest slope between
  // neighbouring centres times the step (plus rounding).
  const auto grid = paper_grid();
  const auto c_speed = grid.dimensions()[0].centres();
  const auto c_payload = grid.dimensions()[1].centres();
  const std::array<std::span<const double>, 2> centres{c_speed, c_payload};
  const std::array<double, 6> cell_value{1.0, -4.0, 7.5, 0.3, -2.0, 9.0};
  double max_slope = 0.0;
  for (int i = 0; i + 1 < 3; ++i)
    for (int j = 0; j < 2; ++j)
      max_slope =
          std::max(max_slope, std::abs(cell_value[(i + 1) * 2 + j] - cell_value[i * 2 + j]) /
                                  (c_speed[i + 1] - c_speed[i]));
  const double step = 1e-5;
  double previous = 0.0;
  for (int k = 0; k <= 250000; ++k) {
    const std::array<double, 2> point{k * step, 6.0};
    const auto b = ident::blend_cells(centres, point);
    double v = 0.0;
    for (int c = 0; c < b.count; ++c) v += b.weight[c] * cell_value[std::size_t(b.cell[c])];
    if (k > 0) {
      ASSERT_LE(std::abs(v - previous), max_slope * step + 1e-12) << "speed " << k * step;
    }
    previous = v;
  }
}

TEST(CellBlending, RefusesMismatchedDimensions) {
  const std::vector<double> c0{1.0, 2.0};
  const std::array<std::span<const double>, 1> centres{c0};
  const std::array<double, 2> point{1.0, 2.0};
  EXPECT_EQ(ident::blend_cells(centres, point).count, 0);
}

}  // namespace
