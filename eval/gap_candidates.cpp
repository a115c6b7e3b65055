#include "eval/gap_candidates.hpp"

#include <fmt/format.h>

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

namespace imscal::eval {
namespace {

using Column = Eigen::VectorXd;

Column to_column(const std::vector<double>& v) {
  return Eigen::Map<const Eigen::VectorXd>(v.data(), Eigen::Index(v.size()));
}

// First-order lag y' = (u - y) / tau, exact discretisation, restarted at every run from u.
Column lag(const Column& u, double tau_s, const GapSignals& s) {
  Column y(u.size());
  const double a = std::exp(-s.cycle_s / tau_s);
  for (const auto& [b, e] : s.runs) {
    double state = e > b ? u[Eigen::Index(b)] : 0.0;
    for (std::size_t k = b; k < e; ++k) {
      state = a * state + (1.0 - a) * u[Eigen::Index(k)];
      y[Eigen::Index(k)] = state;
    }
  }
  return y;
}

// Lightly damped second-order response ω²/(s² + 2ζωs + ω²) to u (semi-implicit Euler with 8
// substeps per cycle: stable and accurate to < 1 % up to 40 Hz at 2 ms), and its rate / ω.
std::pair<Column, Column> second_order(const Column& u, double f_hz, double zeta,
                                       const GapSignals& s) {
  const double w = 2.0 * M_PI * f_hz;
  const int sub = 8;
  const double h = s.cycle_s / sub;
  Column y(u.size()), r(u.size());
  for (const auto& [b, e] : s.runs) {
    double p = e > b ? u[Eigen::Index(b)] : 0.0, v = 0.0;  // at rest in its first input
    for (std::size_t k = b; k < e; ++k) {
      const double x = u[Eigen::Index(k)];
      for (int i = 0; i < sub; ++i) {
        v += h * (w * w * (x - p) - 2.0 * zeta * w * v);
        p += h * v;
      }
      y[Eigen::Index(k)] = p;
      r[Eigen::Index(k)] = v / w;
    }
  }
  return {y, r};
}

// Discrete Laguerre filters of u with time scale tau (pole a = exp(-T / tau)):
// L_0 = sqrt(1 - a²) / (1 - a z^-1), L_i = L_{i-1} (z^-1 - a) / (1 - a z^-1): an orthonormal
// basis of stable linear responses, so a few columns follow a closed loop's reaction to u without
// knowing its poles. Each run starts in the steady state of its first input.
std::vector<Column> laguerre(const Column& u, double tau_s, int order, const GapSignals& s) {
  const double a = std::exp(-s.cycle_s / tau_s), g0 = std::sqrt(1.0 - a * a);
  std::vector<Column> out(std::size_t(order), Column(u.size()));
  for (const auto& [b, e] : s.runs) {
    if (e <= b) continue;
    const double u0 = u[Eigen::Index(b)];
    std::vector<double> y(std::size_t(order), g0 / (1.0 - a) * u0);
    std::vector<double> x_previous = y;  // each stage's previous input
    x_previous[0] = u0;
    for (std::size_t k = b; k < e; ++k) {
      double x = u[Eigen::Index(k)];
      for (int i = 0; i < order; ++i) {
        double& yi = y[std::size_t(i)];
        const double next = i == 0 ? a * yi + g0 * x : a * yi + x_previous[std::size_t(i)] - a * x;
        x_previous[std::size_t(i)] = x;
        yi = next;
        out[std::size_t(i)][Eigen::Index(k)] = next;
        x = next;
      }
    }
  }
  return out;
}

Eigen::MatrixXd matrix_of(const std::vector<Column>& cols) {
  Eigen::MatrixXd m(cols.empty() ? 0 : cols[0].size(), Eigen::Index(cols.size()));
  for (std::size_t i = 0; i < cols.size(); ++i) m.col(Eigen::Index(i)) = cols[i];
  return m;
}

std::vector<std::string> numbered(const std::string& stem, int count) {
  std::vector<std::string> names;
  for (int i = 0; i < count; ++i) names.push_back(fmt::format("{}{}_rad", stem, i));
  return names;
}

double rms_of(const Column& c) {
  return c.size() ? std::sqrt(c.squaredNorm() / double(c.size())) : 0.0;
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
  }
  return "?";
}

EffectKind effect_kind_from_index(int index) {
  if (index < 0 || index >= kEffectKindCount)
    throw std::invalid_argument("effect kind index out of range");
  return static_cast<EffectKind>(index);
}

std::vector<CandidateShape> candidate_shapes(EffectKind kind, const GapSignals& s,
                                             std::size_t joint) {
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
      const Column sv = (qd_actual / kSignVelocityScale).array().tanh().matrix();
      out.push_back(local("sign(qd)", {sv}, {"l_rad"}));
      out.push_back(local("sign(qd) + lag 30 ms", {sv, lag(sv, 0.03, s)}, {"l_rad", "l_lag_rad"}));
      // The gear torque must change sign for the play to show as anything but a constant
      // offset: with less than 5 % of the samples on the minority side, no torque-sign shape.
      std::size_t positive = 0;
      for (Eigen::Index k = 0; k < n; ++k) positive += tau_actual[k] > 0.0;
      const double minority = double(std::min<std::size_t>(positive, std::size_t(n) - positive));
      if (minority >= 0.05 * double(n)) {
        // The torque's zero crossing is blurred by the unknown load model: scales 1, 5, 20 % of
        // its RMS. The link crosses the play and lands with the gear's own dynamics: Laguerre
        // bases of 10, 30 and 100 ms.
        for (double fraction : {0.01, 0.05, 0.2}) {
          const double tau_scale = std::max(fraction * rms_of(tau_actual), 1e-9);
          const Column st = (tau_actual / tau_scale).array().tanh().matrix();
          const int percent = int(std::lround(100.0 * fraction));
          out.push_back(
              local(fmt::format("sign(tau) at {} % of its RMS", percent), {st}, {"l_rad"}));
          for (double tl : {0.01, 0.03, 0.1}) {
            std::vector<Column> cols = laguerre(st, tl, 4, s);
            cols.insert(cols.begin(), st);
            const int ms = int(std::lround(1000.0 * tl));
            std::vector<std::string> names = numbered(fmt::format("laguerre{}ms_", ms), 4);
            names.insert(names.begin(), "l_rad");
            out.push_back(
                local(fmt::format("sign(tau) at {} % of its RMS + Laguerre {} ms x4", percent, ms),
                      cols, names));
          }
        }
      }
      break;
    }
    case EffectKind::kCoulombFriction: {
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
      break;
    }
    case EffectKind::kTransmissionError: {
      const Column q = to_column(s.q_internal_rad[joint]);
      const double n_gear = s.gear_ratio[joint];
      for (int h = 1; h <= 3; ++h) {
        const Column phase = double(h) * n_gear * q;
        const Column sn = phase.array().sin().matrix(), cs = phase.array().cos().matrix();
        out.push_back(local(fmt::format("harmonic {} of the motor angle", h), {sn, cs},
                            {"sin_rad", "cos_rad"}));
        for (double f : {5.0, 8.0, 11.0, 15.0, 20.0})
          for (double zeta : {0.2, 0.4}) {
            const Column ys = second_order(sn, f, zeta, s).first;
            const Column yc = second_order(cs, f, zeta, s).first;
            out.push_back(local(fmt::format("harmonic {} of the motor angle through a {:.0f} Hz "
                                            "mode, damping {:.1f}",
                                            h, f, zeta),
                                {ys, yc}, {"sin_rad", "cos_rad"}));
          }
      }
      break;
    }
    case EffectKind::kResonance: {
      for (double f : {2.0, 3.0, 4.5, 6.5, 9.0, 12.0, 15.0, 20.0, 27.0, 36.0})
        for (double zeta : {0.02, 0.05, 0.1, 0.3}) {
          auto [y, r] = second_order(qdd, f, zeta, s);
          out.push_back(local(fmt::format("mode {:.1f} Hz, damping {:.2f}", f, zeta), {y, r},
                              {"gain_rad_s2_per_rad_s2", "quadrature"}));
        }
      break;
    }
    case EffectKind::kTimeOffset:
      out.push_back(local("qd_d * dt", {qd}, {"dt_s"}));
      break;
    case EffectKind::kPayloadMismatch: {
      if (joint != 0) break;  // one candidate for all joints, as the IMS chain's errors below
      // Every joint the payload loads (d tau / d m above 1e-6 N m/kg), each with its own
      // parameters: the same mass error acts on each through that joint's own compliance and loop.
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
          [&](std::size_t j) { return std::vector<Column>{to_column(s.unit_payload_nm_kg[j])}; },
          ""));
      for (const auto& [tl_s, order_taps] : {std::pair{0.03, 4}, std::pair{0.1, 6}}) {
        // Copies: clang 14 cannot capture structured bindings in a lambda.
        const double tl = tl_s;
        const int order = order_taps;
        const int ms = int(std::lround(1000.0 * tl));
        out.push_back(per_joint(
            fmt::format("d tau / d m through Laguerre {} ms x{} on every loaded joint", ms, order),
            order,
            [&](std::size_t j) {
              return laguerre(to_column(s.unit_payload_nm_kg[j]), tl, order, s);
            },
            fmt::format("laguerre{}ms_", ms)));
      }
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

LinearFit fit_columns(const Eigen::MatrixXd& columns, const std::vector<double>& y,
                      const std::vector<bool>& use) {
  std::vector<Eigen::Index> rows;
  for (std::size_t k = 0; k < use.size(); ++k)
    if (use[k]) rows.push_back(Eigen::Index(k));
  const Eigen::Index m = Eigen::Index(rows.size()), p = columns.cols();
  Eigen::MatrixXd x(m, p);
  Eigen::VectorXd b(m);
  for (Eigen::Index i = 0; i < m; ++i) {
    x.row(i) = columns.row(rows[std::size_t(i)]);
    b[i] = y[std::size_t(rows[std::size_t(i)])];
  }
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
    for (Eigen::Index lagk = 1; lagk < std::min<Eigen::Index>(200, m); ++lagk) {
      double c = 0.0;
      for (Eigen::Index i = lagk; i < m; ++i)
        if (rows[std::size_t(i)] - rows[std::size_t(i - lagk)] == lagk) c += r[i] * r[i - lagk];
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

// Sum of squared residuals on the rows `check` of the LS fit of columns to y on the rows `fit`
// (parameters only: no sigma needed to choose a shape).
double validation_sse(const Eigen::MatrixXd& columns, const std::vector<double>& y,
                      const std::vector<Eigen::Index>& fit,
                      const std::vector<Eigen::Index>& check) {
  const Eigen::Index p = columns.cols();
  Eigen::MatrixXd x(Eigen::Index(fit.size()), p);
  Eigen::VectorXd b(x.rows());
  for (std::size_t i = 0; i < fit.size(); ++i) {
    x.row(Eigen::Index(i)) = columns.row(fit[i]);
    b[Eigen::Index(i)] = y[std::size_t(fit[i])];
  }
  Eigen::VectorXd scale(p);
  for (Eigen::Index c = 0; c < p; ++c) {
    scale[c] = x.col(c).norm() > 0.0 ? x.col(c).norm() : 1.0;
    x.col(c) /= scale[c];
  }
  const Eigen::VectorXd theta = x.colPivHouseholderQr().solve(b).cwiseQuotient(scale);
  double sse = 0.0;
  for (Eigen::Index k : check) {
    const double r = y[std::size_t(k)] - columns.row(k).dot(theta);
    sse += r * r;
  }
  return sse;
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

std::optional<CandidateFit> fit_candidate(EffectKind kind, const GapSignals& s, std::size_t joint,
                                          const std::vector<bool>& training) {
  const std::vector<CandidateShape> shapes = candidate_shapes(kind, s, joint);
  if (shapes.empty()) return std::nullopt;
  // The shape is chosen by a 2-fold validation inside the training rows: they are cut into
  // chunks of 1 s of consecutive training rows, alternately in fold A and B; each shape is fitted
  // on A and judged on B and vice versa. Unlike a BIC it needs no count of independent rows (the
  // residuals are coloured), and it sees whether the shape carries over to other motion. Of
  // shapes within 1 % of the best validation error, the one with the fewest parameters.
  const std::size_t chunk = std::max<std::size_t>(1, std::size_t(std::lround(1.0 / s.cycle_s)));
  std::vector<Eigen::Index> fold_a, fold_b;
  std::size_t count = 0;
  for (std::size_t k = 0; k < training.size(); ++k)
    if (training[k]) ((count++ / chunk) % 2 == 0 ? fold_a : fold_b).push_back(Eigen::Index(k));
  const Eigen::Index n = Eigen::Index(s.sample_count());
  std::size_t chosen = 0;
  if (shapes.size() > 1 && !fold_b.empty()) {
    std::vector<double> score;
    for (const auto& sh : shapes) {
      const Stacked st = stack(sh.columns, s.gap_rad);
      const auto a = stacked_rows(fold_a, st.joints.size(), n);
      const auto b = stacked_rows(fold_b, st.joints.size(), n);
      score.push_back(validation_sse(st.x, st.y, a, b) + validation_sse(st.x, st.y, b, a));
    }
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
  const LinearFit f = fit_joint_columns(sh.columns, s.gap_rad, training);
  CandidateFit c;
  c.kind = kind;
  c.joint = joint;
  c.shape = sh.label;
  c.parameter_names = sh.parameter_names;
  c.parameters = f.parameters;
  c.sigma = f.sigma;
  c.columns = sh.columns;
  c.training_rms_rad = f.rms;
  c.prediction = predict_joint_columns(c.columns, c.parameters);
  // Acting on several joints: located where its modelled gap has the most energy.
  std::size_t acting = 0;
  double most = -1.0, total = 0.0;
  for (std::size_t j = 0; j < c.prediction.size(); ++j) {
    if (c.prediction[j].empty()) continue;
    ++acting;
    double e = 0.0;
    for (double v : c.prediction[j]) e += v * v;
    total += e;
    if (e > most) most = e, c.joint = j;
  }
  c.spans_joints = acting > 1;
  const double modelled_rms = std::sqrt(total / double(std::max<Eigen::Index>(n, 1)));
  // Size in words: the first parameter with its sigma, and the RMS of the modelled gap.
  const double arcsec = 180.0 / M_PI * 3600.0;
  std::string first =
      fmt::format("{} = {:.4g} ± {:.2g}", c.parameter_names[0], c.parameters[0], c.sigma[0]);
  if (kind == EffectKind::kGearCompliance && c.parameters[0] != 0.0)
    first += fmt::format(" (stiffness {:.3g} N m/rad)", 1.0 / c.parameters[0]);
  if (kind == EffectKind::kBacklash)
    first += fmt::format(" ({:.2f} arcsec, full play {:.2f} arcsec)", c.parameters[0] * arcsec,
                         2.0 * std::abs(c.parameters[0]) * arcsec);
  if (kind == EffectKind::kTransmissionError)
    first = fmt::format("amplitude {:.3g} rad ({:.2f} arcsec)",
                        std::hypot(c.parameters[0], c.parameters[1]),
                        std::hypot(c.parameters[0], c.parameters[1]) * arcsec);
  if (kind == EffectKind::kTimeOffset) first += " s";
  if (kind == EffectKind::kSensorMounting || kind == EffectKind::kKinematicParameters ||
      kind == EffectKind::kImsScaleFactor || kind == EffectKind::kImsBias) {
    std::vector<std::string> all;
    for (Eigen::Index i = 0; i < c.parameters.size(); ++i)
      all.push_back(fmt::format("{} = {:.3g} ± {:.2g}", c.parameter_names[std::size_t(i)],
                                c.parameters[i], c.sigma[i]));
    first = fmt::format("{}", fmt::join(all, ", "));
  }
  c.size_text =
      fmt::format("{}; modelled gap RMS {:.3g} rad ({:.2f} arcsec){}", first, modelled_rms,
                  modelled_rms * arcsec, c.spans_joints ? " over all joints" : "");
  return c;
}

}  // namespace imscal::eval
