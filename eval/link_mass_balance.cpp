#include "eval/link_mass_balance.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <span>
#include <stdexcept>

#include "eval/friction_identification.hpp"

namespace imscal::eval {
namespace {

using Columns = std::vector<std::vector<std::vector<double>>>;  // [column][joint][sample]

// One joint's balance with the estimated columns (−∂τ/∂p: their coefficients are the changes).
struct JointBalance {
  Eigen::MatrixXd drive, changes;
  Eigen::VectorXd target;
};

// The drive's columns projected out of the changes' columns and the target, over the kept rows.
void project(const JointBalance& b, const std::vector<bool>& keep, Eigen::MatrixXd& changes,
             Eigen::VectorXd& target) {
  const auto rows = Eigen::Index(std::count(keep.begin(), keep.end(), true));
  Eigen::MatrixXd drive(rows, b.drive.cols());
  changes.resize(rows, b.changes.cols());
  target.resize(rows);
  for (Eigen::Index i = 0, r = 0; i < b.drive.rows(); ++i)
    if (keep[std::size_t(i)]) {
      drive.row(r) = b.drive.row(i), changes.row(r) = b.changes.row(i), target(r) = b.target(i);
      ++r;
    }
  const Eigen::VectorXd scale = drive.colwise().norm().cwiseMax(1e-300).cwiseInverse();
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(drive * scale.asDiagonal());
  const Eigen::MatrixXd q = qr.householderQ() * Eigen::MatrixXd::Identity(rows, drive.cols());
  changes -= q * (q.transpose() * changes);
  target -= q * (q.transpose() * target);
}

double correlation_factor(const Eigen::VectorXd& r) {
  const double variance = r.squaredNorm();
  double factor = 1.0;
  for (Eigen::Index lag = 1; variance > 0.0 && lag < std::min<Eigen::Index>(200, r.size()); ++lag) {
    const double rho = r.head(r.size() - lag).dot(r.tail(r.size() - lag)) / variance;
    if (rho <= 0.0) break;
    factor += 2.0 * rho;
  }
  return factor;
}

struct Solution {
  Eigen::VectorXd change;
  Eigen::MatrixXd covariance;
  double condition = 0.0;
};

// Two passes: the changes with each joint weighted by its projected target's variance, then
// again with 1 / (residual variance × correlation factor) and the prior's information added.
Solution solve(const std::vector<JointBalance>& joints, const std::vector<bool>& keep,
               const Eigen::VectorXd& prior_information) {
  const Eigen::Index n = joints.front().changes.cols();
  std::vector<Eigen::MatrixXd> x(joints.size());
  std::vector<Eigen::VectorXd> y(joints.size());
  std::vector<double> weight(joints.size());
  for (std::size_t j = 0; j < joints.size(); ++j) {
    project(joints[j], keep, x[j], y[j]);
    weight[j] = double(y[j].size()) / y[j].squaredNorm();
  }
  Solution s;
  s.change = Eigen::VectorXd::Zero(n);
  for (int pass = 0; pass < 2; ++pass) {
    Eigen::MatrixXd information = prior_information.asDiagonal();
    Eigen::VectorXd right = Eigen::VectorXd::Zero(n);
    for (std::size_t j = 0; j < joints.size(); ++j) {
      information += weight[j] * x[j].transpose() * x[j];
      right += weight[j] * x[j].transpose() * y[j];
    }
    s.change = information.ldlt().solve(right);
    s.covariance = information.inverse();
    const Eigen::VectorXd d = information.diagonal().cwiseSqrt().cwiseInverse();
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(d.asDiagonal() * information *
                                                               d.asDiagonal());
    s.condition = eigen.eigenvalues().maxCoeff() / eigen.eigenvalues().minCoeff();
    for (std::size_t j = 0; j < joints.size(); ++j) {
      const Eigen::VectorXd r = y[j] - x[j] * s.change;
      weight[j] = double(r.size()) / (r.squaredNorm() * correlation_factor(r));
    }
  }
  return s;
}

// −(τ(model) − τ(nominal)) / step per joint and sample.
std::vector<std::vector<double>> change_column(const ModelTorqueSource& changed,
                                               const std::vector<std::vector<double>>& nominal,
                                               const ident::JointErrorLog& log,
                                               std::span<const double> payload_kg, double step) {
  auto t = model_torques_along(changed, log.cycle_s, log.q_desired_rad, payload_kg, log.segments());
  for (std::size_t j = 0; j < t.size(); ++j)
    for (std::size_t k = 0; k < t[j].size(); ++k) t[j][k] = -(t[j][k] - nominal[j][k]) / step;
  return t;
}

// The payload's mass factor's column (the logged mass times 1 + change) when it is estimated.
void payload_column(const ModelTorqueSource& nominal, const ident::JointErrorLog& log,
                    const std::vector<std::vector<double>>& torque,
                    const LinkMassBalanceOptions& options, Columns& columns,
                    std::vector<std::string>& names) {
  if (!(options.payload_mass_prior_sigma > 0.0)) return;
  constexpr double kStep = 0.1;
  std::vector<double> scaled(log.payload_kg);
  for (double& m : scaled) m *= 1.0 + kStep;
  columns.push_back(change_column(nominal, torque, log, scaled, kStep));
  names.push_back("payload mass factor - 1");
}

// The rows whose desired speeds are all below the threshold (all rows when it is 0).
std::vector<bool> quasi_static_rows(const ident::JointErrorLog& log,
                                    const std::vector<std::size_t>& samples, double threshold) {
  std::vector<bool> used(samples.size(), true);
  if (!(threshold > 0.0)) return used;
  for (std::size_t r = 0; r < samples.size(); ++r)
    for (std::size_t j = 0; j < log.joint_count(); ++j) {
      const std::size_t k = samples[r];
      const std::size_t lo = k > 0 ? k - 1 : k, hi = std::min(k + 1, log.time_s.size() - 1);
      const double speed =
          (log.q_desired_rad[j][hi] - log.q_desired_rad[j][lo]) / (double(hi - lo) * log.cycle_s);
      if (std::abs(speed) >= threshold) used[r] = false;
    }
  return used;
}

// Per joint and column: the share of the column's spread the drive's columns leave.
std::vector<std::vector<double>> unexplained_shares(const std::vector<JointBalance>& joints,
                                                    const std::vector<bool>& used) {
  std::vector<std::vector<double>> out;
  for (const auto& joint : joints) {
    Eigen::MatrixXd changes;
    Eigen::VectorXd target;
    project(joint, used, changes, target);
    std::vector<double> share;
    for (Eigen::Index c = 0; c < changes.cols(); ++c) {
      Eigen::VectorXd column(changes.rows());
      for (Eigen::Index i = 0, r = 0; i < joint.changes.rows(); ++i)
        if (used[std::size_t(i)]) column(r++) = joint.changes(i, c);
      const double spread = (column.array() - column.mean()).matrix().norm();
      share.push_back(spread > 0.0 ? changes.col(c).norm() / spread : 0.0);
    }
    out.push_back(std::move(share));
  }
  return out;
}

// Delete-one-block jackknife's standard deviation over time blocks of the used rows.
Eigen::VectorXd jackknife_sigma(const std::vector<JointBalance>& joints,
                                const std::vector<bool>& used, const Eigen::VectorXd& prior,
                                int blocks) {
  blocks = std::max(2, blocks);
  const std::size_t rows = used.size();
  std::vector<Eigen::VectorXd> partial;
  for (int b = 0; b < blocks; ++b) {
    std::vector<bool> keep = used;
    for (std::size_t k = rows * std::size_t(b) / std::size_t(blocks);
         k < rows * std::size_t(b + 1) / std::size_t(blocks); ++k)
      keep[k] = false;
    partial.push_back(solve(joints, keep, prior).change);
  }
  Eigen::VectorXd mean = Eigen::VectorXd::Zero(partial.front().size());
  for (const auto& p : partial) mean += p / double(blocks);
  Eigen::VectorXd spread = Eigen::VectorXd::Zero(mean.size());
  for (const auto& p : partial) spread += (p - mean).cwiseAbs2() * double(blocks - 1) / blocks;
  return spread.cwiseSqrt();
}

}  // namespace

LinkMassBalance identify_link_masses(const ident::JointErrorLog& log,
                                     const ModelTorqueSource& nominal,
                                     const LinkMassBalanceOptions& options) {
  if (!log.has_q_internal())
    throw std::invalid_argument("link masses: the record has no motor encoders (q_internal)");
  LinkMassBalance out;
  out.dead_time_cycles = identify_friction_levels(log, nominal, options.balance)
                             .front()
                             .dead_time_cycles;  // one controller: every joint's δ is the same
  const auto segments = log.segments();
  const auto torque =
      model_torques_along(nominal, log.cycle_s, log.q_desired_rad, log.payload_kg, segments);
  Columns columns;
  for (const int link : options.links) {
    ModelTorqueSource heavier = nominal;
    heavier.robot.joints[std::size_t(link)].link.mass_kg += options.step_kg;
    columns.push_back(change_column(heavier, torque, log, log.payload_kg, options.step_kg));
  }
  payload_column(nominal, log, torque, options, columns, out.payload_names);
  ident::FrictionLevelOptions at_rate = options.balance;
  at_rate.cycle_s = log.cycle_s;
  std::vector<JointBalance> joints;
  std::vector<std::size_t> samples;
  for (const int j : options.joints) {
    const auto J = std::size_t(j);
    std::vector<double> speed, acceleration, unused;
    path_derivatives(log.q_internal_rad[J], log.cycle_s, segments, speed, unused);
    path_derivatives(log.q_desired_rad[J], log.cycle_s, segments, unused, acceleration);
    std::vector<std::span<const double>> extra;
    for (const auto& c : columns) extra.emplace_back(c[J]);
    const auto r = ident::friction_balance_regression(
        {log.q_desired_rad[J], log.q_internal_rad[J], torque[J], speed, acceleration, segments},
        at_rate, out.dead_time_cycles, extra);
    samples = r.samples;
    joints.push_back({r.columns.leftCols(r.drive_columns),
                      r.columns.rightCols(r.columns.cols() - r.drive_columns), r.target});
  }
  const auto used = quasi_static_rows(log, samples, options.quasi_static_speed_rad_s);
  Eigen::VectorXd prior = Eigen::VectorXd::Zero(Eigen::Index(columns.size()));
  if (options.payload_mass_prior_sigma > 0.0)
    prior(Eigen::Index(options.links.size())) = std::pow(options.payload_mass_prior_sigma, -2);
  const Solution all = solve(joints, used, prior);
  out.condition_number = all.condition;
  out.unexplained_share = unexplained_shares(joints, used);
  const Eigen::VectorXd jackknife = jackknife_sigma(joints, used, prior, options.jackknife_blocks);
  for (Eigen::Index i = 0; i < Eigen::Index(columns.size()); ++i) {
    const bool link = i < Eigen::Index(options.links.size());
    const int index = link ? options.links[std::size_t(i)] : -1;
    out.links.push_back({index, link ? nominal.robot.joints[std::size_t(index)].link.mass_kg : 0.0,
                         all.change(i), std::sqrt(all.covariance(i, i)), jackknife(i)});
  }
  return out;
}

}  // namespace imscal::eval
