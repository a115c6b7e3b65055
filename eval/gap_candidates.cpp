#include "eval/gap_candidates.hpp"

#include <fmt/format.h>

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

#include "core/units.hpp"
#include "eval/gap_bounds.hpp"
#include "eval/gap_coupling.hpp"
#include "eval/gap_filters.hpp"
#include "eval/gap_validation.hpp"

namespace imscal::eval {
namespace {

std::vector<std::string> numbered(const std::string& stem, int count) {
  std::vector<std::string> names;
  for (int i = 0; i < count; ++i) names.push_back(fmt::format("{}{}_rad", stem, i));
  return names;
}

// Velocity scale of the smooth sign of the desired velocity [rad/s]: 0.3 deg/s, well below any
// programmed speed.
constexpr double kSignVelocityScale = 0.005;

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

// A nominal drive parameter of a joint, 0 when not known.
double nominal_of(const std::vector<double>& values, std::size_t joint) {
  return joint < values.size() ? values[joint] : 0.0;
}

}  // namespace

const char* to_string(EffectKind kind) {
  switch (kind) {
    case EffectKind::kBacklash:
      return "backlash";
    case EffectKind::kCoulombFriction:
      return "coulomb_friction";
    case EffectKind::kGearCompliance:
      return "gear_compliance";
    case EffectKind::kTransmissionError:
      return "transmission_error";
    case EffectKind::kResonance:
      return "structural_resonance";
    case EffectKind::kTimeOffset:
      return "time_offset";
    case EffectKind::kPayloadMismatch:
      return "payload_mismatch";
    case EffectKind::kZeroOffset:
      return "zero_offset";
    case EffectKind::kThermalDrift:
      return "thermal_drift";
    case EffectKind::kOperatingPoint:
      return "operating_point_extrapolation";
    case EffectKind::kKinematicParameters:
      return "kinematic_parameters";
    case EffectKind::kSensorMounting:
      return "sensor_mounting";
    case EffectKind::kImsScaleFactor:
      return "ims_scale_factor";
    case EffectKind::kImsBias:
      return "ims_bias";
    case EffectKind::kClockOffset:
      return "clock_offset";
  }
  return "?";
}

EffectKind effect_kind_from_index(int index) {
  if (index < 0 || index >= kEffectKindCount)
    throw std::invalid_argument("effect kind index out of range");
  return static_cast<EffectKind>(index);
}

// The fewest periods a searched order's ripple must complete over the joint's motion.
constexpr double kMinRipplePeriods = 10.0;

std::vector<double> transmission_orders_by_fit(const GapSignals& s, std::size_t joint,
                                               const std::vector<double>& gap,
                                               const std::vector<bool>& use) {
  const std::size_t n = s.sample_count();
  const auto [lowest, highest] =
      std::minmax_element(s.q_internal_rad[joint].begin(), s.q_internal_rad[joint].end());
  const double motor_range_rad = n > 0 ? s.gear_ratio[joint] * (*highest - *lowest) : 0.0;
  std::vector<std::pair<double, double>> scored;  // (rms, order)
  for (int twice = 2; twice <= 16; ++twice) {
    const double h = 0.5 * twice;
    // A ripple of fewer periods over the motion is a slow drift to the data, not an order.
    if (h * motor_range_rad < kMinRipplePeriods * 2.0 * M_PI) continue;
    Eigen::MatrixXd columns(Eigen::Index(n), 2);
    for (std::size_t k = 0; k < n; ++k) {
      const double angle = h * s.gear_ratio[joint] * s.q_internal_rad[joint][k];
      columns(Eigen::Index(k), 0) = std::sin(angle);
      columns(Eigen::Index(k), 1) = std::cos(angle);
    }
    scored.emplace_back(fit_columns(columns, gap, use).rms, h);
  }
  std::sort(scored.begin(), scored.end());
  std::vector<double> orders;
  for (const auto& [rms, h] : scored) orders.push_back(h);
  return orders;
}

std::vector<CandidateShape> candidate_shapes(EffectKind kind, const GapSignals& s,
                                             std::size_t joint, const std::vector<bool>* training) {
  const Eigen::Index n = Eigen::Index(s.sample_count());
  const std::size_t nj = s.joint_count();
  const Column qd = to_column(s.qd_desired_rad_s[joint]);
  const Column qdd = to_column(s.qdd_desired_rad_s2[joint]);
  // The drive's actual motion (q_internal) where known: its velocity and its torque.
  const bool actual = joint < s.qd_internal_rad_s.size() && joint < s.torque_internal_nm.size() &&
                      rms_of(to_column(s.qd_internal_rad_s[joint])) > 0.0;
  const Column qd_actual = actual ? to_column(s.qd_internal_rad_s[joint]) : qd;
  const Column tau_actual =
      actual ? to_column(s.torque_internal_nm[joint]) : to_column(s.torque_nm[joint]);
  // A shape on this joint only.
  const auto local = [&](std::string label, std::vector<Column> cols,
                         std::vector<std::string> names) {
    CandidateShape sh;
    sh.label = std::move(label);
    sh.columns.assign(nj, Eigen::MatrixXd());
    sh.columns[joint] = matrix_of(cols);
    sh.parameter_names = std::move(names);
    return sh;
  };
  // A shape with the same parameters on every joint: column block `cols` of joint j's matrix.
  const auto shared = [&](std::string label, const auto& matrix_of_joint, std::vector<int> cols,
                          std::vector<std::string> names) {
    CandidateShape sh;
    sh.label = std::move(label);
    for (std::size_t j = 0; j < nj; ++j) {
      const Eigen::MatrixXd& m = matrix_of_joint(j);
      Eigen::MatrixXd c(n, Eigen::Index(cols.size()));
      for (std::size_t i = 0; i < cols.size(); ++i) c.col(Eigen::Index(i)) = m.col(cols[i]);
      sh.columns.push_back(c);
    }
    sh.parameter_names = std::move(names);
    return sh;
  };
  std::vector<CandidateShape> out;
  switch (kind) {
    case EffectKind::kBacklash: {
      // The paper's eq. 3: the sign of the velocity (smooth, no memory).
      const Column sv = (qd_actual / kSignVelocityScale).array().tanh().matrix();
      out.push_back(local("sign(qd)", {sv}, {"l_rad"}));
      out.push_back(local("sign(qd) + lag 30 ms", {sv, lag(sv, 0.03, s)}, {"l_rad", "l_lag_rad"}));
      // The flank the link rests on: a relay with memory of the sign of the gear torque (the link
      // crosses the play when the torque the gear must pass changes sign, and stays on its flank
      // while the torque is small). That torque is the rigid-body torque of the drive's actual
      // motion plus the friction at the link (an unknown share of the joint's friction, which on
      // light wrist axes outweighs their inertia torques): z = tau / RMS(tau) + c tanh(qd / v_s),
      // c = 0 (torque only), 0.03 .. 3, or the velocity alone; thresholds 2 or 10 % of the
      // torque's RMS. The link lands on the other flank with the gear's and the loop's dynamics:
      // [r] or [r, Laguerre 10, 30 or 100 ms x4 of r].
      const double tau_rms = std::max(rms_of(tau_actual), 1e-12);
      // The smooth sign of the torque without memory (the link also starts across the play on
      // short torque dips that do not reach the other flank): scales 1, 5, 20 % of its RMS, raw or
      // with Laguerre 10, 30 or 100 ms x4; only when at least 5 % of the samples lie on the
      // torque's minority side (otherwise it is the one-flank offset below).
      std::size_t positive = 0;
      for (Eigen::Index k = 0; k < n; ++k) positive += tau_actual[k] > 0.0;
      const double minority = double(std::min<std::size_t>(positive, std::size_t(n) - positive));
      if (minority >= 0.05 * double(n))
        for (double fraction : {0.01, 0.05, 0.2}) {
          const Column st = (tau_actual / (fraction * tau_rms)).array().tanh().matrix();
          const std::string label =
              fmt::format("sign(tau) at {:.0f} % of its RMS", 100.0 * fraction);
          out.push_back(local(label, {st}, {"l_rad"}));
          for (double tl : {0.01, 0.03, 0.1}) {
            std::vector<Column> cols = laguerre(st, tl, 4, s);
            cols.insert(cols.begin(), st);
            const int ms = int(std::lround(1000.0 * tl));
            std::vector<std::string> names = numbered(fmt::format("laguerre{}ms_", ms), 4);
            names.insert(names.begin(), "l_rad");
            out.push_back(local(fmt::format("{} + Laguerre {} ms x4", label, ms), cols, names));
          }
        }
      std::vector<std::pair<std::string, Column>> relays;
      for (double h : {0.02, 0.1})
        relays.emplace_back(fmt::format("sign(tau), hold below {:.0f} % of its RMS", 100.0 * h),
                            relay(tau_actual / tau_rms, h, s));
      for (double c : {0.03, 0.1, 0.3, 1.0, 3.0})
        relays.emplace_back(fmt::format("sign(tau + {:.2f} RMS(tau) sign(qd)), hold below 2 %", c),
                            relay(tau_actual / tau_rms + c * sv, 0.02, s));
      relays.emplace_back("sign(qd), held at rest", relay(qd_actual, kSignVelocityScale, s));
      bool one_flank_added = false;
      for (const auto& [label, r] : relays) {
        // A relay that never switches: the gear torque keeps its sign, the link stays on one
        // flank and the play shows as a constant offset of half its width (one shape for all).
        if (r.maxCoeff() == r.minCoeff()) {
          if (!one_flank_added) out.push_back(local(kOneFlankShape, {r}, {"l_rad"}));
          one_flank_added = true;
          continue;
        }
        out.push_back(local(label, {r}, {"l_rad"}));
        for (double tl : {0.01, 0.03, 0.1}) {
          std::vector<Column> cols = laguerre(r, tl, 4, s);
          cols.insert(cols.begin(), r);
          const int ms = int(std::lround(1000.0 * tl));
          std::vector<std::string> names = numbered(fmt::format("laguerre{}ms_", ms), 4);
          names.insert(names.begin(), "l_rad");
          out.push_back(local(fmt::format("{} + Laguerre {} ms x4", label, ms), cols, names));
        }
      }
      for (auto& sh : out)  // the flank: the first column
        sh.level_signal = sh.columns[joint].col(0),
        sh.level_lower = -nominal_of(s.nominal_half_play_rad, joint);
      break;
    }
    case EffectKind::kCoulombFriction: {
      // A lower friction than the nominal one is physical when the nominal model has some.
      const double lower = nominal_of(s.nominal_coulomb_nm, joint) > 0.0
                               ? -std::numeric_limits<double>::infinity()
                               : 0.0;
      for (double scale : {0.005, 0.01, 0.02}) {
        const Column sv = (qd_actual / scale).array().tanh().matrix();
        const int mrad = int(std::lround(1000.0 * scale));
        std::vector<Column> hp;
        for (double tau : {0.03, 0.1, 0.3}) hp.push_back(sv - lag(sv, tau, s));
        out.push_back(local(fmt::format("sign(qd / {} mrad/s) high-passed 30/100/300 ms", mrad), hp,
                            {"hp30ms_rad", "hp100ms_rad", "hp300ms_rad"}));
        for (const auto& [tl, order] : {std::pair{0.1, 6}, std::pair{0.1, 4}, std::pair{0.03, 6}}) {
          const int ms = int(std::lround(1000.0 * tl));
          out.push_back(
              local(fmt::format("sign(qd / {} mrad/s) through Laguerre {} ms x{}", mrad, ms, order),
                    laguerre(sv, tl, order, s), numbered(fmt::format("laguerre{}ms_", ms), order)));
        }
        for (std::size_t i = out.size() - 4; i < out.size(); ++i)
          out[i].level_signal = sv, out[i].level_lower = lower;
      }
      break;
    }
    case EffectKind::kGearCompliance: {
      const Column tau = to_column(s.torque_nm[joint]);
      out.push_back(local("tau_d / k", {tau}, {"compliance_rad_per_nm"}));
      // Gravity and motion torques apart (the load model of the gravity part is the least sure).
      const Column grav = to_column(s.gravity_torque_nm[joint]);
      out.push_back(local("gravity and motion torques / k", {grav, tau - grav},
                          {"compliance_rad_per_nm", "motion_compliance_rad_per_nm"}));
      // The deflection's dynamics (gear damping, the link's mode): Laguerre bases of 30 ms.
      for (int order : {2, 6}) {
        std::vector<Column> cols = laguerre(tau, 0.03, order, s);
        cols.insert(cols.begin(), tau);
        std::vector<std::string> names = numbered("laguerre30ms_", order);
        names.insert(names.begin(), "compliance_rad_per_nm");
        out.push_back(local(fmt::format("tau_d / k + Laguerre 30 ms x{}", order), cols, names));
      }
      for (auto& sh : out)
        sh.level_signal = tau, sh.level_lower = -nominal_of(s.nominal_compliance_rad_per_nm, joint);
      break;
    }
    case EffectKind::kTransmissionError: {
      // te(theta) = A sin(h N theta + phi) between motor and link, theta the motor angle / N: the
      // link follows it below the closed loop's bandwidth and not above the link's mode, and the
      // motor feels it as a torque ripple te'(theta) tau_g (the virtual work of the gear): the
      // joint's error is a linear response to sin, cos (and tau sin, tau cos) of h N theta, whose
      // frequency h N qd sweeps through those modes. Raw, or through Laguerre bases of 3, 10 or
      // 30 ms (the response without knowing the loop's poles), with the ripple through 100 ms.
      if (joint >= s.q_internal_rad.size()) break;  // the motor angle is not known
      const Column q = to_column(s.q_internal_rad[joint]);
      const double n_gear = s.gear_ratio[joint];
      const Column tau_d = to_column(s.torque_nm[joint]);
      const double tau_d_rms = std::max(rms_of(tau_d), 1e-12);
      const auto through = [&](const std::vector<Column>& inputs, double tl, int order,
                               const std::vector<std::string>& stems) {
        std::vector<Column> cols;
        std::vector<std::string> names;
        const int ms = int(std::lround(1000.0 * tl));
        for (std::size_t i = 0; i < inputs.size(); ++i) {
          for (auto& c : laguerre(inputs[i], tl, order, s)) cols.push_back(std::move(c));
          for (auto& nm : numbered(fmt::format("{}_laguerre{}ms_", stems[i], ms), order))
            names.push_back(std::move(nm));
        }
        return std::pair{cols, names};
      };
      std::vector<double> orders = {1.0, 2.0, 3.0};
      if (training)  // two further orders from the search on the training rows
        for (double h : transmission_orders_by_fit(s, joint, s.gap_rad[joint], *training))
          if (orders.size() < 5 && std::find(orders.begin(), orders.end(), h) == orders.end())
            orders.push_back(h);
      for (double h : orders) {
        const Column phase = h * n_gear * q;
        const Column sn = phase.array().sin().matrix(), cs = phase.array().cos().matrix();
        out.push_back(local(fmt::format("harmonic {} of the motor angle", h), {sn, cs},
                            {"sin_rad", "cos_rad"}));
        for (const auto& [tl, order] :
             {std::pair{0.003, 3}, std::pair{0.003, 4}, std::pair{0.01, 4}, std::pair{0.03, 4}}) {
          auto [cols, names] = through({sn, cs}, tl, order, {"sin", "cos"});
          out.push_back(local(fmt::format("harmonic {} of the motor angle through Laguerre {:.0f} "
                                          "ms x{}",
                                          h, 1000.0 * tl, order),
                              cols, names));
        }
        // The ripple torque through the loop's slower response (its PI integrates it): tau_d (the
        // desired motion's torque: the actual one carries the ripple's own oscillation).
        const Column ts = tau_d.cwiseProduct(sn) / tau_d_rms;
        const Column tc = tau_d.cwiseProduct(cs) / tau_d_rms;
        {
          auto [cols, names] = through({sn, cs}, 0.01, 3, {"sin", "cos"});
          auto [rc, rn] = through({ts, tc}, 0.1, 3, {"tau_sin", "tau_cos"});
          cols.insert(cols.end(), rc.begin(), rc.end());
          names.insert(names.end(), rn.begin(), rn.end());
          out.push_back(
              local(fmt::format("harmonic {} of the motor angle through Laguerre 10 ms x3 "
                                "and its torque ripple through Laguerre 100 ms x3",
                                h),
                    cols, names));
        }
        {
          auto [cols, names] = through({sn, cs}, 0.003, 3, {"sin", "cos"});
          auto [mc, mn] = through({sn, cs}, 0.03, 3, {"sin", "cos"});
          auto [rc, rn] = through({ts, tc}, 0.1, 3, {"tau_sin", "tau_cos"});
          cols.insert(cols.end(), mc.begin(), mc.end());
          cols.insert(cols.end(), rc.begin(), rc.end());
          names.insert(names.end(), mn.begin(), mn.end());
          names.insert(names.end(), rn.begin(), rn.end());
          out.push_back(
              local(fmt::format("harmonic {} of the motor angle through Laguerre 3 and 30 "
                                "ms x3 and its torque ripple through Laguerre 100 ms x3",
                                h),
                    cols, names));
        }
      }
      break;
    }
    case EffectKind::kResonance: {
      // A lightly damped mode is only fitted where its frequency is: 2..40 Hz in steps of 10 %.
      for (double f = 2.0; f < 41.0; f *= 1.1)
        for (double zeta : {0.02, 0.04, 0.07, 0.12, 0.3}) {
          auto [y, r] = second_order(qdd, f, zeta, s);
          out.push_back(local(fmt::format("mode {:.2f} Hz, damping {:.2f}", f, zeta), {y, r},
                              {"gain_rad_s2_per_rad_s2", "quadrature"}));
        }
      break;
    }
    case EffectKind::kTimeOffset:
      out.push_back(local("qd_d * dt", {qd}, {"dt_s"}));
      break;
    case EffectKind::kClockOffset: {
      if (joint != 0 || nj < 2) break;  // one candidate for all joints
      // The measured motion's velocity: the drive's actual one where known (the link lags q_d by
      // the tracking error, ~80 ms on the main axes), else q̇_d.
      const auto velocity = [&](std::size_t j) {
        const bool known =
            j < s.qd_internal_rad_s.size() && rms_of(to_column(s.qd_internal_rad_s[j])) > 0.0;
        return Eigen::MatrixXd(to_column(known ? s.qd_internal_rad_s[j] : s.qd_desired_rad_s[j]));
      };
      out.push_back(shared("q̇_j * dt on every joint", velocity, {0}, {"dt_s"}));
      break;
    }
    case EffectKind::kPayloadMismatch: {
      if (joint != 0) break;  // one candidate for all joints, as the IMS chain's errors below
      // Every joint the payload loads (d tau / d m above 1e-6 N m/kg), each with its own
      // parameters: the same mass error acts on each through that joint's own compliance and loop.
      // The unit-payload torque along the drive's actual motion where known (the mass loads the
      // arm as it moves), else along q_d.
      const auto unit_torque = [&](std::size_t j) {
        const bool internal = j < s.unit_payload_internal_nm_kg.size() &&
                              s.unit_payload_internal_nm_kg[j].size() == std::size_t(n);
        return to_column(internal ? s.unit_payload_internal_nm_kg[j] : s.unit_payload_nm_kg[j]);
      };
      std::vector<std::size_t> loaded;
      for (std::size_t j = 0; j < nj; ++j)
        if (rms_of(to_column(s.unit_payload_nm_kg[j])) > 1e-6) loaded.push_back(j);
      if (loaded.empty()) break;
      const auto per_joint = [&](std::string label, int width, const auto& columns_of,
                                 const std::string& stem) {
        CandidateShape sh;
        sh.label = std::move(label);
        sh.columns.assign(nj, Eigen::MatrixXd());
        const Eigen::Index p = Eigen::Index(width * int(loaded.size()));
        for (std::size_t i = 0; i < loaded.size(); ++i) {
          const std::size_t j = loaded[i];
          Eigen::MatrixXd c = Eigen::MatrixXd::Zero(n, p);
          c.middleCols(Eigen::Index(i) * width, width) = matrix_of(columns_of(j));
          sh.columns[j] = c;
          for (int w = 0; w < width; ++w)
            sh.parameter_names.push_back(
                width == 1 ? fmt::format("dm_over_k_{}_rad_per_kg", s.joint_names[j])
                           : fmt::format("{}{}_{}_rad_per_kg", stem, w, s.joint_names[j]));
        }
        return sh;
      };
      out.push_back(per_joint(
          "d tau / d m / k on every loaded joint", 1,
          [&](std::size_t j) { return std::vector<Column>{unit_torque(j)}; }, ""));
      for (const auto& [scale, count] : {std::pair{0.03, 4}, std::pair{0.1, 6}}) {
        // Plain copies: clang 14 does not let a lambda capture structured bindings.
        const double tl = scale;
        const int order = count;
        const int ms = int(std::lround(1000.0 * tl));
        out.push_back(per_joint(
            fmt::format("d tau / d m through Laguerre {} ms x{} on every loaded joint", ms, order),
            order, [&](std::size_t j) { return laguerre(unit_torque(j), tl, order, s); },
            fmt::format("laguerre{}ms_", ms)));
      }
      // Both time scales: the loop's fast reaction to the inertia part and its slow one (the PI
      // working off the static part).
      out.push_back(per_joint(
          "d tau / d m through Laguerre 30 ms x4 + 100 ms x6 on every loaded joint", 10,
          [&](std::size_t j) {
            std::vector<Column> cols = laguerre(unit_torque(j), 0.03, 4, s);
            for (auto& c : laguerre(unit_torque(j), 0.1, 6, s)) cols.push_back(std::move(c));
            return cols;
          },
          "laguerre30ms100ms_"));
      break;
    }
    case EffectKind::kZeroOffset:
      out.push_back(local("constant", {Column::Ones(n)}, {"offset_rad"}));
      break;
    case EffectKind::kThermalDrift: {
      const double t0 = s.time_s.front(), t1 = s.time_s.back();
      const double span = std::max(t1 - t0, s.cycle_s);
      Column t(n);
      for (Eigen::Index k = 0; k < n; ++k)
        t[k] = (s.time_s[std::size_t(k)] - 0.5 * (t0 + t1)) / span;
      // With its constant: a drift starts from some offset (a pure offset ranks above it by
      // parsimony, see eval/gap_diagnosis.cpp).
      out.push_back(local("constant + linear + quadratic in time",
                          {Column::Ones(n), t, t.array().square().matrix()},
                          {"offset_rad", "slope_rad", "curvature_rad"}));
      break;
    }
    case EffectKind::kOperatingPoint: {
      const double limit = identified_speed_limit(s, joint);
      if (!std::isfinite(limit) || limit <= 0.0) break;
      Column o(n), os(n);
      for (Eigen::Index k = 0; k < n; ++k) {
        o[k] = std::max(0.0, std::abs(qd[k]) - limit) / limit;
        os[k] = o[k] * std::tanh(qd[k] / kSignVelocityScale);
      }
      if (o.cwiseAbs().maxCoeff() == 0.0) break;  // never outside: nothing to fit
      out.push_back(local(fmt::format("beyond identified speed {:.3f} rad/s", limit), {o, os},
                          {"per_excess_rad", "per_excess_signed_rad"}));
      break;
    }
    // The IMS chain's errors: one parameter vector for all joints (see the header). They are the
    // same candidate whatever `joint` is asked for: only joint 0 returns them.
    case EffectKind::kKinematicParameters: {
      if (joint != 0 || s.ims_chain_columns.size() != nj) break;
      const auto dh = [&](std::size_t j) -> const Eigen::MatrixXd& {
        return s.ims_chain_columns[j].dh;
      };
      for (int link = 0; link < 6; ++link) {
        std::vector<int> cols;
        std::vector<std::string> names;
        const char* what[3] = {"a", "alpha", "d"};
        const char* unit[3] = {"m", "rad", "m"};
        for (int p = 0; p < 3; ++p) {
          // A parameter that moves no joint's gap by 1e-9 rad per unit has no signature here
          // (e.g. d_1 for a base offset along axis 1).
          double largest = 0.0;
          for (std::size_t j = 0; j < nj; ++j)
            largest = std::max(largest, rms_of(dh(j).col(3 * link + p)));
          if (largest < 1e-9) continue;
          cols.push_back(3 * link + p);
          names.push_back(fmt::format("d{}{}_{}", what[p], link + 1, unit[p]));
        }
        if (!cols.empty())
          out.push_back(shared(fmt::format("DH a/alpha/d of link {}", link + 1), dh, cols, names));
      }
      break;
    }
    case EffectKind::kSensorMounting: {
      if (joint != 0 || s.ims_chain_columns.size() != nj) break;
      const auto m = [&](std::size_t j) -> const Eigen::MatrixXd& {
        return s.ims_chain_columns[j].mounting;
      };
      out.push_back(shared("mounting rotation", m, {3, 4, 5}, {"rx_rad", "ry_rad", "rz_rad"}));
      out.push_back(shared("mounting translation", m, {0, 1, 2}, {"tx_m", "ty_m", "tz_m"}));
      out.push_back(shared("mounting rotation and translation", m, {3, 4, 5, 0, 1, 2},
                           {"rx_rad", "ry_rad", "rz_rad", "tx_m", "ty_m", "tz_m"}));
      break;
    }
    case EffectKind::kImsScaleFactor: {
      if (joint != 0 || s.ims_chain_columns.size() != nj) break;
      std::vector<Eigen::MatrixXd> isotropic;
      for (std::size_t j = 0; j < nj; ++j) {
        const auto& c = s.ims_chain_columns[j];
        Eigen::MatrixXd m(n, 2);
        m << c.gyro_scale.rowwise().sum(), c.accel_scale.col(0);
        isotropic.push_back(m);
      }
      const auto iso = [&](std::size_t j) -> const Eigen::MatrixXd& { return isotropic[j]; };
      const auto gyro = [&](std::size_t j) -> const Eigen::MatrixXd& {
        return s.ims_chain_columns[j].gyro_scale;
      };
      out.push_back(shared("gyro scale, isotropic", iso, {0}, {"gyro_scale"}));
      out.push_back(shared("gyro scale per flange axis", gyro, {0, 1, 2},
                           {"gyro_scale_x", "gyro_scale_y", "gyro_scale_z"}));
      out.push_back(shared("accelerometer scale, isotropic", iso, {1}, {"accel_scale"}));
      break;
    }
    case EffectKind::kImsBias: {
      if (joint != 0 || s.ims_chain_columns.size() != nj) break;
      const auto b = [&](std::size_t j) -> const Eigen::MatrixXd& {
        return s.ims_chain_columns[j].gyro_bias;
      };
      out.push_back(shared("gyro bias about the flange axes", b, {0, 1, 2},
                           {"bx_rad_s", "by_rad_s", "bz_rad_s"}));
      break;
    }
  }
  return out;
}

namespace {

// The runs of consecutive indices in `rows` (ascending), as [begin, end) positions in rows.
std::vector<std::pair<Eigen::Index, Eigen::Index>> consecutive_runs(
    const std::vector<Eigen::Index>& rows) {
  std::vector<std::pair<Eigen::Index, Eigen::Index>> runs;
  for (std::size_t i = 0; i < rows.size(); ++i)
    if (i == 0 || rows[i] != rows[i - 1] + 1)
      runs.emplace_back(Eigen::Index(i), Eigen::Index(i) + 1);
    else
      ++runs.back().second;
  return runs;
}

}  // namespace

LinearFit fit_columns(const Eigen::MatrixXd& columns, const std::vector<double>& y,
                      const std::vector<bool>& use) {
  std::vector<Eigen::Index> rows;
  for (std::size_t k = 0; k < use.size(); ++k)
    if (use[k]) rows.push_back(Eigen::Index(k));
  const Eigen::Index m = Eigen::Index(rows.size()), p = columns.cols();
  // Gathered column by column (a column-major matrix's rows are strided).
  Eigen::MatrixXd x = columns(rows, Eigen::all);
  Eigen::VectorXd b(m);
  for (Eigen::Index i = 0; i < m; ++i) b[i] = y[std::size_t(rows[std::size_t(i)])];
  // Column scaling keeps the QR well conditioned for columns of very different sizes.
  Eigen::VectorXd scale(p);
  for (Eigen::Index c = 0; c < p; ++c) {
    const double nrm = x.col(c).norm();
    scale[c] = nrm > 0.0 ? nrm : 1.0;
    x.col(c) /= scale[c];
  }
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(x);
  LinearFit fit;
  Eigen::VectorXd theta = qr.solve(b);
  const Eigen::VectorXd r = b - x * theta;
  fit.rms = m ? std::sqrt(r.squaredNorm() / double(m)) : 0.0;
  // Integrated autocorrelation time of the residual (consecutive rows only; summed up to the first
  // non-positive correlation, at most 200 lags): the effective number of independent rows is
  // m / tau_int, so sigma grows by sqrt(tau_int).
  double tau_int = 1.0;
  const double var = r.squaredNorm() / std::max<double>(double(m), 1.0);
  if (var > 0.0) {
    const std::vector<std::pair<Eigen::Index, Eigen::Index>> runs = consecutive_runs(rows);
    for (Eigen::Index lagk = 1; lagk < std::min<Eigen::Index>(200, m); ++lagk) {
      // The pairs lagk apart in the same run, in row order.
      double c = 0.0;
      for (const auto& [begin, end] : runs)
        for (Eigen::Index i = begin + lagk; i < end; ++i) c += r[i] * r[i - lagk];
      const double rho = c / (double(m) * var);
      if (rho <= 0.0) break;
      tau_int += 2.0 * rho;
    }
  }
  fit.inflation = std::sqrt(tau_int);
  const double dof = std::max<double>(double(m - p), 1.0);
  const double s2 = r.squaredNorm() / dof;
  const Eigen::MatrixXd rr =
      qr.matrixR().topLeftCorner(p, p).template triangularView<Eigen::Upper>();
  // Cov(theta_scaled) = s2 (R^T R)^-1 in the pivoted order.
  Eigen::MatrixXd cov_piv =
      s2 * (rr.transpose() * rr).completeOrthogonalDecomposition().pseudoInverse();
  const auto perm = qr.colsPermutation();
  const Eigen::MatrixXd cov = perm * cov_piv * perm.transpose();
  fit.parameters = theta.cwiseQuotient(scale);
  const Eigen::VectorXd inverse_scale = scale.cwiseInverse();
  fit.covariance = inverse_scale.asDiagonal() * cov * inverse_scale.asDiagonal();
  fit.covariance *= fit.inflation * fit.inflation;
  fit.sigma = cov.diagonal().cwiseMax(0.0).cwiseSqrt().cwiseQuotient(scale) * fit.inflation;
  return fit;
}

namespace {

// The rows of the joints that have columns, stacked: joint after joint, all samples each.
struct Stacked {
  Eigen::MatrixXd x;
  std::vector<double> y;
  std::vector<std::size_t> joints;  // in stacking order
};

Stacked stack(const std::vector<Eigen::MatrixXd>& columns,
              const std::vector<std::vector<double>>& gap) {
  Stacked st;
  Eigen::Index p = 0, n = 0;
  for (std::size_t j = 0; j < columns.size(); ++j)
    if (columns[j].size() > 0) {
      st.joints.push_back(j);
      p = columns[j].cols();
      n = columns[j].rows();
    }
  st.x.resize(n * Eigen::Index(st.joints.size()), p);
  st.y.reserve(std::size_t(st.x.rows()));
  for (std::size_t i = 0; i < st.joints.size(); ++i) {
    st.x.middleRows(Eigen::Index(i) * n, n) = columns[st.joints[i]];
    st.y.insert(st.y.end(), gap[st.joints[i]].begin(), gap[st.joints[i]].end());
  }
  return st;
}

std::vector<bool> repeat(const std::vector<bool>& use, std::size_t times) {
  std::vector<bool> out;
  out.reserve(use.size() * times);
  for (std::size_t i = 0; i < times; ++i) out.insert(out.end(), use.begin(), use.end());
  return out;
}

// The joint whose columns are the only ones, if one joint has columns.
std::optional<std::size_t> only_joint(const std::vector<Eigen::MatrixXd>& columns) {
  std::optional<std::size_t> found;
  for (std::size_t j = 0; j < columns.size(); ++j) {
    if (columns[j].size() == 0) continue;
    if (found) return std::nullopt;
    found = j;
  }
  return found;
}

// Relative margin within which the shape with fewer parameters wins the validation.
constexpr double kShapeParsimony = 0.01;

// The rows of `fold` (sample indices) on every stacked joint.
std::vector<Eigen::Index> stacked_rows(const std::vector<Eigen::Index>& fold, std::size_t joints,
                                       Eigen::Index samples) {
  std::vector<Eigen::Index> rows;
  rows.reserve(fold.size() * joints);
  for (std::size_t i = 0; i < joints; ++i)
    for (Eigen::Index k : fold) rows.push_back(Eigen::Index(i) * samples + k);
  return rows;
}

}  // namespace

LinearFit fit_joint_columns(const std::vector<Eigen::MatrixXd>& columns,
                            const std::vector<std::vector<double>>& gap,
                            const std::vector<bool>& use) {
  // One joint with columns: its rows are the stack (no copy).
  if (const auto j = only_joint(columns)) return fit_columns(columns[*j], gap[*j], use);
  const Stacked st = stack(columns, gap);
  return fit_columns(st.x, st.y, repeat(use, st.joints.size()));
}

std::vector<std::vector<double>> predict_joint_columns(const std::vector<Eigen::MatrixXd>& columns,
                                                       const Eigen::VectorXd& parameters) {
  std::vector<std::vector<double>> out(columns.size());
  for (std::size_t j = 0; j < columns.size(); ++j) {
    if (columns[j].size() == 0) continue;
    const Eigen::VectorXd p = columns[j] * parameters;
    out[j].assign(p.data(), p.data() + p.size());
  }
  return out;
}

std::vector<Eigen::MatrixXd> join_columns(const std::vector<Eigen::MatrixXd>& a,
                                          const std::vector<Eigen::MatrixXd>& b,
                                          std::size_t samples) {
  Eigen::Index pa = 0, pb = 0;
  for (const auto& m : a) pa = std::max(pa, m.cols());
  for (const auto& m : b) pb = std::max(pb, m.cols());
  std::vector<Eigen::MatrixXd> out(std::max(a.size(), b.size()));
  const Eigen::Index n = Eigen::Index(samples);
  for (std::size_t j = 0; j < out.size(); ++j) {
    const bool has_a = j < a.size() && a[j].size() > 0, has_b = j < b.size() && b[j].size() > 0;
    if (!has_a && !has_b) continue;
    out[j] = Eigen::MatrixXd::Zero(n, pa + pb);
    if (has_a) out[j].leftCols(pa) = a[j];
    if (has_b) out[j].rightCols(pb) = b[j];
  }
  return out;
}

namespace {

// Half the step of a backlash's modelled gap between the two flanks: the medians of its own
// joint's modelled gap where the shape's first column (the flank) is positive and negative,
// half their difference (the Laguerre columns' landing transients left aside; samples between
// the flanks, where a smooth sign is near zero, left out). One flank only: the modelled offset.
double half_play(const CandidateFit& c, const CandidateShape& sh) {
  const Eigen::MatrixXd& cols = sh.columns[c.joint];
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

// The size of the effect in words: the first parameter with its sigma (all of them for the IMS
// chain's few geometric parameters), in the effect's own terms where it has them.
std::string size_in_words(const CandidateFit& c, const CandidateShape& sh, double own_rms) {
  std::string first =
      fmt::format("{} = {:.4g} ± {:.2g}", c.parameter_names[0], c.parameters[0], c.sigma[0]);
  switch (c.kind) {
    case EffectKind::kGearCompliance: {
      // The static compliance: the modelled deflection's coefficient on tau_d (the Laguerre
      // columns' static gain included), added to the nominal model's.
      const double nominal = -c.bound.lower, combined = nominal + c.level;
      first = fmt::format("static compliance change {:.3g} rad/N m", c.level);
      if (c.level > 0.0) first += fmt::format(" (a stiffness of {:.3g} N m/rad)", 1.0 / c.level);
      if (nominal > 0.0)
        first += fmt::format(
            "; with the robot's {:.3g} N m/rad, a gear stiffness of {}", 1.0 / nominal,
            combined > 0.0 ? fmt::format("{:.3g} N m/rad", 1.0 / combined) : std::string("rigid"));
      break;
    }
    case EffectKind::kBacklash: {
      const double l = half_play(c, sh);
      if (sh.label == kOneFlankShape)
        first = fmt::format(
            "a constant offset of {:.3g} rad ({:.2f} arcsec): half the play if all of it is the "
            "play (full play {:.2f} arcsec)",
            l, l * kArcsecPerRad, 2.0 * std::abs(l) * kArcsecPerRad);
      else
        first = fmt::format("half play {:.3g} rad ({:.2f} arcsec, full play {:.2f} arcsec)", l,
                            l * kArcsecPerRad, 2.0 * std::abs(l) * kArcsecPerRad);
      break;
    }
    case EffectKind::kTransmissionError: {
      const double a = sh.parameter_names.size() == 2 ? std::hypot(c.parameters[0], c.parameters[1])
                                                      : std::sqrt(2.0) * own_rms;
      first = fmt::format("amplitude {:.3g} rad ({:.2f} arcsec){}", a, a * kArcsecPerRad,
                          sh.parameter_names.size() == 2 ? "" : " at the link (sqrt 2 x RMS)");
      break;
    }
    case EffectKind::kTimeOffset:
    case EffectKind::kClockOffset:
      first += " s";
      break;
    case EffectKind::kSensorMounting:
    case EffectKind::kKinematicParameters:
    case EffectKind::kImsScaleFactor:
    case EffectKind::kImsBias: {
      std::vector<std::string> all;
      for (Eigen::Index i = 0; i < c.parameters.size(); ++i)
        all.push_back(fmt::format("{} = {:.3g} ± {:.2g}", c.parameter_names[std::size_t(i)],
                                  c.parameters[i], c.sigma[i]));
      first = fmt::format("{}", fmt::join(all, ", "));
      break;
    }
    default:
      break;
  }
  return first;
}

// The LS fit of a candidate's columns within its physical bound (eval/gap_bounds.hpp): sets its
// level, the unconstrained one and whether the bound is active.
LinearFit fit_bounded(CandidateFit& c, const GapSignals& s, const std::vector<bool>& training) {
  LinearFit f = fit_joint_columns(c.columns, s.gap_rad, training);
  if (c.bound.count == 0) return f;
  c.unconstrained_level = bound_level(c.columns, c.bound, f.parameters, training);
  c.at_bound = apply_level_bounds(c.columns, s.gap_rad, training, {c.bound}, f);
  c.level = bound_level(c.columns, c.bound, f.parameters, training);
  return f;
}

}  // namespace

bool acts_through_dynamics(EffectKind kind) {
  switch (kind) {
    case EffectKind::kBacklash:
    case EffectKind::kCoulombFriction:
    case EffectKind::kGearCompliance:
    case EffectKind::kTransmissionError:
    case EffectKind::kResonance:
    case EffectKind::kPayloadMismatch:
      return true;
    default:
      return false;
  }
}

std::optional<CandidateFit> fit_candidate(EffectKind kind, const GapSignals& s, std::size_t joint,
                                          const std::vector<bool>& training) {
  const std::vector<CandidateShape> shapes = candidate_shapes(kind, s, joint, &training);
  if (shapes.empty()) return std::nullopt;
  // The shape is chosen by the 2-fold validation inside the training rows
  // (eval/gap_validation.hpp). Of shapes within 1 % of the best validation error, the one with the
  // fewest parameters.
  const TrainingFolds folds = training_folds(s, training);
  const Eigen::Index n = Eigen::Index(s.sample_count());
  const auto validation_score = [&](const std::vector<Eigen::MatrixXd>& columns) {
    // One joint with columns: its rows are the stack (no copy).
    if (const auto j = only_joint(columns))
      return cross_validation_sse(columns[*j], s.gap_rad[*j], folds);
    const Stacked st = stack(columns, s.gap_rad);
    double sse = 0.0;
    for (std::size_t i = 0; i < folds.folds.size(); ++i)
      sse += validation_sse(st.x, st.y, stacked_rows(folds.complements[i], st.joints.size(), n),
                            stacked_rows(folds.folds[i], st.joints.size(), n));
    return sse;
  };
  std::size_t chosen = 0;
  if (shapes.size() > 1 && folds.usable()) {
    std::vector<double> score;
    for (const auto& sh : shapes) score.push_back(validation_score(sh.columns));
    const double best_score = *std::min_element(score.begin(), score.end());
    const auto width = [&](std::size_t i) { return shapes[i].parameter_names.size(); };
    for (std::size_t i = 0; i < shapes.size(); ++i) {
      if (score[i] > best_score * (1.0 + kShapeParsimony)) continue;
      if (score[chosen] > best_score * (1.0 + kShapeParsimony) || width(i) < width(chosen) ||
          (width(i) == width(chosen) && score[i] < score[chosen]))
        chosen = i;
    }
  }
  const CandidateShape& sh = shapes[chosen];
  CandidateFit c;
  c.kind = kind;
  c.joint = joint;
  c.shape = sh.label;
  c.parameter_names = sh.parameter_names;
  c.columns = sh.columns;
  if (sh.level_signal.size() > 0)
    c.bound = {joint, 0, Eigen::Index(sh.parameter_names.size()), sh.level_signal, sh.level_lower};
  LinearFit f = fit_bounded(c, s, training);
  c.prediction = predict_joint_columns(c.columns, f.parameters);
  // Acting on several joints by its own columns: located where its modelled gap has the most
  // energy; acting on one: that joint, wherever its coupling carries it.
  std::size_t acting = 0;
  double most = -1.0;
  for (std::size_t j = 0; j < c.prediction.size(); ++j) {
    if (c.prediction[j].empty()) continue;
    ++acting;
    double e = 0.0;
    for (double v : c.prediction[j]) e += v * v;
    if (e > most) most = e, c.joint = j;
  }
  c.spans_joints = acting > 1;
  double own_energy = 0.0;
  for (double v : c.prediction[c.joint]) own_energy += v * v;
  // Spread over the other joints through the coupled dynamics (effects that move a link only).
  if (acts_through_dynamics(kind)) {
    std::vector<std::vector<double>> residual = s.gap_rad;
    for (std::size_t j = 0; j < residual.size(); ++j)
      for (std::size_t k = 0; k < c.prediction[j].size(); ++k) residual[j][k] -= c.prediction[j][k];
    const CouplingColumns coupling = coupling_columns(s, c.prediction, residual, folds);
    if (!coupling.joints.empty()) {
      c.columns = join_columns(c.columns, coupling.columns, s.sample_count());
      c.parameter_names.insert(c.parameter_names.end(), coupling.parameter_names.begin(),
                               coupling.parameter_names.end());
      c.coupled_joints = coupling.joints;
      c.coupling_parameter_count = coupling.parameter_names.size();
      std::vector<std::string> reach;
      for (std::size_t i = 0; i < coupling.joints.size(); ++i)
        reach.push_back(
            fmt::format("{} ({})", s.joint_names[coupling.joints[i]], coupling.shapes[i]));
      c.coupling = fmt::format("through the inertia M_ij q̈_j into {}", fmt::join(reach, ", "));
      f = fit_bounded(c, s, training);
      c.prediction = predict_joint_columns(c.columns, f.parameters);
    }
  }
  c.parameters = f.parameters;
  c.sigma = f.sigma;
  c.training_rms_rad = f.rms;
  double total = 0.0;
  for (const auto& p : c.prediction)
    for (double v : p) total += v * v;
  const double modelled_rms = std::sqrt(total / double(std::max<Eigen::Index>(n, 1)));
  const double own_rms = std::sqrt(own_energy / double(std::max<Eigen::Index>(n, 1)));
  c.size_text = size_in_words(c, sh, own_rms);
  c.size_text += fmt::format("; modelled gap RMS {:.3g} rad ({:.2f} arcsec){}", modelled_rms,
                             modelled_rms * kArcsecPerRad,
                             c.spans_joints             ? " over all joints"
                             : c.coupled_joints.empty() ? ""
                                                        : " with its coupling");
  if (c.at_bound)
    c.size_text += fmt::format(
        "; held at its physical bound (level {:.3g}: the unconstrained fit's level {:.3g} would "
        "leave the combined model unphysical)",
        c.level, c.unconstrained_level);
  return c;
}

}  // namespace imscal::eval
