#pragma once
// How one joint's effect spreads over the other joints through the arm's coupled dynamics (gap
// diagnosis). An effect that moves joint j's link (its modelled gap y_j, e.g. the link
// crossing its gear's play, or following a transmission error) accelerates it, and that
// acceleration asks torque of every other joint through the mass matrix: tau_i = M_ij(q_d) ÿ_j.
// Joint i's gear and loop deflect under that torque with their own, unknown, dynamics. So each
// other joint's gap is modelled as a linear response to
//
//   u_i = sum over the candidate's joints j != i of M_ij(q_d) ÿ_j     [N m]
//
// through a Laguerre basis (10 ms x4, 30 ms x6, 3 + 30 ms x4 or 10 + 100 ms x4; the joint's
// gear mode rings fast, its loop settles slowly) with its own parameters
// per joint (rad per N m). The predicted y_j are the candidate's own fit (two stages: the
// coupling columns are then fixed, known signals). Which joints it reaches is chosen by the 2-fold
// validation inside the training rows (eval/gap_validation.hpp): a joint is kept when its basis
// lowers that joint's validation error by at least kCouplingMinGain.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "eval/gap_signals.hpp"
#include "eval/gap_validation.hpp"

namespace imscal::eval {

// Fraction of a joint's validation error (after the candidate's own columns) its coupling columns
// must remove to be kept: small effects must not spread over joints whose gap is only noise.
inline constexpr double kCouplingMinGain = 0.05;

struct CouplingColumns {
  std::vector<Eigen::MatrixXd> columns;  // [joint]: samples x parameters (all the same width, zero
                                         // blocks for the other joints' parameters), or empty
  std::vector<std::string> parameter_names;
  std::vector<std::size_t> joints;  // the joints reached, ascending
  std::vector<std::string> shapes;  // the basis chosen per joint reached
};

// The coupling of a candidate whose modelled gap is `prediction` ([joint], empty where it does not
// act); `residual` is the gap left by the candidate's own columns ([joint], the gap itself where it
// does not act). Empty (no joints) when the signals have no mass matrix or no joint gains.
CouplingColumns coupling_columns(const GapSignals& signals,
                                 const std::vector<std::vector<double>>& prediction,
                                 const std::vector<std::vector<double>>& residual,
                                 const TrainingFolds& folds);

}  // namespace imscal::eval
