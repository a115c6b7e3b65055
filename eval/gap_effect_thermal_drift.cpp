// Thermal drift: [1, t', t'^2], t' = (t - t_mid) / duration.
#include <algorithm>

#include "eval/gap_effect_shapes.hpp"

namespace imscal::eval {
namespace {

std::vector<CandidateShape> shapes(const ShapeContext& x) {
  const double t0 = x.s.time_s.front(), t1 = x.s.time_s.back();
  const double span = std::max(t1 - t0, x.s.cycle_s);
  Column t(x.n);
  for (Eigen::Index k = 0; k < x.n; ++k)
    t[k] = (x.s.time_s[std::size_t(k)] - 0.5 * (t0 + t1)) / span;
  // With its constant: a drift starts from some offset (a pure offset ranks above it by
  // parsimony, see eval/gap_diagnosis.cpp).
  return {x.local("constant + linear + quadratic in time",
                  {Column::Ones(x.n), t, t.array().square().matrix()},
                  {"offset_rad", "slope_rad", "curvature_rad"})};
}

}  // namespace

const EffectDefinition kThermalDriftEffect{
    .kind = EffectKind::kThermalDrift,
    .name = "thermal_drift",
    .acts_through_dynamics = false,
    .what_to_measure = "a repeat of the path after a warm-up and the drive temperatures",
    .shapes = shapes,
};

}  // namespace imscal::eval
