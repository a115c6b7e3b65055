#include "eval/gap_filters.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace imscal::eval {

Column to_column(const std::vector<double>& v) {
  return Eigen::Map<const Eigen::VectorXd>(v.data(), Eigen::Index(v.size()));
}

double rms_of(const Column& c) {
  return c.size() ? std::sqrt(c.squaredNorm() / double(c.size())) : 0.0;
}

Eigen::MatrixXd matrix_of(const std::vector<Column>& cols) {
  Eigen::MatrixXd m(cols.empty() ? 0 : cols[0].size(), Eigen::Index(cols.size()));
  for (std::size_t i = 0; i < cols.size(); ++i) m.col(Eigen::Index(i)) = cols[i];
  return m;
}

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

std::pair<Column, Column> second_order(const Column& u, double f_hz, double zeta,
                                       const GapSignals& s) {
  const double w = 2.0 * M_PI * f_hz;
  const int sub = 8;
  const double h = s.cycle_s / sub;
  // One substep of (p, v) with the input x held: v' = (1 - 2ζωh) v - hω² p + hω² x, p' = p + h v'.
  // It is linear, so the 8 substeps of a cycle are one map s' = A s + B x, composed once here
  // (the same filter, 8x fewer operations per sample; it was a quarter of `imscal diagnose`).
  Eigen::Matrix2d step_A;
  step_A << 1.0 - h * h * w * w, h * (1.0 - 2.0 * zeta * w * h), -h * w * w,
      1.0 - 2.0 * zeta * w * h;
  const Eigen::Vector2d step_B(h * h * w * w, h * w * w);
  Eigen::Matrix2d A = Eigen::Matrix2d::Identity();
  Eigen::Vector2d B = Eigen::Vector2d::Zero();
  for (int i = 0; i < sub; ++i) {
    A = step_A * A;
    B = step_A * B + step_B;
  }
  Column y(u.size()), r(u.size());
  for (const auto& [b, e] : s.runs) {
    double p = e > b ? u[Eigen::Index(b)] : 0.0, v = 0.0;  // at rest in its first input
    for (std::size_t k = b; k < e; ++k) {
      const double x = u[Eigen::Index(k)];
      const double p_next = A(0, 0) * p + A(0, 1) * v + B[0] * x;
      v = A(1, 0) * p + A(1, 1) * v + B[1] * x;
      p = p_next;
      y[Eigen::Index(k)] = p;
      r[Eigen::Index(k)] = v / w;
    }
  }
  return {y, r};
}

namespace {

// The Laguerre filters of u over the run [b, e): filter i's value at sample k goes to out(i, k).
// Stages holds the stages' states: a std::array for the orders used (its elements stay in
// registers, the cascade's stages overlap), a std::vector for any other.
template <typename Stages, typename Out>
void laguerre_run(const Column& u, double a, double g0, std::size_t b, std::size_t e, Stages y,
                  Out& out) {
  const int order = int(y.size());
  const double u0 = u[Eigen::Index(b)];
  for (auto& yi : y) yi = g0 / (1.0 - a) * u0;
  Stages x_previous = y;  // each stage's previous input
  x_previous[0] = u0;
  for (std::size_t k = b; k < e; ++k) {
    double x = u[Eigen::Index(k)];
    for (int i = 0; i < order; ++i) {
      double& yi = y[std::size_t(i)];
      const double next = i == 0 ? a * yi + g0 * x : a * yi + x_previous[std::size_t(i)] - a * x;
      x_previous[std::size_t(i)] = x;
      yi = next;
      out(i, Eigen::Index(k)) = next;
      x = next;
    }
  }
}

// The Laguerre filters of u: filter i's value at sample k goes to out(i, k).
template <typename Out>
void laguerre_filters(const Column& u, double tau_s, int order, const GapSignals& s, Out&& out) {
  const double a = std::exp(-s.cycle_s / tau_s), g0 = std::sqrt(1.0 - a * a);
  for (const auto& [b, e] : s.runs) {
    if (e <= b) continue;
    switch (order) {
      case 3:
        laguerre_run(u, a, g0, b, e, std::array<double, 3>{}, out);
        break;
      case 4:
        laguerre_run(u, a, g0, b, e, std::array<double, 4>{}, out);
        break;
      case 6:
        laguerre_run(u, a, g0, b, e, std::array<double, 6>{}, out);
        break;
      default:
        laguerre_run(u, a, g0, b, e, std::vector<double>(std::size_t(order)), out);
    }
  }
}

}  // namespace

std::vector<Column> laguerre(const Column& u, double tau_s, int order, const GapSignals& s) {
  std::vector<Column> out(std::size_t(order), Column(u.size()));
  laguerre_filters(u, tau_s, order, s,
                   [&](int i, Eigen::Index k) -> double& { return out[std::size_t(i)][k]; });
  return out;
}

void laguerre_into(const Column& u, double tau_s, const GapSignals& s,
                   Eigen::Ref<Eigen::MatrixXd> out) {
  laguerre_filters(u, tau_s, int(out.cols()), s,
                   [&](int i, Eigen::Index k) -> double& { return out(k, i); });
}

Column relay(const Column& z, double h, const GapSignals& s) {
  Column r = Column::Zero(z.size());
  for (const auto& [b, e] : s.runs) {
    double state = 0.0;
    for (std::size_t k = b; k < e && state == 0.0; ++k) {
      const double v = z[Eigen::Index(k)];
      if (std::abs(v) > h) state = v > 0.0 ? 1.0 : -1.0;
    }
    if (state == 0.0)
      state = 1.0;  // never decided: one flank all along (which one: the fit's sign)
    for (std::size_t k = b; k < e; ++k) {
      const double v = z[Eigen::Index(k)];
      if (v > h) state = 1.0;
      if (v < -h) state = -1.0;
      r[Eigen::Index(k)] = state;
    }
  }
  return r;
}

Column run_derivative(const Column& x, const GapSignals& s) {
  Column d = Column::Zero(x.size());
  const double dt = s.cycle_s;
  for (const auto& [b, e] : s.runs) {
    if (e - b < 2) continue;
    const Eigen::Index bi = Eigen::Index(b), ei = Eigen::Index(e);
    d[bi] = (x[bi + 1] - x[bi]) / dt;
    d[ei - 1] = (x[ei - 1] - x[ei - 2]) / dt;
    for (Eigen::Index k = bi + 1; k + 1 < ei; ++k) d[k] = (x[k + 1] - x[k - 1]) / (2.0 * dt);
  }
  return d;
}

}  // namespace imscal::eval
