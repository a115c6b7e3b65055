#include "eval/gap_coupling.hpp"

#include <fmt/format.h>

#include <utility>

#include "eval/gap_filters.hpp"

namespace imscal::eval {
namespace {

struct Basis {
  std::string label;
  std::vector<std::pair<double, int>> laguerres;  // (time scale [s], order)
};

const std::vector<Basis>& bases() {
  static const std::vector<Basis> b = {{"Laguerre 10 ms x4", {{0.01, 4}}},
                                       {"Laguerre 30 ms x6", {{0.03, 6}}},
                                       {"Laguerre 3 ms x4 + 30 ms x4", {{0.003, 4}, {0.03, 4}}},
                                       {"Laguerre 10 ms x4 + 100 ms x4", {{0.01, 4}, {0.1, 4}}}};
  return b;
}

// Every time scale and order the bases take.
std::vector<std::pair<double, int>> basis_scales() {
  std::vector<std::pair<double, int>> scales;
  for (const Basis& basis : bases())
    scales.insert(scales.end(), basis.laguerres.begin(), basis.laguerres.end());
  return scales;
}

// A basis's columns side by side (samples x its parameters).
Eigen::MatrixXd basis_matrix(const Basis& basis, const LaguerreBank& filtered) {
  Eigen::Index width = 0;
  for (const auto& [tl, order] : basis.laguerres) width += order;
  Eigen::MatrixXd m(filtered.first(basis.laguerres.front().first, 1).rows(), width);
  Eigen::Index c = 0;
  for (const auto& [tl, order] : basis.laguerres) {
    m.middleCols(c, order) = filtered.first(tl, order);
    c += order;
  }
  return m;
}

}  // namespace

CouplingColumns coupling_columns(const GapSignals& s,
                                 const std::vector<std::vector<double>>& prediction,
                                 const std::vector<std::vector<double>>& residual,
                                 const TrainingFolds& folds) {
  CouplingColumns out;
  const std::size_t nj = s.joint_count();
  const Eigen::Index n = Eigen::Index(s.sample_count());
  if (s.mass_matrix_kg_m2.size() != nj * nj || !folds.usable()) return out;
  // The modelled link accelerations of the candidate's joints [rad/s²].
  std::vector<Column> acceleration(nj);
  for (std::size_t j = 0; j < nj; ++j)
    if (j < prediction.size() && !prediction[j].empty())
      acceleration[j] = run_derivative(run_derivative(to_column(prediction[j]), s), s);
  struct Reach {
    std::size_t joint;
    Eigen::MatrixXd columns;
    std::string shape;
    std::vector<std::string> names;
  };
  std::vector<Reach> reached;
  for (std::size_t i = 0; i < nj; ++i) {
    Column u = Column::Zero(n);
    for (std::size_t j = 0; j < nj; ++j)
      if (j != i && acceleration[j].size() == n)
        u += Eigen::Map<const Column>(s.mass_matrix_kg_m2[i * nj + j].data(), n)
                 .cwiseProduct(acceleration[j]);
    if (rms_of(u) == 0.0) continue;
    double none = 0.0;  // the validation error without coupling: the residual itself
    for (const auto& fold : folds.folds)
      for (Eigen::Index k : fold) none += residual[i][std::size_t(k)] * residual[i][std::size_t(k)];
    double best = none * (1.0 - kCouplingMinGain);
    Reach chosen{i, {}, {}, {}};
    const LaguerreBank filtered(u, basis_scales(), s);
    for (const Basis& basis : bases()) {
      std::vector<std::string> names;
      for (const auto& [tl, order] : basis.laguerres)
        for (int o = 0; o < order; ++o)
          names.push_back(fmt::format("{}_coupling_laguerre{:.0f}ms_{}_rad_per_nm",
                                      s.joint_names[i], 1000.0 * tl, o));
      const Eigen::MatrixXd m = basis_matrix(basis, filtered);
      const double sse = cross_validation_sse(m, residual[i], folds);
      if (sse < best) {
        best = sse;
        chosen = {i, m, basis.label, names};
      }
    }
    if (chosen.columns.size() > 0) reached.push_back(std::move(chosen));
  }
  if (reached.empty()) return out;
  Eigen::Index width = 0;
  for (const auto& r : reached) width += r.columns.cols();
  out.columns.assign(nj, Eigen::MatrixXd());
  Eigen::Index offset = 0;
  for (auto& r : reached) {
    out.columns[r.joint] = Eigen::MatrixXd::Zero(n, width);
    out.columns[r.joint].middleCols(offset, r.columns.cols()) = r.columns;
    offset += r.columns.cols();
    out.joints.push_back(r.joint);
    out.shapes.push_back(std::move(r.shape));
    for (auto& nm : r.names) out.parameter_names.push_back(std::move(nm));
  }
  return out;
}

}  // namespace imscal::eval
