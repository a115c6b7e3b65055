// Transmission error: s, c = sin/cos(h N q_internal), h = 1..3 per motor revolution and the two
// orders of 1..8 whose raw ripple best fits the training rows: raw, through L_3ms (x3, x4),
// L_10ms or L_30ms (x4), or with the ripple torque tau_d s, tau_d c (the gear's virtual work on the
// motor) through L_100ms x3 beside L_10ms x3 or L_3ms + L_30ms x3 of s, c: below the loop's
// bandwidth the link follows the error, above the link's mode it does not. In the nominal model:
// a_s, a_c [rad] of a further order h per motor revolution, a_s sin(h θ_m) + a_c cos(h θ_m),
// θ_m the motor angle / N (the order from a search, eval/gap_refinement.hpp); no bound.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "core/units.hpp"
#include "eval/gap_effect_shapes.hpp"
#include "eval/gap_nominal_plant.hpp"

namespace imscal::eval {
namespace {

using Named = std::pair<std::vector<Column>, std::vector<std::string>>;

// The inputs through Laguerre bases of time scale tl and `order`, named after `stems`.
Named through(const ShapeContext& x, const std::vector<Column>& inputs, double tl, int order,
              const std::vector<std::string>& stems) {
  std::vector<Column> cols;
  std::vector<std::string> names;
  const int ms = int(std::lround(1000.0 * tl));
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    for (auto& c : laguerre(inputs[i], tl, order, x.s)) cols.push_back(std::move(c));
    for (auto& nm : numbered(fmt::format("{}_laguerre{}ms_", stems[i], ms), order))
      names.push_back(std::move(nm));
  }
  return {cols, names};
}

// a's columns and names followed by b's.
Named joined(Named a, const Named& b) {
  a.first.insert(a.first.end(), b.first.begin(), b.first.end());
  a.second.insert(a.second.end(), b.second.begin(), b.second.end());
  return a;
}

// The shapes of order h per motor revolution.
void add_order(const ShapeContext& x, double h, std::vector<CandidateShape>& out) {
  const Column q = to_column(x.s.q_internal_rad[x.joint]);
  const Column tau_d = to_column(x.s.torque_nm[x.joint]);
  const double tau_d_rms = std::max(rms_of(tau_d), 1e-12);
  const Column phase = h * x.s.gear_ratio[x.joint] * q;
  const Column sn = phase.array().sin().matrix(), cs = phase.array().cos().matrix();
  out.push_back(
      x.local(fmt::format("harmonic {} of the motor angle", h), {sn, cs}, {"sin_rad", "cos_rad"}));
  for (const auto& [tl, order] :
       {std::pair{0.003, 3}, std::pair{0.003, 4}, std::pair{0.01, 4}, std::pair{0.03, 4}}) {
    auto [cols, names] = through(x, {sn, cs}, tl, order, {"sin", "cos"});
    out.push_back(
        x.local(fmt::format("harmonic {} of the motor angle through Laguerre {:.0f} ms x{}", h,
                            1000.0 * tl, order),
                cols, names));
  }
  // The ripple torque through the loop's slower response (its PI integrates it): tau_d (the
  // desired motion's torque: the actual one carries the ripple's own oscillation).
  const Column ts = tau_d.cwiseProduct(sn) / tau_d_rms;
  const Column tc = tau_d.cwiseProduct(cs) / tau_d_rms;
  const Named ripple = through(x, {ts, tc}, 0.1, 3, {"tau_sin", "tau_cos"});
  {
    auto [cols, names] = joined(through(x, {sn, cs}, 0.01, 3, {"sin", "cos"}), ripple);
    out.push_back(x.local(fmt::format("harmonic {} of the motor angle through Laguerre 10 ms x3 "
                                      "and its torque ripple through Laguerre 100 ms x3",
                                      h),
                          cols, names));
  }
  {
    auto [cols, names] = joined(joined(through(x, {sn, cs}, 0.003, 3, {"sin", "cos"}),
                                       through(x, {sn, cs}, 0.03, 3, {"sin", "cos"})),
                                ripple);
    out.push_back(x.local(fmt::format("harmonic {} of the motor angle through Laguerre 3 and 30 "
                                      "ms x3 and its torque ripple through Laguerre 100 ms x3",
                                      h),
                          cols, names));
  }
}

// te(theta) = A sin(h N theta + phi) between motor and link, theta the motor angle / N: the link
// follows it below the closed loop's bandwidth and not above the link's mode, and the motor
// feels it as a torque ripple te'(theta) tau_g (the virtual work of the gear): the joint's error
// is a linear response to sin, cos (and tau sin, tau cos) of h N theta, whose frequency h N qd
// sweeps through those modes. Raw, or through Laguerre bases of 3, 10 or 30 ms (the response
// without knowing the loop's poles), with the ripple through 100 ms.
std::vector<CandidateShape> shapes(const ShapeContext& x) {
  std::vector<CandidateShape> out;
  if (x.joint >= x.s.q_internal_rad.size()) return out;  // the motor angle is not known
  std::vector<double> orders = {1.0, 2.0, 3.0};
  if (x.training)  // two further orders from the search on the training rows
    for (double h : transmission_orders_by_fit(x.s, x.joint, x.s.gap_rad[x.joint], *x.training))
      if (orders.size() < 5 && std::find(orders.begin(), orders.end(), h) == orders.end())
        orders.push_back(h);
  for (double h : orders) add_order(x, h, out);
  return out;
}

std::string size_in_words(const CandidateFit& c, const CandidateShape& sh, double own_rms) {
  const bool raw = sh.parameter_names.size() == 2;
  const double a = raw ? std::hypot(c.parameters[0], c.parameters[1]) : std::sqrt(2.0) * own_rms;
  return fmt::format("amplitude {:.3g} rad ({:.2f} arcsec){}", a, a * kArcsecPerRad,
                     raw ? "" : " at the link (sqrt 2 x RMS)");
}

const NominalParameterDefinition kNominal{
    .parameter_count = 2,
    .of_drive = true,
    .per_motor_order = true,
    .applies = [](const NominalPlant&, std::size_t) { return true; },
    .typical_value = [](const NominalPlant&,
                        std::size_t) { return 20.0 * kRadPerArcsec; },  // typical of RV gears
    .apply =
        [](const NominalParameter& parameter, const double* p, sim::PlantConfig& config,
           sim::DesiredJointPath&) {
          auto& effects = config.effects[parameter.joint];
          if (!effects.transmission_error) effects.transmission_error_shape.amplitude_rad = 0.0;
          effects.transmission_error = true;
          effects.further_transmission_error_shapes.push_back(
              {std::hypot(p[0], p[1]), parameter.harmonic_per_motor_rev, std::atan2(p[1], p[0])});
        },
    .describe =
        [](const std::string& joint, const NominalParameter& parameter,
           const Eigen::VectorXd& p_own, double) {
          return fmt::format(
              "{} transmission error of order {:g} per motor revolution, {:.3g} arcsec", joint,
              parameter.harmonic_per_motor_rev, std::hypot(p_own[0], p_own[1]) / kRadPerArcsec);
        },
};

}  // namespace

const EffectDefinition kTransmissionErrorEffect{
    .kind = EffectKind::kTransmissionError,
    .name = "transmission_error",
    .acts_through_dynamics = true,
    .what_to_measure =
        "a slow constant-speed move of the joint over several motor revolutions "
        "(the error is periodic in the motor angle)",
    .shapes = shapes,
    .size_in_words = size_in_words,
    .nominal = &kNominal,
};

}  // namespace imscal::eval
