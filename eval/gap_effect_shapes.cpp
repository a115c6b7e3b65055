#include "eval/gap_effect_shapes.hpp"

#include <fmt/format.h>

namespace imscal::eval {
namespace {

bool actual_motion_known(const GapSignals& s, std::size_t joint) {
  return joint < s.qd_internal_rad_s.size() && joint < s.torque_internal_nm.size() &&
         rms_of(to_column(s.qd_internal_rad_s[joint])) > 0.0;
}

}  // namespace

ShapeContext::ShapeContext(const GapSignals& signals, std::size_t joint_index,
                           const std::vector<bool>* training_rows)
    : s(signals),
      joint(joint_index),
      training(training_rows),
      n(Eigen::Index(signals.sample_count())),
      nj(signals.joint_count()),
      qd(to_column(signals.qd_desired_rad_s[joint_index])),
      qdd(to_column(signals.qdd_desired_rad_s2[joint_index])) {
  const bool actual = actual_motion_known(s, joint);
  qd_actual = actual ? to_column(s.qd_internal_rad_s[joint]) : qd;
  tau_actual = actual ? to_column(s.torque_internal_nm[joint]) : to_column(s.torque_nm[joint]);
}

CandidateShape ShapeContext::local(std::string label, const std::vector<Column>& cols,
                                   std::vector<std::string> names) const {
  CandidateShape sh;
  sh.label = std::move(label);
  sh.columns.assign(nj, Eigen::MatrixXd());
  sh.columns[joint] = matrix_of(cols);
  sh.parameter_names = std::move(names);
  return sh;
}

std::vector<std::string> numbered(const std::string& stem, int count) {
  std::vector<std::string> names;
  for (int i = 0; i < count; ++i) names.push_back(fmt::format("{}{}_rad", stem, i));
  return names;
}

double nominal_of(const std::vector<double>& values, std::size_t joint) {
  return joint < values.size() ? values[joint] : 0.0;
}

std::string size_of_first_parameter(const CandidateFit& c) {
  return fmt::format("{} = {:.4g} ± {:.2g}", c.parameter_names[0], c.parameters[0], c.sigma[0]);
}

std::string size_in_seconds(const CandidateFit& c, const CandidateShape&, double) {
  return size_of_first_parameter(c) + " s";
}

std::string size_of_every_parameter(const CandidateFit& c, const CandidateShape&, double) {
  std::vector<std::string> all;
  for (Eigen::Index i = 0; i < c.parameters.size(); ++i)
    all.push_back(fmt::format("{} = {:.3g} ± {:.2g}", c.parameter_names[std::size_t(i)],
                              c.parameters[i], c.sigma[i]));
  return fmt::format("{}", fmt::join(all, ", "));
}

}  // namespace imscal::eval
