#include "eval/gap_shape_pool.hpp"

#include <algorithm>
#include <utility>

#include "eval/gap_fold_fit.hpp"
#include "eval/gap_normal_equations.hpp"

namespace imscal::eval {
namespace {

Eigen::Index width_of(const PooledShape& shape) {
  return Eigen::Index(shape.parameter_names.size());
}

// The pool columns of `shape` on `joint` (empty where it does not act).
const std::vector<Eigen::Index>& columns_on(const PooledShape& shape, std::size_t joint) {
  static const std::vector<Eigen::Index> none;
  return joint < shape.pool_columns.size() ? shape.pool_columns[joint] : none;
}

// The shape's augmented Gram matrix on one fold (lower triangle) from the pool's full ones
// ([joint], empty where the pool has no columns).
Eigen::MatrixXd shape_gram(const PooledShape& shape, const std::vector<Eigen::MatrixXd>& pool) {
  const Eigen::Index p = width_of(shape);
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(p + 1, p + 1);
  for (std::size_t j = 0; j < pool.size(); ++j) {
    const std::vector<Eigen::Index>& cols = columns_on(shape, j);
    if (cols.empty()) continue;
    const Eigen::MatrixXd& g = pool[j];
    const Eigen::Index y = g.rows() - 1, first = shape.first_parameter[j];
    for (std::size_t c = 0; c < cols.size(); ++c) {
      const Eigen::Index row = first + Eigen::Index(c);
      for (std::size_t d = 0; d <= c; ++d) a(row, first + Eigen::Index(d)) += g(cols[c], cols[d]);
      a(p, row) += g(y, cols[c]);
    }
    a(p, p) += g(y, y);
  }
  return a;
}

// The fold fits' bounds of the shape's level (PooledShape::level_column of level_joint, a pool
// column) from the pool's fold Gram matrices ([fold][joint]): the sums of u x_c over the shape's
// parameters on that joint and of u². None when the shape has no level or no columns there.
std::vector<FoldBound> level_bounds(const PooledShape& shape,
                                    const std::vector<std::vector<Eigen::MatrixXd>>& grams) {
  const std::vector<Eigen::Index>& cols = columns_on(shape, shape.level_joint);
  if (shape.level_column < 0 || cols.empty()) return {};
  std::vector<Eigen::VectorXd> cross;
  std::vector<double> uu;
  for (const auto& fold : grams) {
    const Eigen::MatrixXd& g = fold[shape.level_joint];
    Eigen::VectorXd c = Eigen::VectorXd::Zero(width_of(shape));
    for (std::size_t i = 0; i < cols.size(); ++i)
      c[shape.first_parameter[shape.level_joint] + Eigen::Index(i)] =
          g(shape.level_column, cols[i]);
    cross.push_back(std::move(c));
    uu.push_back(g(shape.level_column, shape.level_column));
  }
  return fold_bounds(cross, uu, shape.level_lower);
}

// The shape's columns per joint (samples x its parameters where it acts, else empty).
std::vector<Eigen::MatrixXd> columns_of(const ShapePool& pool, const PooledShape& shape) {
  const Eigen::Index p = width_of(shape);
  std::vector<Eigen::MatrixXd> out(pool.columns.size());
  for (std::size_t j = 0; j < pool.columns.size(); ++j) {
    const std::vector<Eigen::Index>& cols = columns_on(shape, j);
    if (cols.empty()) continue;
    const Eigen::MatrixXd& from = pool.columns[j];
    // Zero where the shape's other joints' parameters are.
    Eigen::MatrixXd m = Eigen::Index(cols.size()) == p ? Eigen::MatrixXd(from.rows(), p)
                                                       : Eigen::MatrixXd::Zero(from.rows(), p);
    for (std::size_t c = 0; c < cols.size(); ++c)
      m.col(shape.first_parameter[j] + Eigen::Index(c)) = from.col(cols[c]);
    out[j] = std::move(m);
  }
  return out;
}

// A shape whose joints each have parameters of their own (the payload's) is that many separate
// least-squares problems: its fold Gram matrices are block-diagonal, so its fits and validation
// error are the sums of each joint's. Split into one shape per joint, with its own parameters
// from 0; any other shape as it is. Each part is solved alone: the blocks' scales do not mix in
// one condition number, and a block that needs the QR takes it on its own joint's rows only.
std::vector<PooledShape> independent_parts(const PooledShape& shape) {
  std::vector<PooledShape> parts;
  std::vector<int> taken(std::size_t(width_of(shape)), 0);  // joints per parameter
  for (std::size_t j = 0; j < shape.pool_columns.size(); ++j) {
    const std::vector<Eigen::Index>& cols = shape.pool_columns[j];
    if (cols.empty()) continue;
    for (std::size_t c = 0; c < cols.size(); ++c)
      ++taken[std::size_t(shape.first_parameter[j]) + c];
    PooledShape part;
    part.parameter_names.assign(
        shape.parameter_names.begin() + shape.first_parameter[j],
        shape.parameter_names.begin() + shape.first_parameter[j] + Eigen::Index(cols.size()));
    part.pool_columns.assign(shape.pool_columns.size(), {});
    part.pool_columns[j] = cols;
    part.first_parameter.assign(shape.pool_columns.size(), 0);
    parts.push_back(std::move(part));
  }
  // Parameters shared between joints: one problem.
  const bool each_once = std::all_of(taken.begin(), taken.end(), [](int t) { return t == 1; });
  if (parts.size() < 2 || !each_once) return {shape};
  return parts;
}

// The validation error of one shape of the pool (grams: [fold][joint]).
double shape_validation_sse(const PooledShape& shape,
                            const std::vector<std::vector<Eigen::MatrixXd>>& grams) {
  double sse = 0.0;
  for (PooledShape part : independent_parts(shape)) {
    part.level_column = shape.level_column, part.level_joint = shape.level_joint,
    part.level_lower = shape.level_lower;
    std::vector<Eigen::MatrixXd> part_folds;
    for (const auto& fold : grams) part_folds.push_back(shape_gram(part, fold));
    sse += folds_validation_sse(part_folds, level_bounds(part, grams));
  }
  return sse;
}

}  // namespace

CandidateShape shape_from_pool(const ShapePool& pool, std::size_t index) {
  const PooledShape& shape = pool.shapes[index];
  CandidateShape out;
  out.label = shape.label;
  out.parameter_names = shape.parameter_names;
  out.columns = columns_of(pool, shape);
  if (shape.level_column >= 0)
    out.level_signal = pool.columns[shape.level_joint].col(shape.level_column);
  out.level_lower = shape.level_lower;
  out.constant_on_own_joint = shape.constant_on_own_joint;
  return out;
}

PooledShape local_pooled_shape(std::size_t joints, std::size_t joint, std::string label,
                               std::vector<Eigen::Index> cols, std::vector<std::string> names) {
  PooledShape shape;
  shape.label = std::move(label);
  shape.parameter_names = std::move(names);
  shape.pool_columns.assign(joints, {});
  shape.pool_columns[joint] = std::move(cols);
  shape.first_parameter.assign(joints, 0);
  return shape;
}

std::vector<CandidateShape> shapes_from_pools(const std::vector<ShapePool>& pools) {
  std::vector<CandidateShape> out;
  for (const ShapePool& pool : pools)
    for (std::size_t i = 0; i < pool.shapes.size(); ++i) out.push_back(shape_from_pool(pool, i));
  return out;
}

std::vector<double> pooled_cross_validation_sse(const ShapePool& pool,
                                                const std::vector<std::vector<double>>& y,
                                                const TrainingFolds& folds) {
  // [fold][joint]: the pool's augmented Gram matrix, both triangles.
  std::vector<std::vector<Eigen::MatrixXd>> grams(folds.folds.size());
  for (std::size_t f = 0; f < folds.folds.size(); ++f) {
    grams[f].resize(pool.columns.size());
    for (std::size_t j = 0; j < pool.columns.size(); ++j)
      if (pool.columns[j].size() > 0)
        grams[f][j] =
            augmented_gram(pool.columns[j], y[j], folds.folds[f]).selfadjointView<Eigen::Lower>();
  }
  std::vector<double> out;
  for (const PooledShape& shape : pool.shapes) out.push_back(shape_validation_sse(shape, grams));
  return out;
}

}  // namespace imscal::eval
