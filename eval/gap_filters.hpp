#pragma once
// The filters the candidate effects of the gap diagnosis are built from (eval/gap_candidates.hpp,
// eval/gap_coupling.hpp): causal filters of a known signal over the whole record, restarted at
// every run of GapSignals::runs (no filter reaches across a time gap), each run starting in the
// steady state of its first input.
#include <Eigen/Core>
#include <utility>
#include <vector>

#include "eval/gap_signals.hpp"

namespace imscal::eval {

using Column = Eigen::VectorXd;

Column to_column(const std::vector<double>& v);
double rms_of(const Column& c);
// The columns side by side (samples x count).
Eigen::MatrixXd matrix_of(const std::vector<Column>& cols);

// First-order lag y' = (u - y) / tau, exact discretisation.
Column lag(const Column& u, double tau_s, const GapSignals& s);

// Lightly damped second-order response ω²/(s² + 2ζωs + ω²) to u held over each cycle
// (semi-implicit Euler with 8 substeps per cycle, composed into one map per cycle: stable and
// accurate to < 1 % up to 40 Hz at 2 ms), and its rate / ω.
std::pair<Column, Column> second_order(const Column& u, double f_hz, double zeta,
                                       const GapSignals& s);

// Discrete Laguerre filters of u with time scale tau (pole a = exp(-T / tau)):
// L_0 = sqrt(1 - a²) / (1 - a z^-1), L_i = L_{i-1} (z^-1 - a) / (1 - a z^-1): an orthonormal
// basis of stable linear responses, so a few columns follow a closed loop's reaction to u without
// knowing its poles.
std::vector<Column> laguerre(const Column& u, double tau_s, int order, const GapSignals& s);

// The first out.cols() Laguerre filters of u with time scale tau, written into out's columns
// (samples x order), bit for bit those of `laguerre`: a lower order's filters are the first ones
// of a higher order's (the stages are a cascade), so shapes that take several orders of one time
// scale share one call at the highest.
void laguerre_into(const Column& u, double tau_s, const GapSignals& s,
                   Eigen::Ref<Eigen::MatrixXd> out);

// Relay with memory: +1 once z > h, -1 once z < -h, the last value while |z| <= h (the link of a
// gear with play stays on the flank it was pushed to until the torque really reverses: the
// friction at the link holds it). Before the first decision of a run, that decision (the flank
// the link starts on is not known; the first push says which it was on, or goes to).
Column relay(const Column& z, double h, const GapSignals& s);

// Central differences within each run, one-sided at its ends [unit of x per s].
Column run_derivative(const Column& x, const GapSignals& s);

}  // namespace imscal::eval
