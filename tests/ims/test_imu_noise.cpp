// Sensor noise model against theory: white noise (sigma of increments, Allan deviation at
// tau = 1 s), Gauss-Markov steady state and correlation, quantisation with the residual
// carried, saturation, determinism by seed, statistics of the drawn unit errors, and the
// shipped sensor specs.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

#include "ims/imu_noise.hpp"

using namespace imscal::ims;

namespace {
ImuSeries zero_increments(std::size_t n, double dt) {
  ImuSeries s;
  s.quantity = ImuQuantity::kIncrements;
  s.nominal_dt_s = dt;
  for (std::size_t k = 1; k <= n; ++k)
    s.samples.push_back({k * dt, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()});
  return s;
}

// Overlapping Allan variance at tau = m dt from the increments of one channel.
double allan_variance(const std::vector<double>& increments, std::size_t m, double dt) {
  std::vector<double> cumulative(increments.size() + 1, 0.0);
  for (std::size_t k = 0; k < increments.size(); ++k) {
    cumulative[k + 1] = cumulative[k] + increments[k];
  }
  double sum = 0.0;
  const std::size_t count = cumulative.size() - 2 * m;
  for (std::size_t k = 0; k < count; ++k) {
    const double d = cumulative[k + 2 * m] - 2 * cumulative[k + m] + cumulative[k];
    sum += d * d;
  }
  const double tau = m * dt;
  return sum / (2.0 * tau * tau * count);
}

std::vector<double> channel(const ImuSeries& s, bool gyro, int axis) {
  std::vector<double> out;
  for (const auto& x : s.samples) out.push_back(gyro ? x.gyro[axis] : x.acc[axis]);
  return out;
}

double standard_deviation(const std::vector<double>& x) {
  double mean = 0.0, sq = 0.0;
  for (double v : x) mean += v;
  mean /= x.size();
  for (double v : x) sq += (v - mean) * (v - mean);
  return std::sqrt(sq / (x.size() - 1));
}

bool sanitized() {
  return std::getenv("IMSCAL_SANITIZED") != nullptr;
}
}  // namespace

TEST(ImuNoise, WhiteNoiseSigmaAndAllanDeviation) {
  SensorSpec spec;
  spec.gyro.white_noise_density = 0.1 * M_PI / 180.0 / 60.0;  // 0.1 deg/sqrt(h) in rad/sqrt(s)
  spec.acc.white_noise_density = 50e-6 * 9.80665;             // 50 ug/sqrt(Hz)
  const double dt = 0.01;
  const ImuSeries out = corrupt(zero_increments(60000, dt), {}, spec, 42);  // 600 s at 100 Hz
  for (bool gyro : {true, false}) {
    const double density = gyro ? spec.gyro.white_noise_density : spec.acc.white_noise_density;
    double sigma_ratio = 0.0, adev_ratio = 0.0;
    for (int axis = 0; axis < 3; ++axis) {
      const auto x = channel(out, gyro, axis);
      sigma_ratio += standard_deviation(x) / (density * std::sqrt(dt)) / 3.0;
      // White rate noise: Allan deviation N / sqrt(tau); at tau = 1 s, N.
      adev_ratio += std::sqrt(allan_variance(x, 100, dt)) / density / 3.0;
    }
    // sigma from 180000 values: relative standard error 1/sqrt(2 * 180000) = 0.17%; 1%.
    EXPECT_NEAR(sigma_ratio, 1.0, 0.01) << (gyro ? "gyro" : "acc");
    // Overlapping ADEV at tau = 1 s over 600 s: ~900 degrees of freedom, 2.4% per axis,
    // 1.4% over three axes; 5% is > 3 sigma.
    EXPECT_NEAR(adev_ratio, 1.0, 0.05) << (gyro ? "gyro" : "acc");
    std::printf("%s: sigma / (N sqrt(dt)) = %.4f, ADEV(1 s) / N = %.4f\n", gyro ? "gyro" : "acc",
                sigma_ratio, adev_ratio);
  }
}

TEST(ImuNoise, GaussMarkovSteadyStateAndCorrelation) {
  SensorSpec spec;
  const double sigma = 1e-3, tau = 0.5, dt = 0.01;
  spec.gyro.bias_instability = {{sigma, tau}};
  const std::size_t n = sanitized() ? 100000 : 200000;  // 1000 / 2000 s (lighter under ASan)
  const ImuSeries out = corrupt(zero_increments(n, dt), {}, spec, 7);
  // The output is the mean bias over each interval, m_k = (b_{k-1} + b_k) / 2, with
  // Var m = sigma^2 (1 + rho) / 2 and Cov(m_k, m_k+L) = sigma^2 (2 rho^L + rho^(L-1) + rho^(L+1))
  // / 4.
  const double rho = std::exp(-dt / tau);
  const std::size_t lag = 50;  // = tau / dt
  const double var_theory = sigma * sigma * (1 + rho) / 2;
  const double cov_theory =
      sigma * sigma * (2 * std::pow(rho, lag) + std::pow(rho, lag - 1) + std::pow(rho, lag + 1)) /
      4;
  double var = 0.0, cov = 0.0;
  for (int axis = 0; axis < 3; ++axis) {
    auto x = channel(out, true, axis);
    for (double& v : x) v /= dt;
    for (std::size_t k = 0; k < x.size(); ++k) var += x[k] * x[k] / (3.0 * x.size());
    for (std::size_t k = 0; k + lag < x.size(); ++k) {
      cov += x[k] * x[k + lag] / (3.0 * (x.size() - lag));
    }
  }
  // About T / (2 tau) = 2000 independent values per axis (1000 under ASan): sigma to ~1.5%
  // (variance ~3%) over three axes, the correlation to ~0.02; allow 10% on the variance and
  // 0.06 on the correlation coefficient.
  EXPECT_NEAR(var / var_theory, 1.0, 0.10);
  EXPECT_NEAR(cov / var - cov_theory / var_theory, 0.0, 0.06);
  EXPECT_NEAR(cov_theory / var_theory, std::exp(-1.0), 0.01);  // the theory is e^-1 at tau
  std::printf("Gauss-Markov: variance / theory = %.4f, correlation at tau %.4f (theory %.4f)\n",
              var / var_theory, cov / var, cov_theory / var_theory);
}

TEST(ImuNoise, QuantisationKeepsTheResidual) {
  SensorSpec spec;
  spec.gyro.white_noise_density = 1e-4;
  spec.acc.white_noise_density = 1e-3;
  ImuSeries ideal = zero_increments(20000, 0.001);
  for (auto& s : ideal.samples) {
    s.gyro = Eigen::Vector3d(1e-3, -2.3e-4, 7e-6);  // a rate of ~1 rad/s: many LSB per sample
    s.acc = Eigen::Vector3d(0.0, 3.3e-6, -9.81e-3);
  }
  const ImuSeries unquantised = corrupt(ideal, {}, spec, 5);
  spec.gyro.quantization_lsb = 1e-6;
  spec.acc.quantization_lsb = 1e-5;
  const ImuSeries quantised = corrupt(ideal, {}, spec, 5);  // same seed: same noise draws
  Eigen::Vector3d sum_g = Eigen::Vector3d::Zero(), sum_a = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < ideal.samples.size(); ++k) {
    const ImuSample& q = quantised.samples[k];
    const ImuSample& u = unquantised.samples[k];
    for (int i = 0; i < 3; ++i) {
      // Whole multiples of the LSB (up to the rounding of lsb * integer).
      EXPECT_NEAR(q.gyro[i] / 1e-6, std::round(q.gyro[i] / 1e-6), 1e-6);
      EXPECT_NEAR(q.acc[i] / 1e-5, std::round(q.acc[i] / 1e-5), 1e-6);
    }
    sum_g += q.gyro - u.gyro;
    sum_a += q.acc - u.acc;
    // The accumulated quantisation error is the residual: at most half an LSB, however many
    // samples (plus rounding of the running sums, < 1e-12 of an LSB here).
    ASSERT_LE(sum_g.cwiseAbs().maxCoeff(), 0.5e-6 * (1 + 1e-9)) << "sample " << k;
    ASSERT_LE(sum_a.cwiseAbs().maxCoeff(), 0.5e-5 * (1 + 1e-9)) << "sample " << k;
  }
}

TEST(ImuNoise, SaturationClampsTheMeanRate) {
  SensorSpec spec;
  spec.gyro.range = 5.0;   // [rad/s]
  spec.acc.range = 100.0;  // [m/s^2]
  ImuSeries ideal = zero_increments(3, 0.002);
  ideal.samples[1].gyro = Eigen::Vector3d(0.02, -0.002, 0.005);  // 10, -1, 2.5 rad/s
  ideal.samples[1].acc = Eigen::Vector3d(-0.3, 0.0, 0.1);        // -150, 0, 50 m/s^2
  const ImuSeries out = corrupt(ideal, {}, spec, 1);
  // 5 rad/s * 2 ms and 100 m/s^2 * 2 ms; the products round to an ulp.
  EXPECT_LT((out.samples[1].gyro - Eigen::Vector3d(0.01, -0.002, 0.005)).norm(), 1e-17);
  EXPECT_LT((out.samples[1].acc - Eigen::Vector3d(-0.2, 0.0, 0.1)).norm(), 1e-16);
}

TEST(ImuNoise, DeterministicBySeed) {
  const SensorSpec spec =
      load_sensor_spec(std::filesystem::path(IMSCAL_SOURCE_DIR) / "datasets/sensors/mems.yaml");
  std::mt19937_64 rng_a(3), rng_b(3);
  const SensorErrorModel ea = draw_sensor_errors(spec, rng_a);
  const SensorErrorModel eb = draw_sensor_errors(spec, rng_b);
  EXPECT_EQ(ea.gyro.bias, eb.gyro.bias);
  EXPECT_EQ(ea.acc.misalignment, eb.acc.misalignment);
  const ImuSeries ideal = zero_increments(1000, 0.001);
  const ImuSeries a = corrupt(ideal, ea, spec, 99);
  const ImuSeries b = corrupt(ideal, ea, spec, 99);
  const ImuSeries c = corrupt(ideal, ea, spec, 100);
  ASSERT_EQ(a.samples.size(), b.samples.size());
  EXPECT_EQ(std::memcmp(a.samples.data(), b.samples.data(), a.samples.size() * sizeof(ImuSample)),
            0);
  EXPECT_NE(a.samples[10].gyro, c.samples[10].gyro);
}

TEST(ImuNoise, InRunBiasIsWhatTheRecordCarriesBesideTheTurnOnBias) {
  // Only bias instability (two Gauss-Markov terms per triad) and a turn-on bias: every output
  // increment is then (turn-on + in-run bias) * dt exactly (to rounding), and handing back the
  // in-run part changes no draw.
  SensorSpec spec;
  spec.gyro.bias_instability = {{1e-6, 50.0}, {2e-6, 500.0}};
  spec.acc.bias_instability = {{1e-4, 20.0}, {5e-5, 600.0}};
  SensorErrorModel errors;
  errors.gyro.bias = Eigen::Vector3d(3e-6, -1e-6, 2e-6);
  errors.acc.bias = Eigen::Vector3d(2e-4, 1e-4, -3e-4);
  const double dt = 0.01;
  const ImuSeries ideal = zero_increments(20000, dt);  // 200 s
  InRunBias in_run;
  const ImuSeries with = corrupt(ideal, errors, spec, 5, &in_run);
  const ImuSeries without = corrupt(ideal, errors, spec, 5);
  ASSERT_EQ(in_run.t_s.size(), ideal.samples.size());
  EXPECT_EQ(std::memcmp(with.samples.data(), without.samples.data(),
                        with.samples.size() * sizeof(ImuSample)),
            0);
  double worst_gyro = 0.0, worst_acc = 0.0, spread_acc = 0.0;
  for (std::size_t k = 0; k < ideal.samples.size(); ++k) {
    EXPECT_EQ(in_run.t_s[k], with.samples[k].t_s);
    worst_gyro =
        std::max(worst_gyro, (with.samples[k].gyro / dt - errors.gyro.bias - in_run.gyro_rad_s[k])
                                 .cwiseAbs()
                                 .maxCoeff());
    worst_acc = std::max(
        worst_acc,
        (with.samples[k].acc / dt - errors.acc.bias - in_run.acc_m_s2[k]).cwiseAbs().maxCoeff());
    spread_acc =
        std::max(spread_acc, (in_run.acc_m_s2[k] - in_run.acc_m_s2.front()).cwiseAbs().maxCoeff());
  }
  // Rounding of a ~1e-6 increment divided by 0.01 s: ~1e-20 / 1e-2.
  EXPECT_LT(worst_gyro, 1e-15);
  EXPECT_LT(worst_acc, 1e-13);
  // And it is not a constant: the 20 s term (1e-4 sigma) wanders by ~its sigma over 200 s.
  EXPECT_GT(spread_acc, 5e-5);
}

TEST(ImuNoise, DrawnErrorsFollowTheSpec) {
  SensorSpec spec;
  spec.gyro.turn_on_bias_sigma = 1e-5;
  spec.gyro.scale_factor_sigma = 3e-5;
  spec.gyro.misalignment_sigma = 2e-5;
  spec.acc.turn_on_bias_sigma = 2e-4;
  std::mt19937_64 rng(11);
  double bias_sq = 0.0, scale_sq = 0.0, mis_sq = 0.0, acc_bias_sq = 0.0, diagonal = 0.0;
  const int units = 4000;
  for (int i = 0; i < units; ++i) {
    const SensorErrorModel e = draw_sensor_errors(spec, rng);
    bias_sq += e.gyro.bias.squaredNorm() / (3.0 * units);
    scale_sq += e.gyro.scale_factor.squaredNorm() / (3.0 * units);
    mis_sq += e.gyro.misalignment.squaredNorm() / (6.0 * units);
    acc_bias_sq += e.acc.bias.squaredNorm() / (3.0 * units);
    diagonal += e.gyro.misalignment.diagonal().norm();
  }
  // 12000 (24000) values: sigma to 0.65% (0.46%); allow 3%.
  EXPECT_NEAR(std::sqrt(bias_sq) / 1e-5, 1.0, 0.03);
  EXPECT_NEAR(std::sqrt(scale_sq) / 3e-5, 1.0, 0.03);
  EXPECT_NEAR(std::sqrt(mis_sq) / 2e-5, 1.0, 0.03);
  EXPECT_NEAR(std::sqrt(acc_bias_sq) / 2e-4, 1.0, 0.03);
  EXPECT_EQ(diagonal, 0.0);
}

TEST(ImuNoise, ErrorModelAndTurnOnBiasAreApplied) {
  SensorSpec spec;  // no noise: the output is the error model applied exactly
  SensorErrorModel e;
  e.gyro.bias = Eigen::Vector3d(1e-5, -2e-5, 3e-5);
  e.acc.scale_factor = Eigen::Vector3d(1e-3, 0, 0);
  e.acc.misalignment(1, 2) = 2e-4;
  ImuSeries ideal = zero_increments(10, 0.001);
  for (auto& s : ideal.samples) s.acc = Eigen::Vector3d(0.001, 0.002, 0.0098);
  const ImuSeries out = corrupt(ideal, e, spec, 1);
  for (std::size_t k = 0; k < ideal.samples.size(); ++k) {
    const ImuSample expected = e.apply(ideal.samples[k], ImuQuantity::kIncrements, 0.001);
    EXPECT_LT((out.samples[k].gyro - expected.gyro).norm(), 1e-20);
    EXPECT_LT((out.samples[k].acc - expected.acc).norm(), 1e-18);
  }
  // Rates are corrupted as rate * dt increments: the same bias in rad/s.
  ImuSeries rates = ideal;
  rates.quantity = ImuQuantity::kRates;
  const ImuSeries out_rates = corrupt(rates, e, spec, 1);
  EXPECT_LT((out_rates.samples[3].gyro - (rates.samples[3].gyro + e.gyro.bias)).norm(), 1e-17);
}

TEST(ImuNoise, ShippedSpecsLoadInSi) {
  const std::filesystem::path dir = std::filesystem::path(IMSCAL_SOURCE_DIR) / "datasets/sensors";
  const SensorSpec nav = load_sensor_spec(dir / "navigation-grade.yaml");
  const SensorSpec mems = load_sensor_spec(dir / "mems.yaml");
  // Conversion of the file units checked against the raw YAML numbers.
  const auto raw = imscal::ConfigNode::load_file(dir / "navigation-grade.yaml");
  EXPECT_NEAR(
      nav.gyro.white_noise_density,
      raw.child("gyro").child("angle_random_walk_deg_per_sqrt_h").as_double() * M_PI / 180.0 / 60.0,
      1e-20);
  EXPECT_NEAR(nav.acc.white_noise_density,
              raw.child("accelerometer").child("velocity_random_walk_ug_per_sqrt_hz").as_double() *
                  9.80665e-6,
              1e-20);
  // The classes are what they claim: navigation grade is orders of magnitude quieter.
  EXPECT_LT(nav.gyro.white_noise_density * 100, mems.gyro.white_noise_density);
  EXPECT_LT(nav.acc.turn_on_bias_sigma * 10, mems.acc.turn_on_bias_sigma);
  EXPECT_FALSE(nav.gyro.bias_instability.empty());
  EXPECT_GT(nav.gyro.range, 5.0);  // > 286 deg/s: robot wrists turn fast
}
