#pragma once
// Structure of the paper's per-joint ARX model (equation 2), sample time T (2 ms by default):
//
//   y(k) + a_1 y(k-1) + ... + a_na y(k-na) = b_0 u(k-d) + ... + b_{nb-1} u(k-d-nb+1) + e(k)
//
// with y = q̂ (the joint angle the robot reaches), u = q_d (the desired joint angle), d the dead
// time in samples and e(k) the equation error. na >= 0 (na = 0 is a FIR model), nb >= 1, d >= 0.
#include <algorithm>
#include <span>
#include <stdexcept>
#include <string>

namespace imscal::ident {

struct ArxStructure {
  int na = 1;         // number of autoregressive coefficients a_1..a_na
  int nb = 1;         // number of input coefficients b_0..b_{nb-1}
  int dead_time = 0;  // d: delay of the first input coefficient, in samples

  int parameter_count() const { return na + nb; }
  // Largest lag of any regressor: the first sample k that has a complete regressor.
  int max_lag() const { return std::max(na, dead_time + nb - 1); }

  // Throws std::invalid_argument when a field is out of range.
  void validate() const {
    if (na < 0)
      throw std::invalid_argument("ArxStructure: na must be >= 0, got " + std::to_string(na));
    if (nb < 1)
      throw std::invalid_argument("ArxStructure: nb must be >= 1, got " + std::to_string(nb));
    if (dead_time < 0)
      throw std::invalid_argument("ArxStructure: dead_time must be >= 0, got " +
                                  std::to_string(dead_time));
  }

  friend bool operator==(const ArxStructure&, const ArxStructure&) = default;
};

// One contiguous recording (one run) of the desired joint angle u = q_d and the reached joint
// angle y = q̂ of one joint, sampled every T. Several segments are separate runs: no regressor
// ever reaches across a segment boundary. The spans are views; the caller owns the samples.
struct IoSegment {
  std::span<const double> input;   // u(k) = q_d(k) [rad]
  std::span<const double> output;  // y(k) = q̂(k) [rad]
};

inline std::string to_string(const ArxStructure& s) {
  return "na=" + std::to_string(s.na) + " nb=" + std::to_string(s.nb) +
         " d=" + std::to_string(s.dead_time);
}

}  // namespace imscal::ident
