#pragma once
// Physical bounds of the gap diagnosis' candidate effects (eval/gap_candidates.hpp). A candidate
// models the change of a parameter of the nominal model (a compliance, a play, a friction level);
// the combined model, nominal plus change, must stay physical: no negative compliance or play, no
// negative friction. Its shape is a linear response whose coefficients are not the parameter
// itself (Laguerre bases of the loop's reaction), so the bound acts on the effect's level: the LS
// coefficient of the candidate's modelled gap on its own joint against the effect's static
// signal u (tau_d for a compliance, the flank for a play, the sign of the velocity for friction)
// over the training rows,
//
//   level(theta) = <u, X_own theta> / <u, u>   (linear in theta: w^T theta)
//
// and level >= lower, lower = -(the nominal model's value) in the level's units (0 when the
// nominal model has none of it). A fit whose unconstrained optimum breaks a bound is refitted with
// that bound active: least squares under the equality constraints of an active set (most violated
// bound added first until all hold), theta = theta_ls + G A^T (A G A^T)^-1 (b - A theta_ls),
// G = (X^T X)^-1 (Lawson & Hanson, ch. 20-23).
//
// References (docs/references.md): [LawsonHanson1974].
#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "eval/gap_candidates.hpp"

namespace imscal::eval {

// The level of `parameters` under `bound` (training rows `use`).
double bound_level(const std::vector<Eigen::MatrixXd>& columns, const LevelBound& bound,
                   const Eigen::VectorXd& parameters, const std::vector<bool>& use);

// Refits `fit` (the LS fit of `columns` to `gap` on the rows `use`, stacked over the joints as
// fit_joint_columns) so that every bound holds; returns whether any bound is active. The sigma
// and covariance stay those of the unconstrained fit; rms is the constrained fit's.
bool apply_level_bounds(const std::vector<Eigen::MatrixXd>& columns,
                        const std::vector<std::vector<double>>& gap, const std::vector<bool>& use,
                        const std::vector<LevelBound>& bounds, LinearFit& fit);

}  // namespace imscal::eval
