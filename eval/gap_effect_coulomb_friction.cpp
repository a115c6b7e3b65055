// Coulomb friction: u = tanh(q̇_a / v_s), v_s 5, 10, 20 mrad/s (physical rate thresholds, well
// below any programmed speed; not the simulator's smoothing). The friction's static level, so
// that a changed friction level is a parameter change of its own: [r] or [r, L_100ms,0..3 r], r
// the sign of the last motion held at rest (the drive stuck where it stopped, wound by the
// friction, and the loop's integral action unwinding it). The smooth [u] alone is not among the
// shapes: on a single move it is a box over the motion, which a withheld gear stiffness also
// fills (decision 0080). Its transient: the friction acts on the motor's own velocity and the PI
// loop works it off after every reversal: [HP_30/100/300ms u], [L_100ms,0..5 u],
// [L_100ms,0..3 u] or [L_30ms,0..5 u]. Bound: the static column's level >= 0 when the nominal
// model has no friction. In the nominal model: ΔF_c [N m] of the joint's drive (switched on when
// the nominal has it off); F_c + ΔF_c >= 0.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "eval/gap_effect_shapes.hpp"
#include "eval/gap_nominal_plant.hpp"

namespace imscal::eval {
namespace {

// The friction's level where the joint stops: a Coulomb friction holds the drive where it stuck,
// wound by the friction of its last motion, until the loop's integral action works it off. So the
// sign of the last motion, held at rest (a relay of q̇_a at 5 mrad/s, eval/gap_filters.hpp), alone
// or with its Laguerre 100 ms x4 columns (the loop's unwinding): the same columns as a backlash's
// flank, so that a smaller friction and a smaller play compete on them.
void add_held_at_rest(const ShapeContext& x, double lower, std::vector<CandidateShape>& out) {
  const Column held = relay(x.qd_actual, kSignVelocityScale, x.s);
  if (held.maxCoeff() == held.minCoeff()) return;  // one direction only: a zero offset
  out.push_back(x.local("sign(qd), held at rest", {held}, {"static_rad"}));
  std::vector<Column> landing = laguerre(held, 0.1, 4, x.s);
  landing.insert(landing.begin(), held);
  std::vector<std::string> names = numbered("laguerre100ms_", 4);
  names.insert(names.begin(), "static_rad");
  out.push_back(x.local("sign(qd), held at rest + Laguerre 100 ms x4", landing, names));
  for (std::size_t i = out.size() - 2; i < out.size(); ++i)
    out[i].level_signal = held, out[i].level_lower = lower;
}

std::vector<CandidateShape> shapes(const ShapeContext& x) {
  std::vector<CandidateShape> out;
  // A lower friction than the nominal one is physical when the nominal model has some.
  const double lower = nominal_of(x.s.nominal_coulomb_nm, x.joint) > 0.0
                           ? -std::numeric_limits<double>::infinity()
                           : 0.0;
  for (double scale : {0.005, 0.01, 0.02}) {
    const Column sv = (x.qd_actual / scale).array().tanh().matrix();
    const int mrad = int(std::lround(1000.0 * scale));
    const std::size_t first = out.size();
    std::vector<Column> hp;
    for (double tau : {0.03, 0.1, 0.3}) hp.push_back(sv - lag(sv, tau, x.s));
    out.push_back(x.local(fmt::format("sign(qd / {} mrad/s) high-passed 30/100/300 ms", mrad), hp,
                          {"hp30ms_rad", "hp100ms_rad", "hp300ms_rad"}));
    for (const auto& [tl, order] : {std::pair{0.1, 6}, std::pair{0.1, 4}, std::pair{0.03, 6}}) {
      const int ms = int(std::lround(1000.0 * tl));
      out.push_back(
          x.local(fmt::format("sign(qd / {} mrad/s) through Laguerre {} ms x{}", mrad, ms, order),
                  laguerre(sv, tl, order, x.s), numbered(fmt::format("laguerre{}ms_", ms), order)));
    }
    for (std::size_t i = first; i < out.size(); ++i)
      out[i].level_signal = sv, out[i].level_lower = lower;
  }
  add_held_at_rest(x, lower, out);
  return out;
}

const calib::DriveParameters& drive_of(const NominalPlant& plant, std::size_t joint) {
  return plant.config.robot.joints[joint].drive;
}

const NominalParameterDefinition kNominal{
    .parameter_count = 1,
    .of_drive = true,
    .applies = [](const NominalPlant&, std::size_t) { return true; },
    .nominal_value =
        [](const NominalPlant& plant, std::size_t joint) {
          return plant.config.effects[joint].coulomb_friction ? drive_of(plant, joint).coulomb_nm
                                                              : 0.0;
        },
    .typical_value =
        [](const NominalPlant& plant, std::size_t joint) {
          const double f = drive_of(plant, joint).coulomb_nm;
          return f > 0.0 ? f : 1.0;
        },
    .apply =
        [](const NominalParameter& parameter, const double* p, sim::PlantConfig& config,
           sim::DesiredJointPath&) {
          auto& effects = config.effects[parameter.joint];
          auto& drive = config.robot.joints[parameter.joint].drive;
          drive.coulomb_nm =
              std::max(0.0, (effects.coulomb_friction ? drive.coulomb_nm : 0.0) + p[0]);
          effects.coulomb_friction = true;
        },
    .describe =
        [](const std::string& joint, const NominalParameter&, const Eigen::VectorXd& p_own,
           double nominal) {
          return fmt::format("{} Coulomb friction {:.3g} N m (nominal {:.3g} N m)", joint,
                             nominal + p_own[0], nominal);
        },
};

}  // namespace

const EffectDefinition kCoulombFrictionEffect{
    .kind = EffectKind::kCoulombFriction,
    .name = "coulomb_friction",
    .acts_through_dynamics = true,
    .what_to_measure =
        "reversals of the joint at several speeds (friction transients follow the "
        "controller, not the play)",
    .shapes = shapes,
    .nominal = &kNominal,
};

}  // namespace imscal::eval
