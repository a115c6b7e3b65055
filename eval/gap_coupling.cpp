#include "eval/gap_coupling.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <utility>

#include "eval/gap_filters.hpp"
#include "eval/gap_shape_pool.hpp"

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

// The pool of one reached joint (eval/gap_shape_pool.hpp): u through each time scale once, at the
// highest order the bases take of it, and the bases as its column subsets.
struct BasisPool {
  ShapePool pool;
  std::vector<std::string> shapes;  // the bases' labels
};

BasisPool basis_pool(const Column& u, std::size_t joint, const GapSignals& s) {
  std::vector<std::pair<double, int>> highest;  // (time scale, highest order), first taken first
  for (const Basis& basis : bases())
    for (const auto& [tl, order] : basis.laguerres) {
      const auto same = [tl = tl](const auto& h) { return h.first == tl; };
      const auto it = std::find_if(highest.begin(), highest.end(), same);
      if (it == highest.end())
        highest.emplace_back(tl, order);
      else
        it->second = std::max(it->second, order);
    }
  std::vector<Eigen::Index> first;  // of each time scale in the pool
  Eigen::Index width = 0;
  for (const auto& [tl, order] : highest) first.push_back(width), width += order;
  BasisPool out;
  out.pool.columns.assign(s.joint_count(), Eigen::MatrixXd());
  Eigen::MatrixXd& m = out.pool.columns[joint];
  m.resize(u.size(), width);
  for (std::size_t i = 0; i < highest.size(); ++i)
    laguerre_into(u, highest[i].first, s, m.middleCols(first[i], highest[i].second));
  for (const Basis& basis : bases()) {
    PooledShape shape;
    shape.pool_columns.assign(s.joint_count(), {});
    shape.first_parameter.assign(s.joint_count(), 0);
    for (const auto& [tl, order] : basis.laguerres) {
      const auto same = [tl = tl](const auto& h) { return h.first == tl; };
      const Eigen::Index f =
          first[std::size_t(std::find_if(highest.begin(), highest.end(), same) - highest.begin())];
      for (int o = 0; o < order; ++o) {
        shape.pool_columns[joint].push_back(f + o);
        shape.parameter_names.push_back(fmt::format("{}_coupling_laguerre{:.0f}ms_{}_rad_per_nm",
                                                    s.joint_names[joint], 1000.0 * tl, o));
      }
    }
    out.pool.shapes.push_back(std::move(shape));
    out.shapes.push_back(basis.label);
  }
  return out;
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
    const BasisPool pool = basis_pool(u, i, s);
    const std::vector<double> sse = pooled_cross_validation_sse(pool.pool, residual, folds);
    for (std::size_t b = 0; b < sse.size(); ++b)
      if (sse[b] < best) {
        best = sse[b];
        CandidateShape shape = shape_from_pool(pool.pool, b);
        chosen = {i, std::move(shape.columns[i]), pool.shapes[b], std::move(shape.parameter_names)};
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
