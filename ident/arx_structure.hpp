#pragma once
// Structure of the paper's per-joint ARX model (equation 2), sample time T (2 ms by default):
//
//   y(k) + a_1 y(k-1) + ... + a_na y(k-na) = b_0 u(k-d) + ... + b_{nb-1} u(k-d-nb+1)
//                                           + Σ_e [c_e,0 x_e(k-d) + ... + c_e,nx-1 x_e(k-d-nx+1)]
//                                           + e(k)
//
// with y = q̂ (the joint angle the robot reaches), u = q_d (the desired joint angle), d the dead
// time in samples and e(k) the equation error. na >= 0 (na = 0 is a FIR model), nb >= 1, d >= 0.
// The x_e are optional further inputs of the multi-input form (imscal's extension: the
// joint torque of the robot's rigid-body model and the direction of motion,
// ident/joint_identification.hpp), extra_inputs of them with nx coefficients each, lags from d
// as the main input's. extra_inputs = 0 is the paper's single-input model.
//
// References (docs/references.md): [Paper] (eq. 2), [Ljung1999] (ARX models).
#include <algorithm>
#include <array>
#include <span>
#include <stdexcept>
#include <string>

namespace imscal::ident {

inline constexpr int kMaxExtraInputs = 11;

struct ArxStructure {
  int na = 1;            // number of autoregressive coefficients a_1..a_na
  int nb = 1;            // number of input coefficients b_0..b_{nb-1}
  int dead_time = 0;     // d: delay of the first input coefficient, in samples
  int extra_inputs = 0;  // number of further inputs x_e (0..kMaxExtraInputs)
  // Coefficients of each further input, c_e,0..c_e,nx[e]-1 (>= 1 for e < extra_inputs, 0 for the
  // unused entries): a slowly varying input (the torque's sign) needs one, a dynamic one many.
  std::array<int, kMaxExtraInputs> nx{};

  // Coefficients of all further inputs, and where those of input e start in c.
  int extra_coefficient_count() const {
    int sum = 0;
    for (int e = 0; e < extra_inputs; ++e) sum += nx[std::size_t(e)];
    return sum;
  }
  int extra_offset(int e) const {
    int sum = 0;
    for (int i = 0; i < e; ++i) sum += nx[std::size_t(i)];
    return sum;
  }
  int max_nx() const {
    int m = 0;
    for (int e = 0; e < extra_inputs; ++e) m = std::max(m, nx[std::size_t(e)]);
    return m;
  }
  int parameter_count() const { return na + nb + extra_coefficient_count(); }
  // Largest lag of any regressor: the first sample k that has a complete regressor.
  int max_lag() const {
    return std::max({na, dead_time + nb - 1, extra_inputs > 0 ? dead_time + max_nx() - 1 : 0});
  }

  // Throws std::invalid_argument when a field is out of range.
  void validate() const {
    if (na < 0)
      throw std::invalid_argument("ArxStructure: na must be >= 0, got " + std::to_string(na));
    if (nb < 1)
      throw std::invalid_argument("ArxStructure: nb must be >= 1, got " + std::to_string(nb));
    if (dead_time < 0)
      throw std::invalid_argument("ArxStructure: dead_time must be >= 0, got " +
                                  std::to_string(dead_time));
    if (extra_inputs < 0 || extra_inputs > kMaxExtraInputs)
      throw std::invalid_argument("ArxStructure: extra_inputs must be in 0.." +
                                  std::to_string(kMaxExtraInputs) + ", got " +
                                  std::to_string(extra_inputs));
    for (int e = 0; e < kMaxExtraInputs; ++e) {
      const int n = nx[std::size_t(e)];
      if (e < extra_inputs ? n < 1 : n != 0) {
        std::string what = "ArxStructure: nx of further input " + std::to_string(e);
        what += e < extra_inputs ? " must be >= 1, got " : " must be 0 (unused), got ";
        what += std::to_string(n);
        throw std::invalid_argument(what);
      }
    }
  }

  friend bool operator==(const ArxStructure&, const ArxStructure&) = default;
};

// One contiguous recording (one run) of the desired joint angle u = q_d and the reached joint
// angle y = q̂ of one joint, sampled every T. Several segments are separate runs: no regressor
// ever reaches across a segment boundary. The spans are views; the caller owns the samples.
struct IoSegment {
  std::span<const double> input;   // u(k) = q_d(k) [rad]
  std::span<const double> output;  // y(k) = q̂(k) [rad]
  // The further inputs x_e(k) of the multi-input form, each of the output's length; the first
  // extra_count are used (the structure's extra_inputs must match).
  std::array<std::span<const double>, kMaxExtraInputs> extra{};
  int extra_count = 0;

  // The same rows [first, first + count) of every signal.
  IoSegment subspan(std::size_t first, std::size_t count = std::dynamic_extent) const {
    IoSegment out{input.subspan(first, count), output.subspan(first, count), {}, extra_count};
    for (int e = 0; e < extra_count; ++e)
      out.extra[std::size_t(e)] = extra[std::size_t(e)].subspan(first, count);
    return out;
  }
};

inline std::string to_string(const ArxStructure& s) {
  std::string text = "na=" + std::to_string(s.na) + " nb=" + std::to_string(s.nb) +
                     " d=" + std::to_string(s.dead_time);
  if (s.extra_inputs > 0) {
    text += " nx=";
    for (int e = 0; e < s.extra_inputs; ++e) {
      if (e > 0) text += ',';
      text += std::to_string(s.nx[std::size_t(e)]);
    }
  }
  return text;
}

}  // namespace imscal::ident
