#pragma once
// A joint record made backwards from known paths, for the transmission-error tests: the motor
// angle θ follows the command u with a one-cycle first-order lag, θ(k+1) = α θ(k) + (1 - α) u(k),
// so the command that gives a chosen θ exactly is u(k) = (θ(k+1) - α θ(k)) / (1 - α). The record
// is then the plant's without simulation error; the tests choose θ (the link angle q, the gear's
// deflection and the angle errors under test) and check the identification against it.
#include <cstddef>
#include <utility>
#include <vector>

#include "ident/joint_identification.hpp"

namespace imscal::test_support {

struct LaggedMotorRecord {
  std::vector<double> q_desired, q_link, torque_nm, payload;
  std::vector<std::pair<std::size_t, std::size_t>> segments;
};

// The record of n = q.size() - 1 cycles from θ, q and τ [N m] at k = 0..n (one more sample than
// rows: u(k) needs θ(k+1)); one segment, a constant 5 kg payload.
inline LaggedMotorRecord record_from_motor_angle(const std::vector<double>& theta_rad,
                                                 const std::vector<double>& q_rad,
                                                 const std::vector<double>& torque_nm,
                                                 double alpha) {
  const std::size_t n = q_rad.size() - 1;
  LaggedMotorRecord r;
  for (std::size_t k = 0; k < n; ++k) {
    r.q_desired.push_back((theta_rad[k + 1] - alpha * theta_rad[k]) / (1.0 - alpha));
    r.q_link.push_back(q_rad[k]);
    r.torque_nm.push_back(torque_nm[k]);
    r.payload.push_back(5.0);
  }
  r.segments = {{0, n}};
  return r;
}

// Joint A2 identified from the record in one cell that holds every row (speeds 0..5 rad/s).
inline ident::JointIdentification identify_in_one_cell(const LaggedMotorRecord& r, double dt_s,
                                                       const ident::JointIdentificationOptions& o) {
  const ident::CellGrid one_cell({{ident::OperatingQuantity::kSpeed, {0.0, 5.0}}});
  return ident::identify_joint("A2", r.q_desired, r.q_link, r.payload, r.segments, dt_s, one_cell,
                               o, r.torque_nm);
}

}  // namespace imscal::test_support
