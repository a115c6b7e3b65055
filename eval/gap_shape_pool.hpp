#pragma once
// Shapes of a candidate effect that are subsets of one pool of columns (eval/gap_candidates.hpp):
// a transmission error's bases of one order share its filtered ripple, the payload's shapes share
// each loaded joint's filtered unit-payload torque, the coupling's bases one joint's filtered
// inertia torque. The pool's augmented Gram matrix per fold and joint is formed once; a shape's
// fold Gram matrix is the sum of its entries (the Gram entry of two columns does not depend on
// the other columns), so its validation error (eval/gap_validation.hpp) needs no copy of its
// columns, and only the chosen shape's columns are copied out of the pool.
#include <Eigen/Core>
#include <cstddef>
#include <string>
#include <vector>

#include "eval/gap_candidates.hpp"
#include "eval/gap_validation.hpp"

namespace imscal::eval {

struct PooledShape {
  std::string label;
  std::vector<std::string> parameter_names;
  // [joint]: the pool columns of that joint that are the shape's parameters first_parameter[j],
  // first_parameter[j] + 1, ... (empty: the shape does not act on the joint; the shape's other
  // parameters are zero columns there).
  std::vector<std::vector<Eigen::Index>> pool_columns;
  std::vector<Eigen::Index> first_parameter;
  // CandidateShape::level_signal: pool column `level_column` of joint `level_joint` (-1: none),
  // with its lower bound; and CandidateShape::constant_on_own_joint.
  Eigen::Index level_column = -1;
  std::size_t level_joint = 0;
  double level_lower = 0.0;
  bool constant_on_own_joint = false;
};

// A shape on `joint` only of the pool columns `cols` of that joint (pool of `joints` joints).
PooledShape local_pooled_shape(std::size_t joints, std::size_t joint, std::string label,
                               std::vector<Eigen::Index> cols, std::vector<std::string> names);

struct ShapePool {
  std::vector<Eigen::MatrixXd> columns;  // [joint]: samples x pool width, or empty
  std::vector<PooledShape> shapes;
};

// A shape of the pool with its own columns (samples x its parameters per joint it acts on).
CandidateShape shape_from_pool(const ShapePool& pool, std::size_t index);

// Every shape of every pool, pool by pool: the `shapes` of an effect with `shape_pools`
// (eval/gap_effects.hpp), in the order its pools validate them.
std::vector<CandidateShape> shapes_from_pools(const std::vector<ShapePool>& pools);

// The validation error summed over the folds of each shape of the pool fitted to y ([joint]),
// the same as cross_validation_sse of its columns within its level's bound: the fold fits
// (eval/gap_fold_fit.hpp) from the pool's Gram matrices. A shape whose joints each have
// parameters of their own is that many separate problems (its Gram matrices are block-diagonal):
// each joint's is solved alone and their errors add.
std::vector<double> pooled_cross_validation_sse(const ShapePool& pool,
                                                const std::vector<std::vector<double>>& y,
                                                const TrainingFolds& folds);

}  // namespace imscal::eval
