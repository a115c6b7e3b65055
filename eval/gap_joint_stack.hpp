#pragma once
// The rows of several joints stacked into one least-squares problem (one parameter vector for all
// joints, eval/gap_candidates.hpp fit_joint_columns): joint after joint, all samples each. The
// column-pivoted QR fits need the copy; the normal equations (eval/gap_normal_equations.hpp) sum
// each joint's Gram matrix instead.
#include <Eigen/Core>
#include <cstddef>
#include <vector>

namespace imscal::eval {

struct StackedJoints {
  Eigen::MatrixXd x;
  std::vector<double> y;
  std::vector<std::size_t> joints;  // in stacking order: those with columns
};
StackedJoints stack_joints(const std::vector<Eigen::MatrixXd>& columns,
                           const std::vector<std::vector<double>>& gap);

// The rows of `fold` (sample indices) on every one of `joints` stacked joints of `samples` rows.
std::vector<Eigen::Index> stacked_rows(const std::vector<Eigen::Index>& fold, std::size_t joints,
                                       Eigen::Index samples);

// The joints that have columns, ascending.
std::vector<std::size_t> joints_with_columns(const std::vector<Eigen::MatrixXd>& columns);

}  // namespace imscal::eval
