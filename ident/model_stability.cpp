#include "ident/model_stability.hpp"

#include <fmt/format.h>

#include <cmath>
#include <complex>
#include <exception>

namespace imscal::ident {

StabilityCheck check_stability(const ArxModel& model, double margin) {
  StabilityCheck check;
  check.margin = margin;
  if (!model.a().allFinite() || !model.b().allFinite()) {
    check.reason = "non-finite model coefficients";
    return check;
  }
  try {
    check.poles = model.poles();
  } catch (const std::exception& e) {
    check.reason = fmt::format("poles not computable: {}", e.what());
    return check;
  }
  Eigen::Index worst = -1;
  for (Eigen::Index i = 0; i < check.poles.size(); ++i) {
    const double r = std::abs(check.poles(i));
    if (r > check.spectral_radius || worst < 0) {
      check.spectral_radius = r;
      worst = i;
    }
  }
  check.stable = check.spectral_radius < 1.0 - margin;
  if (!check.stable) {
    const auto p = check.poles(worst);
    check.reason = fmt::format(
        "unstable: pole {:.6f}{:+.6f}i has |p| = {:.6f} >= 1 - margin = {:.6f} ({} of {} poles "
        "outside)",
        p.real(), p.imag(), check.spectral_radius, 1.0 - margin,
        (check.poles.array().abs() >= 1.0 - margin).count(), check.poles.size());
  }
  return check;
}

}  // namespace imscal::ident
