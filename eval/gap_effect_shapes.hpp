#pragma once
// What the effects' shape builders (eval/gap_effect_<name>.cpp) share: the joint's known signals
// and the two ways a shape places its columns (on its own joint, or the same parameters on every
// joint), the size-in-words forms several effects use.
#include <fmt/format.h>

#include <Eigen/Core>
#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "eval/gap_candidates.hpp"
#include "eval/gap_filters.hpp"

namespace imscal::eval {

// Velocity scale of the smooth sign of a velocity [rad/s]: 0.3 deg/s, well below any programmed
// speed.
inline constexpr double kSignVelocityScale = 0.005;

// The signals a candidate's shapes on `joint` are built from.
struct ShapeContext {
  ShapeContext(const GapSignals& signals, std::size_t joint, const std::vector<bool>* training);

  const GapSignals& s;
  std::size_t joint;
  // The rows a search inside the shapes (a transmission error's further orders) may use; null:
  // none.
  const std::vector<bool>* training;
  Eigen::Index n;  // samples
  std::size_t nj;  // joints
  Column qd, qdd;  // desired velocity and acceleration of the joint
  // The drive's actual motion (q_internal) where known, else the desired one: its velocity and
  // its torque.
  Column qd_actual, tau_actual;

  // A shape on this joint only.
  CandidateShape local(std::string label, const std::vector<Column>& cols,
                       std::vector<std::string> names) const;

  // A shape with the same parameters on every joint: column block `cols` of joint j's matrix
  // `matrix_of_joint(j)`.
  template <typename MatrixOfJoint>
  CandidateShape shared(std::string label, const MatrixOfJoint& matrix_of_joint,
                        const std::vector<int>& cols, std::vector<std::string> names) const {
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
  }
};

// "<stem>0_rad", "<stem>1_rad", ... (count names).
std::vector<std::string> numbered(const std::string& stem, int count);

// A nominal drive parameter of a joint, 0 when not known.
double nominal_of(const std::vector<double>& values, std::size_t joint);

// Sizes in words: the first parameter with its sigma; the same in seconds; every parameter with
// its sigma (the IMS chain's few geometric parameters).
std::string size_of_first_parameter(const CandidateFit& fit);
std::string size_in_seconds(const CandidateFit& fit, const CandidateShape& shape, double own_rms);
std::string size_of_every_parameter(const CandidateFit& fit, const CandidateShape& shape,
                                    double own_rms);

}  // namespace imscal::eval
