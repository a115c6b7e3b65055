// Structural resonance: q̈_d through ω²/(s² + 2ζωs + ω²), f 2..40 Hz in 10 % steps x ζ {0.02,
// 0.04, 0.07, 0.12, 0.3}; [y, ẏ/ω] (gain and phase).
#include <fmt/format.h>

#include <array>

#include "eval/gap_effect_shapes.hpp"

namespace imscal::eval {
namespace {

constexpr std::array<double, 5> kDampings = {0.02, 0.04, 0.07, 0.12, 0.3};

// A lightly damped mode is only fitted where its frequency is: 2..40 Hz in steps of 10 %.
const std::vector<double>& frequencies_hz() {
  static const std::vector<double> grid = [] {
    std::vector<double> f;
    for (double hz = 2.0; hz < 41.0; hz *= 1.1) f.push_back(hz);
    return f;
  }();
  return grid;
}

std::size_t shape_count(const ShapeContext&) {
  return frequencies_hz().size() * kDampings.size();
}

// Frequency after frequency, each with every damping.
CandidateShape shape_at(const ShapeContext& x, std::size_t index) {
  const double f = frequencies_hz()[index / kDampings.size()];
  const double zeta = kDampings[index % kDampings.size()];
  auto [y, r] = second_order(x.qdd, f, zeta, x.s);
  return x.local(fmt::format("mode {:.2f} Hz, damping {:.2f}", f, zeta), {y, r},
                 {"gain_rad_s2_per_rad_s2", "quadrature"});
}

std::vector<CandidateShape> shapes(const ShapeContext& x) {
  std::vector<CandidateShape> out;
  for (std::size_t i = 0; i < shape_count(x); ++i) out.push_back(shape_at(x, i));
  return out;
}

}  // namespace

const EffectDefinition kResonanceEffect{
    .kind = EffectKind::kResonance,
    .name = "structural_resonance",
    .acts_through_dynamics = true,
    .what_to_measure =
        "fast stops of the joint recorded by the IMS at its full rate (ring-down "
        "frequency and damping)",
    .shapes = shapes,
    .shape_count = shape_count,
    .shape_at = shape_at,
};

}  // namespace imscal::eval
