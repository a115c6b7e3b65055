// The coupling of one joint's effect into the others (eval/gap_coupling.hpp) on a synthetic arm
// whose truth is known: joint 2's gap is the inertia torque M_21 q̈_1 of joint 1's modelled motion
// through a first-order lag of 30 ms (a response the 30 ms Laguerre basis holds exactly), joint 3
// couples to joint 1 as strongly but its gap is noise only. The coupling must reach joint 2, leave
// joint 3, and leave on joint 2's held-out rows only its noise.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "eval/gap_coupling.hpp"
#include "eval/gap_diagnosis.hpp"
#include "eval/gap_filters.hpp"

namespace imscal::eval {
namespace {

TEST(GapCoupling, ReachesTheCoupledJointOnlyAndLeavesItsNoise) {
  const std::size_t n = 6000, nj = 6;  // 12 s at 2 ms
  GapSignals s;
  s.cycle_s = 0.002;
  s.runs = {{0, n}};
  for (std::size_t j = 0; j < nj; ++j) s.joint_names.push_back(std::string(1, 'A') + char('1' + j));
  for (std::size_t k = 0; k < n; ++k) s.time_s.push_back(double(k) * s.cycle_s);
  s.mass_matrix_kg_m2.assign(nj * nj, std::vector<double>(n, 0.0));
  for (std::size_t k = 0; k < n; ++k) {
    const double q = 0.3 * std::sin(0.5 * s.time_s[k]);  // a slowly changing pose
    s.mass_matrix_kg_m2[1 * nj + 0][k] = s.mass_matrix_kg_m2[0 * nj + 1][k] = 2.0 + std::cos(q);
    s.mass_matrix_kg_m2[2 * nj + 0][k] = s.mass_matrix_kg_m2[0 * nj + 2][k] = 2.5;
  }
  // Joint 1's modelled gap: a few hundred microradians moving at 1..3 Hz.
  std::vector<std::vector<double>> prediction(nj);
  prediction[0].resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    const double t = s.time_s[k];
    prediction[0][k] =
        2e-4 * std::sin(2.0 * M_PI * 1.1 * t) + 1e-4 * std::sin(2.0 * M_PI * 2.7 * t + 1.0);
  }
  const Column acceleration = run_derivative(run_derivative(to_column(prediction[0]), s), s);
  const Column torque = to_column(s.mass_matrix_kg_m2[1 * nj + 0]).cwiseProduct(acceleration);
  const Column response = 2e-3 * lag(torque, 0.03, s);  // rad: 2 mrad per N m, through 30 ms
  const double noise = 1e-6;
  std::mt19937_64 rng(3);
  std::normal_distribution<double> white(0.0, noise);
  s.gap_rad.assign(nj, std::vector<double>(n));
  for (std::size_t j = 0; j < nj; ++j)
    for (std::size_t k = 0; k < n; ++k)
      s.gap_rad[j][k] = (j == 0   ? prediction[0][k]
                         : j == 1 ? response[Eigen::Index(k)]
                                  : 0.0) +
                        white(rng);
  std::vector<std::vector<double>> residual = s.gap_rad;
  for (std::size_t k = 0; k < n; ++k) residual[0][k] -= prediction[0][k];

  const std::vector<bool> training = training_rows(s, 1.0);
  const CouplingColumns c = coupling_columns(s, prediction, residual, training_folds(s, training));
  ASSERT_EQ(c.joints, std::vector<std::size_t>{1});  // joint 3 (index 2) is noise: not reached
  ASSERT_EQ(c.columns[1].cols(), Eigen::Index(c.parameter_names.size()));
  // Fitted on the training rows, judged on the held-out rows: what is left of joint 2's gap is
  // its white noise (RMS 1e-6 rad); 10 % covers the fitted parameters' own error (~20 parameters
  // from ~3000 rows: sqrt(20 / 3000) ~ 8 % of the noise) and the draw.
  const LinearFit f = fit_columns(c.columns[1], s.gap_rad[1], training);
  const Eigen::VectorXd p = c.columns[1] * f.parameters;
  double energy = 0.0, gap_energy = 0.0;
  std::size_t rows = 0;
  for (std::size_t k = 0; k < n; ++k) {
    if (training[k]) continue;
    const double r = s.gap_rad[1][k] - p[Eigen::Index(k)];
    energy += r * r;
    gap_energy += s.gap_rad[1][k] * s.gap_rad[1][k];
    ++rows;
  }
  EXPECT_GT(std::sqrt(gap_energy / double(rows)), 20.0 * noise);  // a gap well above the noise
  EXPECT_NEAR(std::sqrt(energy / double(rows)), noise, 0.1 * noise);
}

}  // namespace
}  // namespace imscal::eval
