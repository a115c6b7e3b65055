#include "eval/gap_joint_significance.hpp"

#include <algorithm>
#include <cmath>

namespace imscal::eval {

double high_frequency_noise_floor(const std::vector<double>& x,
                                  const std::vector<std::pair<std::size_t, std::size_t>>& runs) {
  std::vector<double> second;
  for (const auto& [b, e] : runs)
    for (std::size_t k = b + 1; k + 1 < e; ++k)
      second.push_back(std::abs(x[k + 1] - 2.0 * x[k] + x[k - 1]));
  if (second.empty()) return 0.0;
  const auto mid = second.begin() + std::ptrdiff_t(second.size() / 2);
  std::nth_element(second.begin(), mid, second.end());
  // 1.4826 median|.|: the sigma of a normal variable; Δ² of white noise has variance 6 sigma².
  return 1.4826 * *mid / std::sqrt(6.0);
}

double sidak_alpha(double alpha, std::size_t tests) {
  return tests <= 1 ? alpha : 1.0 - std::pow(1.0 - alpha, 1.0 / double(tests));
}

}  // namespace imscal::eval
