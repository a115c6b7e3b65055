#include "eval/gap_candidates.hpp"

#include <fmt/format.h>

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

#include "core/units.hpp"
#include "eval/gap_bounds.hpp"
#include "eval/gap_coupling.hpp"
#include "eval/gap_effect_shapes.hpp"
#include "eval/gap_filters.hpp"
#include "eval/gap_joint_stack.hpp"
#include "eval/gap_normal_equations.hpp"
#include "eval/gap_shape_choice.hpp"
#include "eval/gap_validation.hpp"

namespace imscal::eval {

std::vector<CandidateShape> candidate_shapes(EffectKind kind, const GapSignals& s,
                                             std::size_t joint, const std::vector<bool>* training) {
  return effect_definition(kind).shapes(ShapeContext(s, joint, training));
}

namespace {

// The runs of consecutive indices in `rows` (ascending), as [begin, end) positions in rows.
std::vector<std::pair<Eigen::Index, Eigen::Index>> consecutive_runs(
    const std::vector<Eigen::Index>& rows) {
  std::vector<std::pair<Eigen::Index, Eigen::Index>> runs;
  for (std::size_t i = 0; i < rows.size(); ++i)
    if (i == 0 || rows[i] != rows[i - 1] + 1)
      runs.emplace_back(Eigen::Index(i), Eigen::Index(i) + 1);
    else
      ++runs.back().second;
  return runs;
}

// Integrated autocorrelation time of the residual r on the rows `rows` (consecutive rows only;
// summed up to the first non-positive correlation, at most 200 lags): the effective number of
// independent rows is m / tau_int, so sigma grows by sqrt(tau_int).
double residual_autocorrelation_time(const Eigen::VectorXd& r,
                                     const std::vector<Eigen::Index>& rows) {
  const Eigen::Index m = r.size();
  double tau_int = 1.0;
  const double var = r.squaredNorm() / std::max<double>(double(m), 1.0);
  if (var <= 0.0) return tau_int;
  const std::vector<std::pair<Eigen::Index, Eigen::Index>> runs = consecutive_runs(rows);
  for (Eigen::Index lagk = 1; lagk < std::min<Eigen::Index>(200, m); ++lagk) {
    // The pairs lagk apart in the same run.
    double c = 0.0;
    for (const auto& [begin, end] : runs)
      if (end - begin > lagk)
        c += r.segment(begin + lagk, end - begin - lagk).dot(r.segment(begin, end - begin - lagk));
    const double rho = c / (double(m) * var);
    if (rho <= 0.0) break;
    tau_int += 2.0 * rho;
  }
  return tau_int;
}

// The fit's figures from its residual r on the rows `rows` and the covariance of the scaled
// parameters up to the residual variance (`scaled_covariance`, columns scaled by `scale`).
LinearFit finished_fit(const Eigen::VectorXd& theta, const Eigen::VectorXd& r,
                       const std::vector<Eigen::Index>& rows,
                       const Eigen::MatrixXd& scaled_covariance, const Eigen::VectorXd& scale) {
  const Eigen::Index m = r.size(), p = theta.size();
  LinearFit fit;
  fit.parameters = theta;
  fit.rms = m ? std::sqrt(r.squaredNorm() / double(m)) : 0.0;
  fit.inflation = std::sqrt(residual_autocorrelation_time(r, rows));
  const double dof = std::max<double>(double(m - p), 1.0);
  const Eigen::MatrixXd cov = r.squaredNorm() / dof * scaled_covariance;
  const Eigen::VectorXd inverse_scale = scale.cwiseInverse();
  fit.covariance = inverse_scale.asDiagonal() * cov * inverse_scale.asDiagonal();
  fit.covariance *= fit.inflation * fit.inflation;
  fit.sigma = cov.diagonal().cwiseMax(0.0).cwiseSqrt().cwiseQuotient(scale) * fit.inflation;
  return fit;
}

// The column-pivoted QR fit of the scaled columns on the rows `rows` (the fallback of the normal
// equations: ill-conditioned or rank-deficient columns).
LinearFit qr_fit(const Eigen::MatrixXd& columns, const std::vector<double>& y,
                 const std::vector<Eigen::Index>& rows) {
  const Eigen::Index m = Eigen::Index(rows.size()), p = columns.cols();
  // Gathered column by column (a column-major matrix's rows are strided).
  Eigen::MatrixXd x = columns(rows, Eigen::all);
  Eigen::VectorXd b(m);
  for (Eigen::Index i = 0; i < m; ++i) b[i] = y[std::size_t(rows[std::size_t(i)])];
  // Column scaling keeps the QR well conditioned for columns of very different sizes.
  Eigen::VectorXd scale(p);
  for (Eigen::Index c = 0; c < p; ++c) {
    const double nrm = x.col(c).norm();
    scale[c] = nrm > 0.0 ? nrm : 1.0;
    x.col(c) /= scale[c];
  }
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(x);
  const Eigen::VectorXd theta = qr.solve(b);
  const Eigen::VectorXd r = b - x * theta;
  const Eigen::MatrixXd rr =
      qr.matrixR().topLeftCorner(p, p).template triangularView<Eigen::Upper>();
  // (R^T R)^-1 in the pivoted order, put back in the columns' order.
  const Eigen::MatrixXd cov_piv =
      (rr.transpose() * rr).completeOrthogonalDecomposition().pseudoInverse();
  const auto perm = qr.colsPermutation();
  return finished_fit(theta.cwiseQuotient(scale), r, rows, perm * cov_piv * perm.transpose(),
                      scale);
}

// The columns and gap of one joint in a stacked fit.
struct JointRows {
  const Eigen::MatrixXd& x;
  const std::vector<double>& y;
};

// The residual y - x theta on the rows `use_rows` of every joint of `joints`, stacked joint after
// joint.
Eigen::VectorXd stacked_residual(const std::vector<JointRows>& joints,
                                 const std::vector<Eigen::Index>& use_rows,
                                 const Eigen::VectorXd& theta) {
  const Eigen::Index m = Eigen::Index(use_rows.size());
  Eigen::VectorXd r(m * Eigen::Index(joints.size()));
  const auto runs = consecutive_runs(use_rows);
  for (std::size_t i = 0; i < joints.size(); ++i)
    for (const auto& [begin, end] : runs) {
      const Eigen::Index first = use_rows[std::size_t(begin)], length = end - begin;
      r.segment(Eigen::Index(i) * m + begin, length) =
          Eigen::Map<const Eigen::VectorXd>(joints[i].y.data() + first, length) -
          joints[i].x.middleRows(first, length) * theta;
    }
  return r;
}

// The fit of one parameter vector to the rows `use_rows` of every joint of `joints` (stacked joint
// after joint: row i * samples + k) by the normal equations; nullopt when they are
// ill-conditioned.
std::optional<LinearFit> gram_fit(const std::vector<JointRows>& joints,
                                  const std::vector<Eigen::Index>& use_rows) {
  const Eigen::Index p = joints.front().x.cols(), n = joints.front().x.rows();
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(p + 1, p + 1);
  for (const JointRows& j : joints) add_augmented_gram(j.x, j.y, use_rows, a);
  const std::optional<GramSolution> solution = solve_normal_equations(a, true);
  if (!solution) return std::nullopt;
  const Eigen::VectorXd r = stacked_residual(joints, use_rows, solution->theta);
  return finished_fit(solution->theta, r, stacked_rows(use_rows, joints.size(), n),
                      solution->inverse_scaled_gram, solution->scale);
}

std::vector<Eigen::Index> rows_of(const std::vector<bool>& use) {
  std::vector<Eigen::Index> rows;
  for (std::size_t k = 0; k < use.size(); ++k)
    if (use[k]) rows.push_back(Eigen::Index(k));
  return rows;
}

// fit_columns(columns, y, use).rms, without the parameters' covariance (an order search needs
// the residual RMS only); `rows`: the rows flagged in `use`.
double fit_rms(const Eigen::MatrixXd& columns, const std::vector<double>& y,
               const std::vector<bool>& use, const std::vector<Eigen::Index>& rows) {
  if (rows.empty()) return fit_columns(columns, y, use).rms;
  const std::optional<GramSolution> solution =
      solve_normal_equations(augmented_gram(columns, y, rows));
  if (!solution) return fit_columns(columns, y, use).rms;
  const Eigen::VectorXd r = stacked_residual({{columns, y}}, rows, solution->theta);
  return std::sqrt(r.squaredNorm() / double(r.size()));
}

}  // namespace

// The fewest periods a searched order's ripple must complete over the joint's motion.
constexpr double kMinRipplePeriods = 10.0;

std::vector<double> transmission_orders_by_fit(const GapSignals& s, std::size_t joint,
                                               const std::vector<double>& gap,
                                               const std::vector<bool>& use) {
  const std::size_t n = s.sample_count();
  const auto [lowest, highest] =
      std::minmax_element(s.q_internal_rad[joint].begin(), s.q_internal_rad[joint].end());
  const double motor_range_rad = n > 0 ? s.gear_ratio[joint] * (*highest - *lowest) : 0.0;
  std::vector<std::pair<double, double>> scored;  // (rms, order)
  const std::vector<Eigen::Index> rows = rows_of(use);
  for (int twice = 2; twice <= 16; ++twice) {
    const double h = 0.5 * twice;
    // A ripple of fewer periods over the motion is a slow drift to the data, not an order.
    if (h * motor_range_rad < kMinRipplePeriods * 2.0 * M_PI) continue;
    Eigen::MatrixXd columns(Eigen::Index(n), 2);
    for (std::size_t k = 0; k < n; ++k) {
      const double angle = h * s.gear_ratio[joint] * s.q_internal_rad[joint][k];
      columns(Eigen::Index(k), 0) = std::sin(angle);
      columns(Eigen::Index(k), 1) = std::cos(angle);
    }
    scored.emplace_back(fit_rms(columns, gap, use, rows), h);
  }
  std::sort(scored.begin(), scored.end());
  std::vector<double> orders;
  for (const auto& [rms, h] : scored) orders.push_back(h);
  return orders;
}

LinearFit fit_columns(const Eigen::MatrixXd& columns, const std::vector<double>& y,
                      const std::vector<bool>& use) {
  const std::vector<Eigen::Index> rows = rows_of(use);
  if (!rows.empty())
    if (auto fit = gram_fit({{columns, y}}, rows)) return *fit;
  return qr_fit(columns, y, rows);
}

LinearFit fit_joint_columns(const std::vector<Eigen::MatrixXd>& columns,
                            const std::vector<std::vector<double>>& gap,
                            const std::vector<bool>& use) {
  const std::vector<std::size_t> joints = joints_with_columns(columns);
  // One joint with columns: its rows are the stack (no copy).
  if (joints.size() == 1) return fit_columns(columns[joints[0]], gap[joints[0]], use);
  const std::vector<Eigen::Index> rows = rows_of(use);
  std::vector<JointRows> stack;
  for (std::size_t j : joints) stack.push_back({columns[j], gap[j]});
  if (!stack.empty() && !rows.empty())
    if (auto fit = gram_fit(stack, rows)) return *fit;
  const StackedJoints st = stack_joints(columns, gap);
  const Eigen::Index n = joints.empty() ? 0 : columns[joints[0]].rows();
  return qr_fit(st.x, st.y, stacked_rows(rows, joints.size(), n));
}

std::vector<std::vector<double>> predict_joint_columns(const std::vector<Eigen::MatrixXd>& columns,
                                                       const Eigen::VectorXd& parameters) {
  std::vector<std::vector<double>> out(columns.size());
  for (std::size_t j = 0; j < columns.size(); ++j) {
    if (columns[j].size() == 0) continue;
    const Eigen::VectorXd p = columns[j] * parameters;
    out[j].assign(p.data(), p.data() + p.size());
  }
  return out;
}

std::vector<Eigen::MatrixXd> join_columns(const std::vector<Eigen::MatrixXd>& a,
                                          const std::vector<Eigen::MatrixXd>& b,
                                          std::size_t samples) {
  Eigen::Index pa = 0, pb = 0;
  for (const auto& m : a) pa = std::max(pa, m.cols());
  for (const auto& m : b) pb = std::max(pb, m.cols());
  std::vector<Eigen::MatrixXd> out(std::max(a.size(), b.size()));
  const Eigen::Index n = Eigen::Index(samples);
  for (std::size_t j = 0; j < out.size(); ++j) {
    const bool has_a = j < a.size() && a[j].size() > 0, has_b = j < b.size() && b[j].size() > 0;
    if (!has_a && !has_b) continue;
    out[j] = Eigen::MatrixXd::Zero(n, pa + pb);
    if (has_a) out[j].leftCols(pa) = a[j];
    if (has_b) out[j].rightCols(pb) = b[j];
  }
  return out;
}

namespace {

// The size of the effect in words, in the effect's own terms where it has them.
std::string size_in_words(const CandidateFit& c, const CandidateShape& sh, double own_rms) {
  const auto own_words = effect_definition(c.kind).size_in_words;
  return own_words ? own_words(c, sh, own_rms) : size_of_first_parameter(c);
}

// The LS fit of a candidate's columns within its physical bound (eval/gap_bounds.hpp): sets its
// level, the unconstrained one and whether the bound is active.
LinearFit fit_bounded(CandidateFit& c, const GapSignals& s, const std::vector<bool>& training) {
  LinearFit f = fit_joint_columns(c.columns, s.gap_rad, training);
  if (c.bound.count == 0) return f;
  c.unconstrained_level = bound_level(c.columns, c.bound, f.parameters, training);
  c.at_bound = apply_level_bounds(c.columns, s.gap_rad, training, {c.bound}, f);
  c.level = bound_level(c.columns, c.bound, f.parameters, training);
  return f;
}

}  // namespace

std::optional<CandidateFit> fit_candidate(EffectKind kind, const GapSignals& s, std::size_t joint,
                                          const std::vector<bool>& training) {
  // The shape the 2-fold validation inside the training rows chooses (eval/gap_shape_choice.hpp).
  const TrainingFolds folds = training_folds(s, training);
  std::optional<CandidateShape> chosen = chosen_shape(kind, s, joint, training, folds);
  if (!chosen) return std::nullopt;
  CandidateShape& sh = *chosen;
  const Eigen::Index n = Eigen::Index(s.sample_count());
  CandidateFit c;
  c.kind = kind;
  c.joint = joint;
  c.shape = sh.label;
  c.parameter_names = sh.parameter_names;
  c.columns = std::move(sh.columns);  // the fit holds them from here on (no copy)
  if (sh.level_signal.size() > 0)
    c.bound = {joint, 0, Eigen::Index(sh.parameter_names.size()), sh.level_signal, sh.level_lower};
  LinearFit f = fit_bounded(c, s, training);
  c.prediction = predict_joint_columns(c.columns, f.parameters);
  // Acting on several joints by its own columns: located where its modelled gap has the most
  // energy; acting on one: that joint, wherever its coupling carries it.
  std::size_t acting = 0;
  double most = -1.0;
  for (std::size_t j = 0; j < c.prediction.size(); ++j) {
    if (c.prediction[j].empty()) continue;
    ++acting;
    double e = 0.0;
    for (double v : c.prediction[j]) e += v * v;
    if (e > most) most = e, c.joint = j;
  }
  c.spans_joints = acting > 1;
  double own_energy = 0.0;
  for (double v : c.prediction[c.joint]) own_energy += v * v;
  // Spread over the other joints through the coupled dynamics (effects that move a link only).
  if (acts_through_dynamics(kind)) {
    std::vector<std::vector<double>> residual = s.gap_rad;
    for (std::size_t j = 0; j < residual.size(); ++j)
      for (std::size_t k = 0; k < c.prediction[j].size(); ++k) residual[j][k] -= c.prediction[j][k];
    const CouplingColumns coupling = coupling_columns(s, c.prediction, residual, folds);
    if (!coupling.joints.empty()) {
      c.columns = join_columns(c.columns, coupling.columns, s.sample_count());
      c.parameter_names.insert(c.parameter_names.end(), coupling.parameter_names.begin(),
                               coupling.parameter_names.end());
      c.coupled_joints = coupling.joints;
      c.coupling_parameter_count = coupling.parameter_names.size();
      std::vector<std::string> reach;
      for (std::size_t i = 0; i < coupling.joints.size(); ++i)
        reach.push_back(
            fmt::format("{} ({})", s.joint_names[coupling.joints[i]], coupling.shapes[i]));
      c.coupling = fmt::format("through the inertia M_ij q̈_j into {}", fmt::join(reach, ", "));
      f = fit_bounded(c, s, training);
      c.prediction = predict_joint_columns(c.columns, f.parameters);
    }
  }
  c.parameters = f.parameters;
  c.sigma = f.sigma;
  c.training_rms_rad = f.rms;
  double total = 0.0;
  for (const auto& p : c.prediction)
    for (double v : p) total += v * v;
  const double modelled_rms = std::sqrt(total / double(std::max<Eigen::Index>(n, 1)));
  const double own_rms = std::sqrt(own_energy / double(std::max<Eigen::Index>(n, 1)));
  c.size_text = size_in_words(c, sh, own_rms);
  c.size_text += fmt::format("; modelled gap RMS {:.3g} rad ({:.2f} arcsec){}", modelled_rms,
                             modelled_rms * kArcsecPerRad,
                             c.spans_joints             ? " over all joints"
                             : c.coupled_joints.empty() ? ""
                                                        : " with its coupling");
  if (c.at_bound)
    c.size_text += fmt::format(
        "; held at its physical bound (level {:.3g}: the unconstrained fit's level {:.3g} would "
        "leave the combined model unphysical)",
        c.level, c.unconstrained_level);
  return c;
}

}  // namespace imscal::eval
