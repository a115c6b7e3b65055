// The per-joint pipeline on data whose dynamics depend on the operating point: every sample k
// follows the ARX model of its own cell (slow / fast speed band), so each cell's fit must
// recover its own model from its own rows — the truth of "a cell's Gram matrix collects only
// its rows, regressors reach back into other cells". An empty payload band is filled from its
// neighbour, reported with the reason.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "ident/joint_identification.hpp"

namespace {
namespace ident = imscal::ident;

constexpr double kDt = 0.002;

struct CellTruth {
  std::vector<double> a, b;  // na = nb = 2, d = 1
};

// Slow cells: poles 0.9 ± 0.1i; fast cells: 0.8 ± 0.2i; static gain 1 in both.
const std::vector<CellTruth> kTruth{{{-1.8, 0.82}, {0.012, 0.008}}, {{-1.6, 0.68}, {0.05, 0.03}}};

ident::CellGrid grid() {
  return ident::CellGrid({{ident::OperatingQuantity::kSpeed, {0.0, 0.5, 5.0}},
                          {ident::OperatingQuantity::kPayload, {0.0, 10.0, 20.0}}});
}

struct Data {
  std::vector<double> q_desired, q_measured, payload;
  std::vector<std::pair<std::size_t, std::size_t>> segments;
};

Data simulate(double noise, unsigned seed) {
  const std::size_t n = 40000;  // 80 s
  Data d;
  d.q_desired.resize(n);
  d.payload.assign(n, 5.0);  // payload band 1 never visited
  const double amplitude[] = {0.3, 0.05, 0.02, 0.01, 0.005};
  const double frequency[] = {0.5, 2.3, 5.1, 7.7, 11.0};
  for (std::size_t k = 0; k < n; ++k) {
    double q = 0.2;
    for (int i = 0; i < 5; ++i)
      q += amplitude[i] * std::sin(2.0 * std::numbers::pi * frequency[i] * double(k) * kDt + i);
    d.q_desired[k] = q;
  }
  d.segments = {{0, n / 2}, {n / 2, n}};  // two runs
  const auto signals = ident::operating_signals(d.q_desired, d.segments, kDt);
  const auto cells = ident::assign_cells(grid(), d.q_desired, d.payload, signals);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  d.q_measured.resize(n);
  for (const auto& [begin, end] : d.segments) {
    for (std::size_t k = begin; k < end; ++k) {
      const CellTruth& t = kTruth[std::size_t(cells[k] / 2)];  // speed band of sample k
      auto y = [&](std::size_t lag) {
        return k >= begin + lag ? d.q_measured[k - lag] : d.q_desired[begin];
      };
      auto u = [&](std::size_t lag) {
        return k >= begin + lag ? d.q_desired[k - lag] : d.q_desired[begin];
      };
      d.q_measured[k] =
          -t.a[0] * y(1) - t.a[1] * y(2) + t.b[0] * u(1) + t.b[1] * u(2) + noise * normal(rng);
    }
  }
  return d;
}

ident::JointIdentificationOptions options(const ident::OrderGrid& g) {
  ident::JointIdentificationOptions o;
  o.grid = g;
  o.min_rows_per_cell = 1000;
  o.identify_backlash = false;
  return o;
}

TEST(JointIdentification, EachCellRecoversItsOwnModelWithoutNoise) {
  const Data d = simulate(0.0, 1);
  const auto r = ident::identify_joint("A2", d.q_desired, d.q_measured, d.payload, d.segments, kDt,
                                       grid(), options({2, 2, 2, 2, 1, 1}));
  ASSERT_EQ(r.cells.size(), 4u);
  for (int speed_band = 0; speed_band < 2; ++speed_band) {
    const auto& cell = r.parameters.cells[std::size_t(speed_band * 2)];
    ASSERT_EQ(cell.status, ident::CellStatus::kIdentified) << cell.reason;
    const CellTruth& t = kTruth[std::size_t(speed_band)];
    // Noise-free data satisfy the cell's equation exactly on its rows: the least-squares
    // solution is the truth up to the solver's rounding (condition ~1e8 for these smooth,
    // offset signals, QR accuracy ~1e-16 x condition).
    for (int i = 0; i < 2; ++i) {
      EXPECT_NEAR(cell.a[std::size_t(i)], t.a[std::size_t(i)],
                  1e-7 * std::abs(t.a[std::size_t(i)]));
      EXPECT_NEAR(cell.b[std::size_t(i)], t.b[std::size_t(i)],
                  1e-7 * std::abs(t.b[std::size_t(i)]));
    }
    // Held-out rows of the same cell: perfect prediction up to rounding.
    EXPECT_GT(cell.figures.one_step_fit_percent, 99.999);
    EXPECT_GT(cell.figures.simulation_fit_percent, 99.9);
    // Empty payload band: filled from the same speed band (1 band step), with the reason.
    const auto& filled = r.parameters.cells[std::size_t(speed_band * 2 + 1)];
    EXPECT_EQ(filled.status, ident::CellStatus::kFilled);
    EXPECT_EQ(filled.filled_from, speed_band * 2);
    EXPECT_EQ(filled.a, cell.a);
    EXPECT_NE(filled.reason.find("0 estimation rows"), std::string::npos) << filled.reason;
    EXPECT_EQ(r.cells[std::size_t(speed_band * 2 + 1)].reason, filled.reason);
  }
}

TEST(JointIdentification, OrderSweepPerCellFindsTheTrueStructureWithNoise) {
  const Data d = simulate(1e-6, 2);  // white equation noise, 1 µrad
  const auto r = ident::identify_joint("A2", d.q_desired, d.q_measured, d.payload, d.segments, kDt,
                                       grid(), options({1, 4, 1, 3, 0, 3}));
  for (int speed_band = 0; speed_band < 2; ++speed_band) {
    const auto& report = r.cells[std::size_t(speed_band * 2)];
    ASSERT_EQ(report.status, ident::CellStatus::kIdentified) << report.reason;
    ASSERT_TRUE(report.sweep.has_value());
    EXPECT_EQ(report.sweep->chosen, (ident::ArxStructure{2, 2, 1})) << report.label;
    // Unbiased within 4σ (σ from the fit's own covariance; 4: 8 checks at once).
    const auto& fit = *report.fit;
    const CellTruth& t = kTruth[std::size_t(speed_band)];
    const std::vector<double> truth{t.a[0], t.a[1], t.b[0], t.b[1]};
    for (int i = 0; i < 4; ++i)
      EXPECT_NEAR(fit.model.parameters()(i), truth[std::size_t(i)], 4.0 * fit.parameter_std(i));
    ASSERT_TRUE(report.validation.has_value());
    // The residual of the right model is white noise: the whiteness test passes.
    EXPECT_TRUE(report.validation->residual_whiteness.passed);
  }
}

TEST(JointIdentification, TooLittleExcitationReported) {
  Data d = simulate(0.0, 3);
  auto o = options({2, 2, 2, 2, 1, 1});
  o.min_rms_speed_rad_s = 0.7;  // the slow band's RMS speed is below, the fast band's above
  const auto r =
      ident::identify_joint("A2", d.q_desired, d.q_measured, d.payload, d.segments, kDt, grid(), o);
  EXPECT_EQ(r.parameters.cells[0].status, ident::CellStatus::kFilled);
  EXPECT_NE(r.parameters.cells[0].reason.find("too little excitation"), std::string::npos);
  EXPECT_EQ(r.parameters.cells[0].filled_from, 2);
  EXPECT_EQ(r.parameters.cells[2].status, ident::CellStatus::kIdentified);
}

}  // namespace
