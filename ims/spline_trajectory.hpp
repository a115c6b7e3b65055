#pragma once
// A Trajectory through densely sampled poses (t, p_W, q_W_S), e.g. a simulator's output at 1 kHz,
// interpolated so that IMS signals can be synthesised from it.
//
// Position: piecewise quintic Hermite between samples; velocity and acceleration at each sample
// from the 7-point finite-difference stencil (Fornberg weights, arbitrary spacing; shifted to one
// side at the ends), so p, v and a are continuous (C^2) and exact for polynomials up to degree 6.
// Attitude: on the interval [t_i, t_i+1], q_W_S(t) = q_i exp(phi(t)) with phi a quintic Hermite
// curve through phi(t_i) = 0 and phi(t_i+1) = log(q_i^-1 q_i+1), whose end derivatives carry the
// body rate omega and its derivative at the samples (estimated like v and a in the chart of
// each sample, where d phi/dt = omega and d2 phi/dt2 = d omega/dt), mapped through the inverse
// right Jacobian at the far end. So omega_WS_S is continuous with a continuous derivative.
//
// Accuracy (samples of a smooth motion, spacing h): errors of O(h^6) in p and attitude,
// O(h^5..h^6) in v and omega, O(h^4..h^5) in a; rounding of the samples is amplified ~ 1/h in v,
// omega and ~ 1/h^2 in a (positions rounded to 1e-16 m at 1 kHz: ~1e-10 m/s^2).
// At the samples the third derivatives jump slightly; the synthesiser splits its quadrature there
// (PiecewiseSmooth), so IMS sample times need not coincide with pose sample times.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <vector>

#include "ims/imu_synthesis.hpp"
#include "ims/trajectory.hpp"

namespace imscal::ims {

struct PoseSample {
  double t_s = 0.0;
  Eigen::Vector3d p_W = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_W_S = Eigen::Quaterniond::Identity();
};

class SplineTrajectory final : public Trajectory, public PiecewiseSmooth {
 public:
  // Needs >= 7 samples with strictly increasing, finite times and consecutive attitudes less
  // than 0.2 rad apart (sample faster otherwise); throws std::invalid_argument.
  explicit SplineTrajectory(const std::vector<PoseSample>& samples);

  double begin_s() const override { return times_.front(); }
  double end_s() const override { return times_.back(); }
  // Outside [begin_s, end_s] the first or last interval's polynomial is extrapolated.
  KinematicState at(double t_s) const override;
  // The sample times (knots): the third derivatives jump there.
  const std::vector<double>& joints_s() const override { return times_; }

 private:
  using Quintic = std::array<Eigen::Vector3d, 6>;  // coefficients of u^0 .. u^5, u in [0, 1]
  std::vector<double> times_;
  std::vector<Eigen::Quaterniond> attitudes_;
  std::vector<Quintic> position_;  // per interval
  std::vector<Quintic> rotation_;  // phi per interval, in the chart of its first sample
};

}  // namespace imscal::ims
