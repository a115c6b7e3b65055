// Transmission error: s, c = sin/cos(h N q_internal), h = 1..3 per motor revolution and the two
// orders of 1..8 whose raw ripple best fits the training rows: raw, through L_3ms (x3, x4),
// L_10ms or L_30ms (x4), or with the ripple torque tau_d s, tau_d c (the gear's virtual work on the
// motor) through L_100ms x3 beside L_10ms x3 or L_3ms + L_30ms x3 of s, c: below the loop's
// bandwidth the link follows the error, above the link's mode it does not. In the nominal model:
// a_s, a_c [rad] of a further order h per motor revolution, a_s sin(h θ_m) + a_c cos(h θ_m),
// θ_m the motor angle / N (the order from a search, eval/gap_refinement.hpp); no bound.
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

// One order's pool of columns (eval/gap_shape_pool.hpp): s, c; s, c through L_3ms, L_10ms and
// L_30ms x4 each; the ripple torque's s, c through L_100ms x3.
constexpr Eigen::Index kPoolWidth = 32;
constexpr Eigen::Index kRippleFirst = 26;
// The first pool column of s through Laguerre time scale `scale` (c follows 4 columns on).
Eigen::Index laguerre_first(int scale) {
  return 2 + 8 * Eigen::Index(scale);
}

// `count` columns from pool column `first` on, named "<stem>0_rad", "<stem>1_rad", ...
struct Block {
  Eigen::Index first;
  int count;
  std::string stem;
};

// s and c through Laguerre time scale `scale` (0: 3 ms, 1: 10 ms, 2: 30 ms) of `order`.
std::vector<Block> through(int scale, int order) {
  const int ms = std::array{3, 10, 30}[std::size_t(scale)];
  const Eigen::Index first = laguerre_first(scale);
  return {{first, order, fmt::format("sin_laguerre{}ms_", ms)},
          {first + 4, order, fmt::format("cos_laguerre{}ms_", ms)}};
}

// The ripple torque's s and c through Laguerre 100 ms x3.
std::vector<Block> ripple() {
  return {{kRippleFirst, 3, "tau_sin_laguerre100ms_"},
          {kRippleFirst + 3, 3, "tau_cos_laguerre100ms_"}};
}

void add_shape(ShapePool& pool, std::size_t joint, std::string label,
               const std::vector<std::vector<Block>>& parts) {
  PooledShape shape;
  shape.label = std::move(label);
  shape.pool_columns.assign(pool.columns.size(), {});
  shape.first_parameter.assign(pool.columns.size(), 0);
  for (const auto& part : parts)
    for (const Block& b : part) {
      for (int i = 0; i < b.count; ++i) shape.pool_columns[joint].push_back(b.first + i);
      for (auto& name : numbered(b.stem, b.count)) shape.parameter_names.push_back(std::move(name));
    }
  pool.shapes.push_back(std::move(shape));
}

// The shapes of order h per motor revolution, from one pool.
ShapePool order_pool(const ShapeContext& x, double h) {
  const Column q = to_column(x.s.q_internal_rad[x.joint]);
  const Column tau_d = to_column(x.s.torque_nm[x.joint]);
  const double tau_d_rms = std::max(rms_of(tau_d), 1e-12);
  const Column phase = h * x.s.gear_ratio[x.joint] * q;
  const Column sn = phase.array().sin().matrix(), cs = phase.array().cos().matrix();
  // The ripple torque through the loop's slower response (its PI integrates it): tau_d (the
  // desired motion's torque: the actual one carries the ripple's own oscillation).
  const Column ts = tau_d.cwiseProduct(sn) / tau_d_rms;
  const Column tc = tau_d.cwiseProduct(cs) / tau_d_rms;
  Eigen::MatrixXd m(x.n, kPoolWidth);
  m.col(0) = sn;
  m.col(1) = cs;
  for (int scale = 0; scale < 3; ++scale) {
    const double tl = std::array{0.003, 0.01, 0.03}[std::size_t(scale)];
    laguerre_into(sn, tl, x.s, m.middleCols(laguerre_first(scale), 4));
    laguerre_into(cs, tl, x.s, m.middleCols(laguerre_first(scale) + 4, 4));
  }
  laguerre_into(ts, 0.1, x.s, m.middleCols(kRippleFirst, 3));
  laguerre_into(tc, 0.1, x.s, m.middleCols(kRippleFirst + 3, 3));
  ShapePool pool;
  pool.columns.assign(x.nj, Eigen::MatrixXd());
  pool.columns[x.joint] = std::move(m);
  const std::size_t j = x.joint;
  add_shape(pool, j, fmt::format("harmonic {} of the motor angle", h), {});
  pool.shapes.back().pool_columns[j] = {0, 1};
  pool.shapes.back().parameter_names = {"sin_rad", "cos_rad"};
  for (const auto& [scale, order] :
       {std::pair{0, 3}, std::pair{0, 4}, std::pair{1, 4}, std::pair{2, 4}})
    add_shape(pool, j,
              fmt::format("harmonic {} of the motor angle through Laguerre {} ms x{}", h,
                          std::array{3, 10, 30}[std::size_t(scale)], order),
              {through(scale, order)});
  add_shape(pool, j,
            fmt::format("harmonic {} of the motor angle through Laguerre 10 ms x3 and its torque "
                        "ripple through Laguerre 100 ms x3",
                        h),
            {through(1, 3), ripple()});
  add_shape(pool, j,
            fmt::format("harmonic {} of the motor angle through Laguerre 3 and 30 ms x3 and its "
                        "torque ripple through Laguerre 100 ms x3",
                        h),
            {through(0, 3), through(2, 3), ripple()});
  return pool;
}

// te(theta) = A sin(h N theta + phi) between motor and link, theta the motor angle / N: the link
// follows it below the closed loop's bandwidth and not above the link's mode, and the motor
// feels it as a torque ripple te'(theta) tau_g (the virtual work of the gear): the joint's error
// is a linear response to sin, cos (and tau sin, tau cos) of h N theta, whose frequency h N qd
// sweeps through those modes. Raw, or through Laguerre bases of 3, 10 or 30 ms (the response
// without knowing the loop's poles), with the ripple through 100 ms.
std::vector<ShapePool> shape_pools(const ShapeContext& x) {
  std::vector<ShapePool> pools;
  if (x.joint >= x.s.q_internal_rad.size()) return pools;  // the motor angle is not known
  std::vector<double> orders = {1.0, 2.0, 3.0};
  if (x.training)  // two further orders from the search on the training rows
    for (double h : transmission_orders_by_fit(x.s, x.joint, x.s.gap_rad[x.joint], *x.training))
      if (orders.size() < 5 && std::find(orders.begin(), orders.end(), h) == orders.end())
        orders.push_back(h);
  for (double h : orders) pools.push_back(order_pool(x, h));
  return pools;
}

std::vector<CandidateShape> shapes(const ShapeContext& x) {
  return shapes_from_pools(shape_pools(x));
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
    .shape_pools = shape_pools,
    .size_in_words = size_in_words,
    .nominal = &kNominal,
};

}  // namespace imscal::eval
