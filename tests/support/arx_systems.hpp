#pragma once
// Known ARX systems and their simulated data, shared by the ident tests: the truth that
// identification results are checked against.
#include <Eigen/Core>
#include <complex>
#include <cstddef>
#include <random>
#include <utility>
#include <vector>

#include "ident/arx_model.hpp"
#include "ident/arx_structure.hpp"

namespace imscal::test_support {

// Monic polynomial coefficients a_1..a_n of Π (z - p_i) for conjugate-closed poles.
inline Eigen::VectorXd polynomial_from_poles(const std::vector<std::complex<double>>& poles) {
  std::vector<std::complex<double>> c{1.0};
  for (const auto& p : poles) {
    c.push_back(0.0);
    for (std::size_t i = c.size() - 1; i > 0; --i) c[i] -= p * c[i - 1];
  }
  Eigen::VectorXd a(static_cast<Eigen::Index>(poles.size()));
  for (std::size_t i = 1; i < c.size(); ++i) a(static_cast<Eigen::Index>(i - 1)) = c[i].real();
  return a;
}

// Random stable poles: conjugate pairs (and one real pole for odd na), modulus in [0.3, 0.9].
inline std::vector<std::complex<double>> random_poles(int na, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> modulus(0.3, 0.9), angle(0.1, 3.0), sign(-1.0, 1.0);
  std::vector<std::complex<double>> poles;
  // Every draw in its own statement: the evaluation order of function arguments and operands is
  // unspecified, and GCC and clang differ (the same seed gave other systems under clang). The
  // order is GCC's, with which the tests' figures were measured: angle, then modulus.
  for (int i = 0; i + 1 < na; i += 2) {
    const double theta = angle(rng);
    const double r = modulus(rng);
    const auto p = std::polar(r, theta);
    poles.push_back(p);
    poles.push_back(std::conj(p));
  }
  if (na % 2 == 1) {
    const double r = modulus(rng);
    const double s = sign(rng) < 0 ? -1.0 : 1.0;
    poles.emplace_back(r * s, 0.0);
  }
  return poles;
}

// Input coefficients of magnitude [0.5, 1.5] and random sign.
inline Eigen::VectorXd random_b(int nb, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> magnitude(0.5, 1.5), sign(-1.0, 1.0);
  Eigen::VectorXd b(nb);
  for (int j = 0; j < nb; ++j) {  // one draw per statement (see random_poles)
    const double m = magnitude(rng);
    b(j) = sign(rng) < 0 ? -m : m;
  }
  return b;
}

// A random stable system of the given structure (poles first, then b, from the same stream).
inline ident::ArxModel random_system(const ident::ArxStructure& s, std::mt19937_64& rng) {
  const Eigen::VectorXd a = polynomial_from_poles(random_poles(s.na, rng));
  return ident::ArxModel(s, a, random_b(s.nb, rng));
}

struct ArxRecord {
  std::vector<double> u, y, e;
};

// y(k) = -Σ a_i y(k-i) + Σ b_j u(k-d-j) + e(k) for the given input u and equation noise e
// (same length); samples before k = 0 are taken as y_before and u_before (non-zero values let
// two runs start from different states).
inline ArxRecord simulate_arx(const ident::ArxModel& m, std::vector<double> u,
                              std::vector<double> e, double y_before = 0.0, double u_before = 0.0) {
  ArxRecord r;
  r.u = std::move(u);
  r.e = std::move(e);
  const std::size_t n = r.u.size();
  r.y.resize(n);
  const auto& s = m.structure();
  for (std::size_t k = 0; k < n; ++k) {
    double sum = r.e[k];
    for (int i = 1; i <= s.na; ++i) {
      sum -= m.a()(i - 1) * (k >= std::size_t(i) ? r.y[k - i] : y_before);
    }
    for (int j = 0; j < s.nb; ++j) {
      const long idx = long(k) - s.dead_time - j;
      sum += m.b()(j) * (idx >= 0 ? r.u[std::size_t(idx)] : u_before);
    }
    r.y[k] = sum;
  }
  return r;
}

inline ident::IoSegment view(const ArxRecord& r) {
  return {r.u, r.y};
}

// y(k) = -Σ a_i y(k-i) + Σ b_j u(k-d-j) + Σ_e Σ_{j<nx[e]} c_e,j x_e(k-d-j) + noise, white inputs,
// zero before k = 0. Computed here, independently of ArxModel::simulate.
struct MultiRecord {
  std::vector<double> u, y;
  std::vector<std::vector<double>> x;
  ident::IoSegment view() const {
    ident::IoSegment s{u, y};
    s.extra_count = int(x.size());
    for (std::size_t e = 0; e < x.size(); ++e) s.extra[e] = x[e];
    return s;
  }
};

inline MultiRecord simulate_multi(const ident::ArxModel& m, std::size_t n, double noise_std,
                                  std::mt19937_64& rng) {
  const ident::ArxStructure& s = m.structure();
  std::normal_distribution<double> normal(0.0, 1.0);
  MultiRecord r;
  r.u.resize(n);
  r.y.resize(n);
  r.x.assign(std::size_t(s.extra_inputs), std::vector<double>(n));
  for (auto& v : r.u) v = normal(rng);
  for (auto& x : r.x)
    for (auto& v : x) v = 100.0 * normal(rng);  // a torque-like scale: 100 N m against 1 rad
  for (std::size_t k = 0; k < n; ++k) {
    double sum = noise_std * normal(rng);
    for (int i = 1; i <= s.na; ++i)
      if (k >= std::size_t(i)) sum -= m.a()(i - 1) * r.y[k - std::size_t(i)];
    for (int j = 0; j < s.nb; ++j) {
      const long idx = long(k) - s.dead_time - j;
      if (idx >= 0) sum += m.b()(j) * r.u[std::size_t(idx)];
    }
    for (int e = 0; e < s.extra_inputs; ++e)
      for (int j = 0; j < s.nx[std::size_t(e)]; ++j) {
        const long idx = long(k) - s.dead_time - j;
        if (idx >= 0) sum += m.c()(s.extra_offset(e) + j) * r.x[std::size_t(e)][std::size_t(idx)];
      }
    r.y[k] = sum;
  }
  return r;
}

inline ident::ArxModel random_multi_system(const ident::ArxStructure& s, std::mt19937_64& rng) {
  Eigen::VectorXd c = 1e-3 * random_b(s.extra_coefficient_count(), rng);
  return ident::ArxModel(s, polynomial_from_poles(random_poles(s.na, rng)), random_b(s.nb, rng), c,
                         0.002);
}

}  // namespace imscal::test_support
