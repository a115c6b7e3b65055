// Backlash: the flank the link rests on. A relay with memory r of the sign of
// z = tau_a / RMS + c tanh(q̇_a / 5 mrad/s) (c = 0 .. 3: the friction at the link can outweigh a
// light axis' inertia torque; hold thresholds 2 / 10 %), or of q̇_a alone, as [r] or
// [r, L_10/30/100ms,0..3 r]; the smooth tanh(tau_a / 1, 5 or 20 % of its RMS) as [u] or
// [u, L_10/30/100ms,0..3 u] (when >= 5 % of the samples lie on the torque's minority side);
// tanh(q̇_a / 5 mrad/s) (the paper, eq. 3) as [u] or [u, LP_30ms u]. A relay that never switches
// is the one-flank shape kOneFlankShape: a constant, half the play. Bound: the flank's level
// >= -nominal half play. In the nominal model: Δb [rad], the play's full width (elastic gears
// only); b + Δb >= 0.
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>

#include "core/units.hpp"
#include "eval/gap_effect_shapes.hpp"
#include "eval/gap_nominal_plant.hpp"
#include "eval/gap_shape_pool.hpp"

namespace imscal::eval {
namespace {

// A pool of one joint's columns `cols` (eval/gap_shape_pool.hpp), without shapes yet.
ShapePool pool_of(const ShapeContext& x, Eigen::MatrixXd cols) {
  ShapePool pool;
  pool.columns.assign(x.nj, Eigen::MatrixXd());
  pool.columns[x.joint] = std::move(cols);
  return pool;
}

// [u] and [u, Laguerre 10, 30 or 100 ms x4 of u], the Laguerre columns the link's landing on the
// other flank with the gear's and the loop's dynamics: one pool [u, L_10ms, L_30ms, L_100ms x4].
ShapePool with_landing(const ShapeContext& x, const std::string& label, const Column& u) {
  Eigen::MatrixXd m(x.n, 13);
  m.col(0) = u;
  const std::array<double, 3> scales_s{0.01, 0.03, 0.1};
  for (std::size_t i = 0; i < scales_s.size(); ++i)
    laguerre_into(u, scales_s[i], x.s, m.middleCols(1 + 4 * Eigen::Index(i), 4));
  ShapePool pool = pool_of(x, std::move(m));
  pool.shapes.push_back(local_pooled_shape(x.nj, x.joint, label, {0}, {"l_rad"}));
  for (std::size_t i = 0; i < scales_s.size(); ++i) {
    const int ms = int(std::lround(1000.0 * scales_s[i]));
    std::vector<Eigen::Index> cols{0};
    for (Eigen::Index c = 0; c < 4; ++c) cols.push_back(1 + 4 * Eigen::Index(i) + c);
    std::vector<std::string> names = numbered(fmt::format("laguerre{}ms_", ms), 4);
    names.insert(names.begin(), "l_rad");
    pool.shapes.push_back(local_pooled_shape(
        x.nj, x.joint, fmt::format("{} + Laguerre {} ms x4", label, ms), cols, names));
  }
  return pool;
}

// The smooth sign of the torque without memory (the link also starts across the play on short
// torque dips that do not reach the other flank): scales 1, 5, 20 % of its RMS, raw or with
// Laguerre 10, 30 or 100 ms x4; only when at least 5 % of the samples lie on the torque's minority
// side (otherwise it is the one-flank offset).
void add_smooth_torque_signs(const ShapeContext& x, double tau_rms, std::vector<ShapePool>& out) {
  std::size_t positive = 0;
  for (Eigen::Index k = 0; k < x.n; ++k) positive += x.tau_actual[k] > 0.0;
  const double minority = double(std::min<std::size_t>(positive, std::size_t(x.n) - positive));
  if (minority < 0.05 * double(x.n)) return;
  for (double fraction : {0.01, 0.05, 0.2}) {
    const Column st = (x.tau_actual / (fraction * tau_rms)).array().tanh().matrix();
    out.push_back(
        with_landing(x, fmt::format("sign(tau) at {:.0f} % of its RMS", 100.0 * fraction), st));
  }
}

// The relays' shapes (see shape_pools): a relay that never switches once, as kOneFlankShape.
void add_relays(const ShapeContext& x, const std::vector<std::pair<std::string, Column>>& relays,
                std::vector<ShapePool>& out) {
  bool one_flank_added = false;
  for (const auto& [label, r] : relays) {
    // A relay that never switches: the gear torque keeps its sign, the link stays on one
    // flank and the play shows as a constant offset of half its width (one shape for all).
    if (r.maxCoeff() == r.minCoeff()) {
      if (!one_flank_added) {
        out.push_back(pool_of(x, r));
        out.back().shapes.push_back(
            local_pooled_shape(x.nj, x.joint, kOneFlankShape, {0}, {"l_rad"}));
        out.back().shapes.back().constant_on_own_joint = true;
      }
      one_flank_added = true;
      continue;
    }
    out.push_back(with_landing(x, label, r));
  }
}

std::vector<ShapePool> shape_pools(const ShapeContext& x) {
  std::vector<ShapePool> out;
  // The paper's eq. 3: the sign of the velocity (smooth, no memory).
  const Column sv = (x.qd_actual / kSignVelocityScale).array().tanh().matrix();
  Eigen::MatrixXd velocity(x.n, 2);
  velocity.col(0) = sv;
  velocity.col(1) = lag(sv, 0.03, x.s);
  out.push_back(pool_of(x, std::move(velocity)));
  out.back().shapes = {
      local_pooled_shape(x.nj, x.joint, "sign(qd)", {0}, {"l_rad"}),
      local_pooled_shape(x.nj, x.joint, "sign(qd) + lag 30 ms", {0, 1}, {"l_rad", "l_lag_rad"})};
  // The flank the link rests on: a relay with memory of the sign of the gear torque (the link
  // crosses the play when the torque the gear must pass changes sign, and stays on its flank
  // while the torque is small). That torque is the rigid-body torque of the drive's actual
  // motion plus the friction at the link (an unknown share of the joint's friction, which on
  // light wrist axes outweighs their inertia torques): z = tau / RMS(tau) + c tanh(qd / v_s),
  // c = 0 (torque only), 0.03 .. 3, or the velocity alone; thresholds 2 or 10 % of the
  // torque's RMS. The link lands on the other flank with the gear's and the loop's dynamics:
  // [r] or [r, Laguerre 10, 30 or 100 ms x4 of r].
  const double tau_rms = std::max(rms_of(x.tau_actual), 1e-12);
  add_smooth_torque_signs(x, tau_rms, out);
  std::vector<std::pair<std::string, Column>> relays;
  for (double h : {0.02, 0.1})
    relays.emplace_back(fmt::format("sign(tau), hold below {:.0f} % of its RMS", 100.0 * h),
                        relay(x.tau_actual / tau_rms, h, x.s));
  for (double c : {0.03, 0.1, 0.3, 1.0, 3.0})
    relays.emplace_back(fmt::format("sign(tau + {:.2f} RMS(tau) sign(qd)), hold below 2 %", c),
                        relay(x.tau_actual / tau_rms + c * sv, 0.02, x.s));
  relays.emplace_back("sign(qd), held at rest", relay(x.qd_actual, kSignVelocityScale, x.s));
  add_relays(x, relays, out);
  for (ShapePool& pool : out)
    for (PooledShape& sh : pool.shapes)  // the flank: the first column
      sh.level_column = 0, sh.level_joint = x.joint,
      sh.level_lower = -nominal_of(x.s.nominal_half_play_rad, x.joint);
  return out;
}

std::vector<CandidateShape> shapes(const ShapeContext& x) {
  return shapes_from_pools(shape_pools(x));
}

// Half the step of a backlash's modelled gap between the two flanks: the medians of its own
// joint's modelled gap where the shape's first column (the flank) is positive and negative,
// half their difference (the Laguerre columns' landing transients left aside; samples between
// the flanks, where a smooth sign is near zero, left out). One flank only: the modelled offset.
double half_play(const CandidateFit& c) {
  const Eigen::MatrixXd& cols = c.columns[c.joint];  // the shape's first
  std::vector<double> up, down;
  for (Eigen::Index k = 0; k < cols.rows(); ++k) {
    if (std::abs(cols(k, 0)) < 0.5) continue;  // between the flanks (a smooth sign near zero)
    (cols(k, 0) > 0.0 ? up : down).push_back(c.prediction[c.joint][std::size_t(k)]);
  }
  const auto median = [](std::vector<double> v) {
    if (v.empty()) return 0.0;
    std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(v.size() / 2), v.end());
    return v[v.size() / 2];
  };
  if (up.empty() || down.empty()) return median(up.empty() ? down : up);
  return 0.5 * (median(up) - median(down));
}

std::string size_in_words(const CandidateFit& c, const CandidateShape& sh, double) {
  const double l = half_play(c);
  if (sh.constant_on_own_joint)
    return fmt::format(
        "a constant offset of {:.3g} rad ({:.2f} arcsec): half the play if all of it is the "
        "play (full play {:.2f} arcsec)",
        l, l * kArcsecPerRad, 2.0 * std::abs(l) * kArcsecPerRad);
  return fmt::format("half play {:.3g} rad ({:.2f} arcsec, full play {:.2f} arcsec)", l,
                     l * kArcsecPerRad, 2.0 * std::abs(l) * kArcsecPerRad);
}

// On one flank the play is a zero offset of the joint (eval/gap_ambiguity.hpp).
std::string separate_from(EffectKind other, const std::string& joint) {
  if (other != EffectKind::kZeroOffset) return {};
  return fmt::format(
      "a path on which the gear torque of {} changes sign (its gravity load reversed by another "
      "pose of the arm, or reversals fast enough that their inertia torque outweighs it): "
      "backlash then shows as a step of the full play where the torque reverses, a zero offset "
      "stays the same constant",
      joint);
}

const calib::DriveParameters& drive_of(const NominalPlant& plant, std::size_t joint) {
  return plant.config.robot.joints[joint].drive;
}

const NominalParameterDefinition kNominal{
    .parameter_count = 1,
    .of_drive = true,
    // The play lives in the elastic gear (sim/plant_config.hpp).
    .applies = [](const NominalPlant& plant,
                  std::size_t joint) { return plant.config.effects[joint].elastic_gear; },
    .nominal_value =
        [](const NominalPlant& plant, std::size_t joint) {
          return plant.config.effects[joint].backlash ? drive_of(plant, joint).backlash_rad : 0.0;
        },
    .typical_value =
        [](const NominalPlant& plant, std::size_t joint) {
          const double b = drive_of(plant, joint).backlash_rad;
          return b > 0.0 ? b : 1e-4;
        },
    .apply =
        [](const NominalParameter& parameter, const double* p, sim::PlantConfig& config,
           sim::DesiredJointPath&) {
          auto& effects = config.effects[parameter.joint];
          auto& drive = config.robot.joints[parameter.joint].drive;
          drive.backlash_rad = std::max(0.0, (effects.backlash ? drive.backlash_rad : 0.0) + p[0]);
          effects.backlash = true;
        },
    .describe =
        [](const std::string& joint, const NominalParameter&, const Eigen::VectorXd& p_own,
           double nominal) {
          return fmt::format("{} backlash {:.3g} arcmin (nominal {:.3g} arcmin)", joint,
                             (nominal + p_own[0]) / kRadPerArcmin, nominal / kRadPerArcmin);
        },
};

}  // namespace

const EffectDefinition kBacklashEffect{
    .kind = EffectKind::kBacklash,
    .name = "backlash",
    .acts_through_dynamics = true,
    .what_to_measure =
        "slow reversals of the joint and static poses approached from both sides "
        "(play does not depend on speed)",
    .shapes = shapes,
    .shape_pools = shape_pools,
    .size_in_words = size_in_words,
    .separate_from = separate_from,
    .nominal = &kNominal,
};

}  // namespace imscal::eval
