#pragma once
// Stability check of an identified ARX model: the free-running model (what the precontrol runs
// online from the desired angles alone) is bounded only if every pole, root of
// A(z) = z^na + a_1 z^(na-1) + ... + a_na, lies strictly inside the unit circle. A margin keeps
// models whose pole sits on the circle within rounding (|p| = 0.99999) from passing: such a
// model integrates its own error and drifts.
#include <Eigen/Core>
#include <string>

#include "ident/arx_model.hpp"

namespace imscal::ident {

struct StabilityCheck {
  bool stable = false;
  double spectral_radius = 0.0;  // largest |pole|
  double margin = 0.0;           // required: spectral_radius < 1 - margin
  Eigen::VectorXcd poles;
  std::string reason;  // why it was rejected (empty when stable)
};

// margin in [0, 1). Never throws for a model it cannot analyse: a failed eigenvalue iteration or
// non-finite coefficients give stable = false with the reason.
StabilityCheck check_stability(const ArxModel& model, double margin = 1e-3);

}  // namespace imscal::ident
