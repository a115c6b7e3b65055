#pragma once
// A least-squares problem for the gap fits' tests: four columns of very different sizes (the
// column scaling must make it well conditioned), y = X theta + N(0, 0.3^2) noise. Columns:
// size_0 (sin t + c n), size_1 (cos 0.7 t + c n), size_2 n, size_3 (1 + 0.5 n); t = 0.01 k,
// n standard normal, c the first two columns' noise fraction.
#include <Eigen/Core>
#include <array>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

namespace imscal::eval::test {

struct ScaledLsProblem {
  Eigen::MatrixXd x;
  std::vector<double> y;
};

struct ScaledLsSpec {
  Eigen::Index samples = 0;
  std::array<double, 4> sizes{};
  double noise_fraction = 0.0;  // c above
  Eigen::Vector4d theta = Eigen::Vector4d::Zero();
};

inline ScaledLsProblem scaled_ls_problem(std::uint64_t seed, const ScaledLsSpec& spec) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  ScaledLsProblem p;
  p.x.resize(spec.samples, 4);
  const auto& s = spec.sizes;
  for (Eigen::Index k = 0; k < spec.samples; ++k) {
    const double t = 0.01 * double(k);
    p.x(k, 0) = s[0] * (std::sin(t) + spec.noise_fraction * normal(rng));
    p.x(k, 1) = s[1] * (std::cos(0.7 * t) + spec.noise_fraction * normal(rng));
    p.x(k, 2) = s[2] * normal(rng);
    p.x(k, 3) = s[3] * (1.0 + 0.5 * normal(rng));
  }
  const Eigen::VectorXd y = p.x * spec.theta;
  for (Eigen::Index k = 0; k < spec.samples; ++k) p.y.push_back(y[k] + 0.3 * normal(rng));
  return p;
}

}  // namespace imscal::eval::test
