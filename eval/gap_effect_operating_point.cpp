// Operating-point extrapolation: [o, o sign(q̇_d)], o = how far |q̇_d| lies beyond the identified
// speed range of the table, relative to it (only with a table that has a speed dimension).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "eval/gap_effect_shapes.hpp"

namespace imscal::eval {
namespace {

// The identified speed range of a joint's table: the upper bound of the highest speed band that
// holds an identified cell (NaN: no table, or no speed dimension).
double identified_speed_limit(const GapSignals& s, std::size_t joint) {
  if (joint >= s.table_dimensions.size()) return std::numeric_limits<double>::quiet_NaN();
  const auto& dims = s.table_dimensions[joint];
  int speed_dim = -1;
  for (std::size_t d = 0; d < dims.size(); ++d)
    if (dims[d].quantity == ident::OperatingQuantity::kSpeed) speed_dim = int(d);
  if (speed_dim < 0) return std::numeric_limits<double>::quiet_NaN();
  const ident::CellGrid grid(dims);
  int top_band = -1;
  for (int c = 0; c < grid.cell_count(); ++c)
    if (s.table_cell_identified[joint][std::size_t(c)])
      top_band = std::max(top_band, grid.bands_of(c)[std::size_t(speed_dim)]);
  if (top_band < 0) return std::numeric_limits<double>::quiet_NaN();
  return dims[std::size_t(speed_dim)].bounds[std::size_t(top_band) + 1];
}

std::vector<CandidateShape> shapes(const ShapeContext& x) {
  const double limit = identified_speed_limit(x.s, x.joint);
  if (!std::isfinite(limit) || limit <= 0.0) return {};
  Column o(x.n), os(x.n);
  for (Eigen::Index k = 0; k < x.n; ++k) {
    o[k] = std::max(0.0, std::abs(x.qd[k]) - limit) / limit;
    os[k] = o[k] * std::tanh(x.qd[k] / kSignVelocityScale);
  }
  if (o.cwiseAbs().maxCoeff() == 0.0) return {};  // never outside: nothing to fit
  return {x.local(fmt::format("beyond identified speed {:.3f} rad/s", limit), {o, os},
                  {"per_excess_rad", "per_excess_signed_rad"})};
}

}  // namespace

const EffectDefinition kOperatingPointEffect{
    .kind = EffectKind::kOperatingPoint,
    .name = "operating_point_extrapolation",
    .acts_through_dynamics = false,
    .what_to_measure = "identification runs at the speeds and joint positions of this path",
    .shapes = shapes,
};

}  // namespace imscal::eval
