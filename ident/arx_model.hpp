#pragma once
// An identified ARX model of one joint (paper, equation 2; structure in ident/arx_structure.hpp):
//
//   q̂(k) = -a_1 q̂(k-1) - ... - a_na q̂(k-na) + b_0 q_d(k-d) + ... + b_{nb-1} q_d(k-d-nb+1)
//   Δq̂(k) = q_d(k-d) - q̂(k)
//
// The model predicts one step ahead from measured outputs, or runs free ("simulation") from the
// desired angles alone, which is what the precontrol does online. Stability is judged from the
// poles, the eigenvalues of the companion matrix of A(z) = z^na + a_1 z^(na-1) + ... + a_na.
#include <Eigen/Core>
#include <span>

#include "ident/arx_structure.hpp"

namespace imscal::ident {

class ArxModel {
 public:
  // a: a_1..a_na, b: b_0..b_{nb-1}; sizes must match the structure (std::invalid_argument).
  // A structure with further inputs needs the constructor with c.
  ArxModel(ArxStructure structure, Eigen::VectorXd a, Eigen::VectorXd b,
           double sample_time_s = 0.002);
  // c: the further inputs' coefficients, input after input (c_e,0..c_e,nx[e]-1 for e = 0, 1, ...).
  ArxModel(ArxStructure structure, Eigen::VectorXd a, Eigen::VectorXd b, Eigen::VectorXd c,
           double sample_time_s);

  const ArxStructure& structure() const { return structure_; }
  const Eigen::VectorXd& a() const { return a_; }
  const Eigen::VectorXd& b() const { return b_; }
  const Eigen::VectorXd& c() const { return c_; }  // empty without further inputs
  double sample_time_s() const { return sample_time_s_; }
  // θ = [a_1..a_na, b_0..b_{nb-1}, c], the order used by fits and covariances.
  Eigen::VectorXd parameters() const;

  // One-step-ahead prediction ŷ(k) from measured y(k-1..k-na), u and the further inputs.
  // Writes predicted[k] for k >= max_lag; earlier entries (no complete regressor) get the
  // measured y(k). predicted.size() must equal the segment length.
  void predict_one_step(const IoSegment& segment, std::span<double> predicted) const;

  // Free-run simulation from the inputs only: the first max_lag outputs are taken from
  // initial_output (measured), later ones from the model's own past outputs.
  // initial_output.size() >= max_lag, simulated.size() == input.size(). Single-input models only
  // (std::invalid_argument otherwise); the IoSegment form serves both.
  void simulate(std::span<const double> input, std::span<const double> initial_output,
                std::span<double> simulated) const;
  // The same with the segment's inputs (and further inputs); the segment's output gives the
  // initial values (only its first max_lag samples are read; it may be that short).
  void simulate(const IoSegment& segment, std::span<double> simulated) const;

  // Joint angle error predicted by free-run simulation: Δq̂(k) = q_d(k-d) - q̂(k) for
  // k >= max_lag, 0 before. Same size rules as simulate().
  void predict_joint_error(std::span<const double> input, std::span<const double> initial_output,
                           std::span<double> joint_error) const;

  // Roots of A(z) (na of them; empty for a FIR model).
  Eigen::VectorXcd poles() const;
  // Largest pole magnitude (0 for a FIR model).
  double spectral_radius() const;
  // Asymptotically stable with the given margin: every |pole| < 1 - margin.
  bool is_stable(double margin = 0.0) const { return spectral_radius() < 1.0 - margin; }
  // Steady-state gain B(1)/A(1) (infinite when A(1) = 0).
  double static_gain() const;
  // Steady-state gain of further input e, C_e(1)/A(1).
  double extra_static_gain(int e) const;

 private:
  ArxStructure structure_;
  Eigen::VectorXd a_;
  Eigen::VectorXd b_;
  Eigen::VectorXd c_;
  double sample_time_s_;
};

}  // namespace imscal::ident
