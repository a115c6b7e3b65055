// Order and dead-time selection: the sweep's criterion values against direct fits on the same
// rows, and the true structure chosen for random stable systems (the selection rate is printed).
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <complex>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "ident/arx_fit.hpp"
#include "ident/order_selection.hpp"
#include "tests/support/arx_systems.hpp"

using imscal::ident::ArxModel;
using imscal::ident::ArxStructure;
using imscal::ident::fit_arx;
using imscal::ident::IoSegment;
using imscal::ident::OrderCandidate;
using imscal::ident::OrderCriterion;
using imscal::ident::OrderSelectionOptions;
using imscal::ident::residual_sum_of_squares;
using imscal::ident::select_arx_order;

namespace {

using imscal::test_support::random_system;
using imscal::test_support::view;
using Record = imscal::test_support::ArxRecord;

// White Gaussian input (persistently exciting of every order) and white equation noise.
Record simulate(const ArxModel& m, std::size_t n, double noise_std, std::mt19937_64& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<double> u(n), e(n);
  for (auto& v : u) v = normal(rng);
  for (auto& v : e) v = noise_std * normal(rng);
  return imscal::test_support::simulate_arx(m, std::move(u), std::move(e));
}

}  // namespace

TEST(OrderSelection, SweepValuesEqualDirectFitsOnTheSameRows) {
  std::mt19937_64 rng(17);
  const ArxModel truth = random_system({3, 2, 2}, rng);
  const Record est_a = simulate(truth, 1200, 0.2, rng), est_b = simulate(truth, 800, 0.2, rng);
  const Record val = simulate(truth, 1000, 0.2, rng);
  const std::vector<IoSegment> estimation{view(est_a), view(est_b)};
  const std::vector<IoSegment> validation{view(val)};
  OrderSelectionOptions options;
  options.grid = {0, 5, 1, 4, 0, 4};
  const auto result = select_arx_order(estimation, options, validation);
  ASSERT_EQ(result.candidates.size(), 5u * 4u * 6u);
  const int first_row = 4 + 4 - 1;  // largest lag of the grid: max(na_max, d_max + nb_max - 1)
  // Trimming each segment so that a candidate's own first row lands on the grid's first row
  // makes fit_arx use exactly the sweep's rows.
  auto trimmed = [&](const std::vector<IoSegment>& data, const ArxStructure& s) {
    std::vector<IoSegment> out;
    const std::size_t skip = std::size_t(first_row - s.max_lag());
    for (const auto& seg : data) out.push_back({seg.input.subspan(skip), seg.output.subspan(skip)});
    return out;
  };
  for (const OrderCandidate& c : result.candidates) {
    ASSERT_TRUE(c.valid) << to_string(c.structure);
    const auto fit = fit_arx(trimmed(estimation, c.structure), c.structure);
    ASSERT_EQ(fit.row_count, result.estimation_rows);
    const double n = double(fit.row_count);
    // The sweep's RSS comes from Gram entries (yᵀy − ‖z‖²): cancellation costs ~1e-16 × yᵀy/RSS
    // ≈ 1e-14 relative here; 1e-9 covers it with margin and still catches any wrong row or lag.
    EXPECT_NEAR(c.loss, fit.residual_sum_of_squares / n, 1e-9 * c.loss) << to_string(c.structure);
    const int p = c.structure.parameter_count();
    EXPECT_NEAR(c.bic, n * std::log(c.loss) + p * std::log(n), 1e-9 * std::abs(c.bic));
    EXPECT_NEAR(c.aic, n * std::log(c.loss) + 2.0 * p, 1e-9 * std::abs(c.aic));
    const auto val_rows = trimmed(validation, c.structure);
    const double val_loss = residual_sum_of_squares(val_rows, c.structure, fit.model.parameters()) /
                            double(result.validation_rows);
    EXPECT_NEAR(c.validation_loss, val_loss, 1e-9 * val_loss) << to_string(c.structure);
  }
  EXPECT_EQ(result.chosen, truth.structure());
  EXPECT_EQ(result.final_fit.model.structure(), result.chosen);
}

TEST(OrderSelection, SelectsTrueOrderAndDeadTimeOfRandomSystems) {
  // 100 random stable systems, na, nb in 1..4, d in 0..4, searched over na, nb in 1..6 and
  // d in 0..6 with BIC (consistent) on 3000 samples at SNR ≈ 15-20 dB.
  std::mt19937_64 rng(2024);
  std::uniform_int_distribution<int> order(1, 4), delay(0, 4);
  const int systems = 100;
  const std::size_t samples = 3000;  // cheap (≈ 1 ms per system), also under ASan/UBSan
  int correct_bic = 0, correct_validation = 0, correct_aic = 0;
  for (int t = 0; t < systems; ++t) {
    const ArxStructure s{order(rng), order(rng), delay(rng)};
    const ArxModel truth = random_system(s, rng);
    const Record rec = simulate(truth, samples, 0.2, rng);
    const std::vector<IoSegment> data{view(rec)};
    OrderSelectionOptions options;
    options.grid = {1, 6, 1, 6, 0, 6};
    const auto result = select_arx_order(data, options);
    if (result.chosen == s) {
      ++correct_bic;
    } else {
      std::printf("system %d: true %s, BIC chose %s\n", t, to_string(s).c_str(),
                  to_string(result.chosen).c_str());
    }
    // The other curves, from the same sweep (reported, not required).
    const OrderCandidate* best_val = nullptr;
    const OrderCandidate* best_aic = nullptr;
    for (const auto& c : result.candidates) {
      if (!c.valid) continue;
      if (!best_val || c.validation_loss < best_val->validation_loss) best_val = &c;
      if (!best_aic || c.aic < best_aic->aic) best_aic = &c;
    }
    correct_validation += best_val->structure == s;
    correct_aic += best_aic->structure == s;
  }
  std::printf("selection rate over %d random systems: BIC %d%%, AIC %d%%, hold-out %d%%\n", systems,
              correct_bic * 100 / systems, correct_aic * 100 / systems,
              correct_validation * 100 / systems);
  RecordProperty("bic_selection_rate_percent", correct_bic * 100 / systems);
  EXPECT_GE(correct_bic, 95);  // the required rate
}

TEST(OrderSelection, ValidationCriterionAndHoldOutSplit) {
  std::mt19937_64 rng(99);
  const ArxModel truth = random_system({2, 3, 3}, rng);
  const Record a = simulate(truth, 2000, 0.1, rng), b = simulate(truth, 1500, 0.1, rng);
  const std::vector<IoSegment> data{view(a), view(b)};
  OrderSelectionOptions options;
  options.grid = {1, 5, 1, 5, 0, 5};
  options.criterion = OrderCriterion::kValidation;
  options.validation_fraction = 0.25;
  const auto result = select_arx_order(data, options);
  const std::size_t first_row = 5 + 5 - 1;
  // Each run is split at 75 %: estimation rows 1500 + 1125 minus the first rows of each part.
  EXPECT_EQ(result.estimation_rows, (1500 - first_row) + (1125 - first_row));
  EXPECT_EQ(result.validation_rows, (500 - first_row) + (375 - first_row));
  // The hold-out loss has no penalty on parameters, so it may pick a larger structure that
  // nests the true one (extra coefficients ≈ 0); it must never drop a true lag.
  const ArxStructure c = result.chosen, t = truth.structure();
  ASSERT_GE(c.na, t.na);
  ASSERT_LE(c.dead_time, t.dead_time);
  ASSERT_GE(c.dead_time + c.nb, t.dead_time + t.nb);
  // The refit on all the data recovers the true θ embedded in the chosen structure (zeros for
  // the extra coefficients) within 4 reported σ (noise 0.1, 3500 samples).
  Eigen::VectorXd embedded = Eigen::VectorXd::Zero(c.parameter_count());
  embedded.head(t.na) = truth.a();
  embedded.segment(c.na + (t.dead_time - c.dead_time), t.nb) = truth.b();
  const Eigen::VectorXd error = result.final_fit.model.parameters() - embedded;
  for (Eigen::Index i = 0; i < error.size(); ++i)
    EXPECT_LT(std::abs(error(i)), 4.0 * result.final_fit.parameter_std(i)) << "parameter " << i;
}

TEST(OrderSelection, RejectsBadGridAndMissingValidation) {
  std::mt19937_64 rng(1);
  const Record r = simulate(random_system({1, 1, 0}, rng), 500, 0.1, rng);
  const std::vector<IoSegment> data{view(r)};
  OrderSelectionOptions options;
  options.grid = {3, 2, 1, 2, 0, 1};
  EXPECT_THROW(select_arx_order(data, options), std::invalid_argument);
  // A tap list shorter than kMaxExtraInputs leaves zeros: the message lists the taps.
  options.grid = {1, 2, 1, 2, 0, 1};
  options.grid.extra_taps = {4, 1, 1};
  try {
    select_arx_order(data, options);
    ADD_FAILURE() << "accepted a zero tap count";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("further inputs' taps 4,1,1,0,0,0,0,0,0,0,0"),
              std::string::npos)
        << e.what();
  }
  options.grid = {1, 2, 1, 2, 0, 1};
  options.validation_fraction = 0.0;
  options.criterion = OrderCriterion::kValidation;
  EXPECT_THROW(select_arx_order(data, options), std::invalid_argument);
}

TEST(OrderSelection, MultiInputSweepEqualsDirectFitsAndFindsTheTrueStructure) {
  // Two further inputs with a fixed number of taps (OrderGrid::extra_taps); the sweep over
  // (na, nb, d) must give the same losses as direct fits on the same rows (1e-9, as above) and
  // choose the true structure.
  std::mt19937_64 rng(31);
  const ArxStructure truth_structure{2, 3, 1, 2, {4, 1}};
  const ArxModel truth = imscal::test_support::random_multi_system(truth_structure, rng);
  const auto est = imscal::test_support::simulate_multi(truth, 3000, 0.05, rng);
  const auto val = imscal::test_support::simulate_multi(truth, 1500, 0.05, rng);
  const std::vector<IoSegment> estimation{est.view()}, validation{val.view()};
  OrderSelectionOptions options;
  options.grid = {0, 4, 1, 4, 0, 3};
  options.grid.extra_taps = {4, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1};
  const auto result = select_arx_order(estimation, options, validation);
  ASSERT_EQ(result.candidates.size(), 5u * 4u * 4u);
  const int first_row = std::max(4, 3 + 4 - 1);  // largest lag of the grid (u and x: d + n - 1)
  for (const OrderCandidate& c : result.candidates) {
    ASSERT_TRUE(c.valid) << to_string(c.structure);
    EXPECT_EQ(c.structure.extra_inputs, 2);
    EXPECT_EQ(c.structure.nx,
              (std::array<int, imscal::ident::kMaxExtraInputs>{4, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0}));
    const std::size_t skip = std::size_t(first_row - c.structure.max_lag());
    const std::vector<IoSegment> rows{estimation[0].subspan(skip)};
    const auto fit = fit_arx(rows, c.structure);
    ASSERT_EQ(fit.row_count, result.estimation_rows) << to_string(c.structure);
    EXPECT_NEAR(c.loss, fit.residual_sum_of_squares / double(fit.row_count), 1e-9 * c.loss)
        << to_string(c.structure);
    const std::vector<IoSegment> val_rows{validation[0].subspan(skip)};
    const double val_loss = residual_sum_of_squares(val_rows, c.structure, fit.model.parameters()) /
                            double(result.validation_rows);
    EXPECT_NEAR(c.validation_loss, val_loss, 1e-9 * val_loss) << to_string(c.structure);
  }
  EXPECT_EQ(result.chosen, truth_structure);
}
