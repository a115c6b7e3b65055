// Structural resonance: q̈_d through ω²/(s² + 2ζωs + ω²), f 2..40 Hz in 10 % steps x ζ {0.02,
// 0.04, 0.07, 0.12, 0.3}; [y, ẏ/ω] (gain and phase).
#include <fmt/format.h>

#include "eval/gap_effect_shapes.hpp"

namespace imscal::eval {
namespace {

std::vector<CandidateShape> shapes(const ShapeContext& x) {
  std::vector<CandidateShape> out;
  // A lightly damped mode is only fitted where its frequency is: 2..40 Hz in steps of 10 %.
  for (double f = 2.0; f < 41.0; f *= 1.1)
    for (double zeta : {0.02, 0.04, 0.07, 0.12, 0.3}) {
      auto [y, r] = second_order(x.qdd, f, zeta, x.s);
      out.push_back(x.local(fmt::format("mode {:.2f} Hz, damping {:.2f}", f, zeta), {y, r},
                            {"gain_rad_s2_per_rad_s2", "quadrature"}));
    }
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
};

}  // namespace imscal::eval
