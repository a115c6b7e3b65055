// Stability: a known unstable system's model is rejected with the reason, both when checked
// directly and when identified from its data by the per-joint pipeline.
#include <gtest/gtest.h>

#include <complex>
#include <random>
#include <vector>

#include "ident/arx_fit.hpp"
#include "ident/joint_identification.hpp"
#include "ident/model_stability.hpp"
#include "tests/support/arx_systems.hpp"

namespace {
namespace ident = imscal::ident;
using imscal::test_support::polynomial_from_poles;

ident::ArxModel model_with_poles(const std::vector<std::complex<double>>& poles) {
  const Eigen::VectorXd a = polynomial_from_poles(poles);
  Eigen::VectorXd b(2);
  b << 0.5, 0.25;
  return ident::ArxModel({int(poles.size()), 2, 1}, a, b);
}

TEST(ModelStability, KnownPolesJudged) {
  const auto stable =
      ident::check_stability(model_with_poles({{0.6, 0.3}, {0.6, -0.3}, {-0.5, 0}}));
  EXPECT_TRUE(stable.stable);
  EXPECT_TRUE(stable.reason.empty());
  // |0.6 ± 0.3i| = √0.45; eigenvalues of a 3x3 companion matrix: a few ulps.
  EXPECT_NEAR(stable.spectral_radius, std::sqrt(0.45), 1e-12);

  const auto unstable = ident::check_stability(model_with_poles({{1.05, 0}, {0.5, 0}}));
  EXPECT_FALSE(unstable.stable);
  EXPECT_NEAR(unstable.spectral_radius, 1.05, 1e-12);
  EXPECT_NE(unstable.reason.find("unstable: pole 1.050000"), std::string::npos) << unstable.reason;
  EXPECT_NE(unstable.reason.find("1 of 2 poles outside"), std::string::npos) << unstable.reason;

  // A pole just inside the circle passes without margin and fails the default 1e-3 margin.
  const auto marginal = model_with_poles({{0.9995, 0}});
  EXPECT_TRUE(ident::check_stability(marginal, 0.0).stable);
  EXPECT_FALSE(ident::check_stability(marginal).stable);
}

TEST(ModelStability, FIRModelIsStable) {
  const ident::ArxModel fir({0, 2, 0}, Eigen::VectorXd(0), Eigen::Vector2d(1.0, 0.5));
  const auto check = ident::check_stability(fir);
  EXPECT_TRUE(check.stable);
  EXPECT_EQ(check.spectral_radius, 0.0);
}

// Data of an unstable system (poles 1.01 and 0.7, white input, short enough not to overflow):
// the least-squares fit recovers it, so the identified model must be rejected.
TEST(ModelStability, UnstableSystemRejectedByThePipeline) {
  const auto truth = model_with_poles({{1.01, 0}, {0.7, 0}});
  std::mt19937_64 rng(9);
  std::normal_distribution<double> normal(0.0, 1.0);
  const std::size_t n = 600;  // 1.01^600 ≈ 400: grows, stays finite
  std::vector<double> u(n), e(n, 0.0);
  for (auto& v : u) v = normal(rng);
  for (auto& v : e) v = 1e-6 * normal(rng);
  const auto rec = imscal::test_support::simulate_arx(truth, u, e);

  const std::vector<ident::IoSegment> data{imscal::test_support::view(rec)};
  const auto fit = ident::fit_arx(data, truth.structure());
  const auto check = ident::check_stability(fit.model);
  EXPECT_FALSE(check.stable);
  EXPECT_NEAR(check.spectral_radius, 1.01, 1e-4);  // noise 1e-6 on a signal of ~1..400
  EXPECT_NE(check.reason.find("unstable"), std::string::npos);

  // The pipeline on one cell: the cell is rejected with the reason; with no other cell to fill
  // it from, the joint fails and says why.
  const ident::CellGrid grid({{ident::OperatingQuantity::kSpeed, {0.0, 1e9}}});
  ident::JointIdentificationOptions options;
  options.grid = {2, 2, 2, 2, 1, 1};
  options.min_rows_per_cell = 100;
  options.min_rms_speed_rad_s = 0.0;
  options.identify_backlash = false;
  const std::vector<double> payload(n, 0.0);
  const std::vector<std::pair<std::size_t, std::size_t>> segments{{0, n}};
  try {
    ident::identify_joint("A1", rec.u, rec.y, payload, segments, 0.002, grid, options);
    FAIL() << "an unstable model was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("no cell could be identified"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("unstable: pole"), std::string::npos) << e.what();
  }
}

}  // namespace
