// Gear compliance: u = tau_d (inverse dynamics on q_d), the deflection tau / k; [u], [G, u - G]
// (gravity and motion parts apart), [u, L_30ms,0..1 u] or [u, L_30ms,0..5 u]. Bound: tau_d's
// level >= -1 / nominal stiffness.
#include <fmt/format.h>

#include "eval/gap_effect_shapes.hpp"

namespace imscal::eval {
namespace {

std::vector<CandidateShape> shapes(const ShapeContext& x) {
  std::vector<CandidateShape> out;
  const Column tau = to_column(x.s.torque_nm[x.joint]);
  out.push_back(x.local("tau_d / k", {tau}, {"compliance_rad_per_nm"}));
  // Gravity and motion torques apart (the load model of the gravity part is the least sure).
  const Column grav = to_column(x.s.gravity_torque_nm[x.joint]);
  out.push_back(x.local("gravity and motion torques / k", {grav, tau - grav},
                        {"compliance_rad_per_nm", "motion_compliance_rad_per_nm"}));
  // The deflection's dynamics (gear damping, the link's mode): Laguerre bases of 30 ms.
  for (int order : {2, 6}) {
    std::vector<Column> cols = laguerre(tau, 0.03, order, x.s);
    cols.insert(cols.begin(), tau);
    std::vector<std::string> names = numbered("laguerre30ms_", order);
    names.insert(names.begin(), "compliance_rad_per_nm");
    out.push_back(x.local(fmt::format("tau_d / k + Laguerre 30 ms x{}", order), cols, names));
  }
  for (auto& sh : out)
    sh.level_signal = tau, sh.level_lower = -nominal_of(x.s.nominal_compliance_rad_per_nm, x.joint);
  return out;
}

// The static compliance: the modelled deflection's coefficient on tau_d (the Laguerre columns'
// static gain included), added to the nominal model's.
std::string size_in_words(const CandidateFit& c, const CandidateShape&, double) {
  const double nominal = -c.bound.lower, combined = nominal + c.level;
  std::string text = fmt::format("static compliance change {:.3g} rad/N m", c.level);
  if (c.level > 0.0) text += fmt::format(" (a stiffness of {:.3g} N m/rad)", 1.0 / c.level);
  if (nominal > 0.0)
    text += fmt::format(
        "; with the robot's {:.3g} N m/rad, a gear stiffness of {}", 1.0 / nominal,
        combined > 0.0 ? fmt::format("{:.3g} N m/rad", 1.0 / combined) : std::string("rigid"));
  return text;
}

}  // namespace

const EffectDefinition kGearComplianceEffect{
    .kind = EffectKind::kGearCompliance,
    .name = "gear_compliance",
    .acts_through_dynamics = true,
    .what_to_measure =
        "the same path at two accelerations and with two payloads (deflection "
        "scales with the torque)",
    .shapes = shapes,
    .size_in_words = size_in_words,
};

}  // namespace imscal::eval
