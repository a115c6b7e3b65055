// The whole table's held-out joint-error fit (ident/table_fit.hpp, JointIdentification::
// table_fit): on a joint whose dynamics change with the speed, identified with two speed cells,
// the library's figure equals the one computed here independently from the stored table as the
// precontrol holds it (each cell's eq. 2 model run free over each held-out stretch, the errors
// blended with ident/cell_blending.hpp's weights), and differs from the cells' own figures,
// which judge each model only on its own held-out runs restarted from the measured output.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "ident/arx_model.hpp"
#include "ident/cell_blending.hpp"
#include "ident/joint_identification.hpp"
#include "ident/operating_point.hpp"

namespace imscal {
namespace {

constexpr double kDt = 0.002;

ident::CellGrid speed_grid() {
  return ident::CellGrid({{ident::OperatingQuantity::kSpeed, {0.0, 0.5, 5.0}}});
}

struct Data {
  std::vector<double> q_desired, q_measured, payload;
  std::vector<std::pair<std::size_t, std::size_t>> segments;
};

// Slow: poles 0.9 +- 0.1i; fast: 0.8 +- 0.2i (static gain 1, d = 1); measurement noise 20 urad.
Data simulate() {
  const std::size_t n = 40000;  // 80 s in two runs
  const std::array<std::array<double, 4>, 2> truth{
      {{-1.8, 0.82, 0.012, 0.008}, {-1.6, 0.68, 0.05, 0.03}}};
  Data d;
  d.q_desired.resize(n);
  d.payload.assign(n, 5.0);
  const double amplitude[] = {0.3, 0.05, 0.02, 0.01};
  const double frequency[] = {0.5, 2.3, 5.1, 7.7};
  for (std::size_t k = 0; k < n; ++k) {
    double q = 0.2;
    for (int i = 0; i < 4; ++i)
      q += amplitude[i] * std::sin(2.0 * std::numbers::pi * frequency[i] * double(k) * kDt + i);
    d.q_desired[k] = q;
  }
  d.segments = {{0, n / 2}, {n / 2, n}};
  const auto signals = ident::operating_signals(d.q_desired, d.segments, kDt);
  std::mt19937_64 rng(11);
  std::normal_distribution<double> noise(0.0, 2e-5);
  std::vector<double> clean(n);
  d.q_measured.resize(n);
  for (const auto& segment : d.segments) {
    const std::size_t begin = segment.first;
    for (std::size_t k = begin; k < segment.second; ++k) {
      const auto& t = truth[std::abs(signals.speed_rad_s[k]) < 0.5 ? 0 : 1];
      const auto y = [&](std::size_t lag) {
        return k >= begin + lag ? clean[k - lag] : d.q_desired[begin];
      };
      const auto u = [&](std::size_t lag) {
        return k >= begin + lag ? d.q_desired[k - lag] : d.q_desired[begin];
      };
      clean[k] = -t[0] * y(1) - t[1] * y(2) + t[2] * u(1) + t[3] * u(2);
      d.q_measured[k] = clean[k] + noise(rng);
    }
  }
  return d;
}

// The table's figure from the stored table: every cell's eq. 2 model (q̂ from q_d, measured
// outputs as the initial values) run over each held-out stretch, Δq̂_c(k) = q_d(k - d) - q̂_c(k),
// blended by the speed; NRMSE fit against the joint error q_d - q_m.
double table_fit_from_table(const ident::JointParameters& joint, const Data& d,
                            double validation_fraction) {
  const auto signals = ident::operating_signals(d.q_desired, d.segments, kDt);
  const std::vector<double> centres = speed_grid().dimensions()[0].centres();
  const std::array<std::span<const double>, 1> centre_spans{centres};
  std::vector<double> residual, reference;
  for (const auto& [segment_begin, segment_end] : d.segments) {
    const std::size_t length = segment_end - segment_begin;
    const std::size_t begin =
        segment_end - std::size_t(std::llround(validation_fraction * double(length)));
    std::vector<std::vector<double>> error(joint.cells.size());
    for (std::size_t c = 0; c < joint.cells.size(); ++c) {
      const ident::CellParameters& p = joint.cells[c];
      const ident::ArxModel model(
          p.structure, Eigen::Map<const Eigen::VectorXd>(p.a.data(), Eigen::Index(p.a.size())),
          Eigen::Map<const Eigen::VectorXd>(p.b.data(), Eigen::Index(p.b.size())));
      const auto lag = std::size_t(p.structure.max_lag());
      const auto d_c = std::size_t(p.structure.dead_time);
      const std::size_t first = begin - lag;  // the held-out stretch starts well inside its run
      const std::span<const double> u(d.q_desired.data() + first, segment_end - first);
      const std::span<const double> y0(d.q_measured.data() + first, lag);
      std::vector<double> simulated(u.size());
      model.simulate(u, y0, simulated);
      for (std::size_t k = begin; k < segment_end; ++k)
        error[c].push_back(d.q_desired[k - d_c] - simulated[k - first]);
    }
    for (std::size_t k = begin; k < segment_end; ++k) {
      const double speed = std::abs(signals.speed_rad_s[k]);
      const ident::CellBlend blend =
          ident::blend_cells(std::span(centre_spans), std::span<const double>(&speed, 1));
      double blended = 0.0;
      for (int i = 0; i < blend.count; ++i)
        blended += blend.weight[std::size_t(i)] *
                   error[std::size_t(blend.cell[std::size_t(i)])][k - begin];
      const double joint_error = d.q_desired[k] - d.q_measured[k];
      residual.push_back(joint_error - blended);
      reference.push_back(joint_error);
    }
  }
  double mean = 0.0, misfit = 0.0, spread = 0.0;
  for (double r : reference) mean += r;
  mean /= double(reference.size());
  for (std::size_t k = 0; k < reference.size(); ++k) {
    misfit += residual[k] * residual[k];
    spread += (reference[k] - mean) * (reference[k] - mean);
  }
  return 100.0 * (1.0 - std::sqrt(misfit / spread));
}

TEST(TableFit, IsTheBlendedTablesFigureAndDiffersFromTheCellsOwn) {
  const Data d = simulate();
  ident::JointIdentificationOptions o;
  o.grid = {1, 3, 1, 3, 0, 2};
  o.identify_backlash = false;  // y = q_m: the independent figure needs no play model
  o.validation_fraction = 0.3;
  const ident::JointIdentification r = ident::identify_joint(
      "A1", d.q_desired, d.q_measured, d.payload, d.segments, kDt, speed_grid(), o);
  ASSERT_EQ(r.cells.size(), 2u);
  for (const auto& c : r.cells) ASSERT_EQ(c.status, ident::CellStatus::kIdentified) << c.label;
  const double independent = table_fit_from_table(r.parameters, d, o.validation_fraction);
  // The same sums in another order and from the stored (angle-form) coefficients: rounding only.
  EXPECT_NEAR(r.table_fit.joint_error_fit_percent, independent, 1e-6);
  EXPECT_EQ(r.table_fit.rows, 2u * 6000u);  // 30 % of each 20 000-sample run
  double cells_own = 0.0;
  std::size_t rows = 0;
  for (const auto& p : r.parameters.cells) {
    cells_own += p.figures.joint_error_fit_percent * double(p.figures.validation_rows);
    rows += p.figures.validation_rows;
  }
  cells_own /= double(rows);
  std::printf("table %.3f %% (independent %.3f %%), cells' own row-weighted %.3f %%\n",
              r.table_fit.joint_error_fit_percent, independent, cells_own);
  // The cells' own figures restart every held-out run of a cell from the measured output; the
  // table runs on through the cell changes with both models blended: they must not agree.
  EXPECT_GT(std::abs(cells_own - r.table_fit.joint_error_fit_percent), 1.0);
}

}  // namespace
}  // namespace imscal
