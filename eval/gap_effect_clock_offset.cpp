// Clock offset: all joints at once, one parameter: [q̇_j] on every joint j, the offset dt [s] of
// the measuring clock against the robot's (a parameter of the nominal model: q_m(t) = q(t - dt),
// linearised -dt q̇ of the joint error's measured side).
#include "eval/gap_effect_shapes.hpp"

namespace imscal::eval {
namespace {

std::vector<CandidateShape> shapes(const ShapeContext& x) {
  if (x.joint != 0 || x.nj < 2) return {};  // one candidate for all joints
  // The measured motion's velocity: the drive's actual one where known (the link lags q_d by
  // the tracking error, ~80 ms on the main axes), else q̇_d.
  const auto velocity = [&](std::size_t j) {
    const bool known =
        j < x.s.qd_internal_rad_s.size() && rms_of(to_column(x.s.qd_internal_rad_s[j])) > 0.0;
    return Eigen::MatrixXd(to_column(known ? x.s.qd_internal_rad_s[j] : x.s.qd_desired_rad_s[j]));
  };
  return {x.shared("q̇_j * dt on every joint", velocity, {0}, {"dt_s"})};
}

}  // namespace

const EffectDefinition kClockOffsetEffect{
    .kind = EffectKind::kClockOffset,
    .name = "clock_offset",
    .acts_through_dynamics = false,
    .what_to_measure =
        "sharp starts and stops of several joints with both streams stamped by one "
        "clock (a common offset shifts every joint's error by the same time)",
    .shapes = shapes,
    .size_in_words = size_in_seconds,
};

}  // namespace imscal::eval
