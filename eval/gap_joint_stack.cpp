#include "eval/gap_joint_stack.hpp"

namespace imscal::eval {

std::vector<std::size_t> joints_with_columns(const std::vector<Eigen::MatrixXd>& columns) {
  std::vector<std::size_t> joints;
  for (std::size_t j = 0; j < columns.size(); ++j)
    if (columns[j].size() > 0) joints.push_back(j);
  return joints;
}

StackedJoints stack_joints(const std::vector<Eigen::MatrixXd>& columns,
                           const std::vector<std::vector<double>>& gap) {
  StackedJoints st;
  st.joints = joints_with_columns(columns);
  const Eigen::Index p = st.joints.empty() ? 0 : columns[st.joints.back()].cols();
  const Eigen::Index n = st.joints.empty() ? 0 : columns[st.joints.back()].rows();
  st.x.resize(n * Eigen::Index(st.joints.size()), p);
  st.y.reserve(std::size_t(st.x.rows()));
  for (std::size_t i = 0; i < st.joints.size(); ++i) {
    st.x.middleRows(Eigen::Index(i) * n, n) = columns[st.joints[i]];
    st.y.insert(st.y.end(), gap[st.joints[i]].begin(), gap[st.joints[i]].end());
  }
  return st;
}

std::vector<Eigen::Index> stacked_rows(const std::vector<Eigen::Index>& fold, std::size_t joints,
                                       Eigen::Index samples) {
  std::vector<Eigen::Index> rows;
  rows.reserve(fold.size() * joints);
  for (std::size_t i = 0; i < joints; ++i)
    for (Eigen::Index k : fold) rows.push_back(Eigen::Index(i) * samples + k);
  return rows;
}

}  // namespace imscal::eval
