#include "eval/gap_measurement_budget.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <utility>

#include "core/units.hpp"

namespace imscal::eval {
namespace {

// The first sample's gear wind-up tau_g / k and play taken up (+-half the play, the sign of
// tau_g) per joint [rad], as calib/static_deflection.hpp models them; zero where not known.
std::pair<std::vector<double>, std::vector<double>> first_sample_deflection(const GapSignals& s) {
  std::vector<double> windup(s.joint_count(), 0.0), play(s.joint_count(), 0.0);
  for (std::size_t j = 0; j < s.joint_count(); ++j) {
    if (j >= s.gravity_torque_nm.size() || s.gravity_torque_nm[j].empty()) continue;
    const double tau = s.gravity_torque_nm[j].front();
    if (j < s.nominal_compliance_rad_per_nm.size())
      windup[j] = s.nominal_compliance_rad_per_nm[j] * tau;
    if (j < s.nominal_half_play_rad.size())
      play[j] = std::copysign(s.nominal_half_play_rad[j], tau);
  }
  return {windup, play};
}

// The budget's columns of joint j (samples x kMeasurementParameterCount, in the order of
// kMeasurementParameterNames): mounting, gyro bias, world rate, q̇_d for the clock offset, and
// the first rest's wind-up and play scales through the start pose's signature.
Eigen::MatrixXd budget_columns(
    const GapSignals& s, std::size_t j,
    const std::pair<std::vector<double>, std::vector<double>>& deflection) {
  const GapSignals::ImsChainColumns& c = s.ims_chain_columns[j];
  const Eigen::Index n = Eigen::Index(s.sample_count());
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n, kMeasurementParameterCount);
  a.leftCols(kFirstDeflectionParameter) << c.mounting, c.gyro_bias, c.world_rate,
      Eigen::Map<const Eigen::VectorXd>(s.qd_desired_rad_s[j].data(), n);
  if (c.start_pose.rows() == n)
    for (Eigen::Index i = 0; i < c.start_pose.cols() && i < 6; ++i) {
      a.col(kFirstDeflectionParameter + i) = c.start_pose.col(i) * deflection.first[std::size_t(i)];
      a.col(kFirstDeflectionParameter + 6 + i) =
          c.start_pose.col(i) * deflection.second[std::size_t(i)];
    }
  return a;
}

// The prior's whitened coordinates: W = V L^(1/2) over the directions P holds (eigenvalues above
// 1e-12 of the largest), so p = W z with z ~ N(0, I) a priori.
Eigen::MatrixXd whitening(const Eigen::MatrixXd& P) {
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(P);
  const Eigen::VectorXd l = eig.eigenvalues();
  const double top = l.maxCoeff();
  std::vector<Eigen::Index> kept;
  for (Eigen::Index i = 0; i < l.size(); ++i)
    if (top > 0.0 && l[i] > 1e-12 * top) kept.push_back(i);
  Eigen::MatrixXd W(P.rows(), Eigen::Index(kept.size()));
  for (std::size_t i = 0; i < kept.size(); ++i)
    W.col(Eigen::Index(i)) = eig.eigenvectors().col(kept[i]) * std::sqrt(l[kept[i]]);
  return W;
}

struct Fitted {
  std::vector<std::vector<double>> residual;  // [joint][sample]
  std::vector<double> expected_ms;            // per joint: mean a P a^T
  Eigen::VectorXd z, p;
};

// The MAP fit of the chain's columns (whitened by the prior) on the training rows, weighted per
// joint by 1 / (sigma_j^2 tau_j).
Fitted fit_measurement(const GapSignals& s, const std::vector<bool>& training,
                       const std::vector<std::size_t>& train_rows, std::size_t max_lag) {
  const std::size_t nj = s.joint_count();
  const Eigen::MatrixXd W = whitening(s.measurement.covariance_si);
  const Eigen::Index r = W.cols();
  Eigen::MatrixXd normal = Eigen::MatrixXd::Identity(r, r);
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(r);
  std::vector<Eigen::MatrixXd> B(nj);
  Fitted f;
  const auto deflection = first_sample_deflection(s);
  for (std::size_t j = 0; j < nj; ++j) {
    B[j] = budget_columns(s, j, deflection) * W;
    f.expected_ms.push_back(B[j].rowwise().squaredNorm().mean());
    const double sigma = s.measurement.noise_floor_rad[j];
    const double w =
        1.0 / (sigma * sigma * integrated_autocorrelation_time(s.gap_rad[j], train_rows, max_lag));
    for (std::size_t k = 0; k < training.size(); ++k) {
      if (!training[k]) continue;
      const auto row = B[j].row(Eigen::Index(k));
      normal.noalias() += w * row.transpose() * row;
      rhs.noalias() += w * row.transpose() * s.gap_rad[j][k];
    }
  }
  f.z = normal.ldlt().solve(rhs);
  f.p = W * f.z;
  for (std::size_t j = 0; j < nj; ++j) {
    const Eigen::VectorXd model = B[j] * f.z;
    f.residual.push_back(s.gap_rad[j]);
    for (std::size_t k = 0; k < s.sample_count(); ++k) f.residual[j][k] -= model[Eigen::Index(k)];
  }
  return f;
}

double rms_on(const std::vector<double>& x, const std::vector<std::size_t>& rows) {
  double e = 0.0;
  for (std::size_t k : rows) e += x[k] * x[k];
  return rows.empty() ? 0.0 : std::sqrt(e / double(rows.size()));
}

// Each joint's chi-squared of its held-out residual against its floor.
void test_joints(const GapSignals& s, const Fitted& f, const std::vector<std::size_t>& heldout,
                 std::size_t max_lag, MeasurementBudget& b) {
  for (std::size_t j = 0; j < s.joint_count(); ++j) {
    MeasurementJoint mj;
    mj.noise_floor_rad = s.measurement.noise_floor_rad[j];
    mj.gap_rms_rad = rms_on(s.gap_rad[j], heldout);
    mj.residual_rms_rad = rms_on(f.residual[j], heldout);
    const double expected_ms = f.expected_ms.empty() ? 0.0 : f.expected_ms[j];
    mj.expected_rms_rad = std::sqrt(mj.noise_floor_rad * mj.noise_floor_rad + expected_ms);
    const double tau = integrated_autocorrelation_time(f.residual[j], heldout, max_lag);
    const double ratio = mj.residual_rms_rad / mj.noise_floor_rad;
    mj.dof = double(heldout.size()) / tau;
    mj.chi2 = mj.dof * ratio * ratio;
    mj.p_value = chi2_upper_tail(mj.chi2, mj.dof);
    b.chi2 += mj.chi2;
    b.dof += mj.dof;
    b.joints.push_back(mj);
  }
}

std::string arcsec(double rad) {
  return fmt::format("{:.1f}", rad * kArcsecPerRad);
}

}  // namespace

double chi2_upper_tail(double chi2, double dof) {
  if (dof <= 0.0) return 1.0;
  if (chi2 <= 0.0) return 1.0;
  const double v = 2.0 / (9.0 * dof);
  const double z = (std::cbrt(chi2 / dof) - (1.0 - v)) / std::sqrt(v);
  return 0.5 * std::erfc(z / std::sqrt(2.0));
}

double integrated_autocorrelation_time(const std::vector<double>& x,
                                       const std::vector<std::size_t>& rows, std::size_t max_lag) {
  const std::size_t m = rows.size();
  double var = 0.0;
  for (std::size_t k : rows) var += x[k] * x[k];
  var /= double(std::max<std::size_t>(m, 1));
  double tau = 1.0;
  if (var <= 0.0) return tau;
  for (std::size_t lag = 1; lag < std::min(max_lag, m); ++lag) {
    double c = 0.0;
    for (std::size_t i = lag; i < m; ++i)
      if (rows[i] - rows[i - lag] == lag) c += x[rows[i]] * x[rows[i - lag]];
    const double rho = c / (double(m) * var);
    if (rho <= 0.0) break;
    tau += 2.0 * rho;
  }
  return tau;
}

MeasurementBudget measurement_budget(const GapSignals& s, const std::vector<bool>& training,
                                     double block_s, double alpha) {
  MeasurementBudget b;
  if (!s.measurement.known() || s.measurement.noise_floor_rad.size() != s.joint_count()) return b;
  b.known = true;
  b.source = s.measurement.source;
  std::vector<std::size_t> train_rows, heldout;
  for (std::size_t k = 0; k < training.size(); ++k)
    (training[k] ? train_rows : heldout).push_back(k);
  const auto max_lag = std::size_t(std::max(1.0, std::round(block_s / s.cycle_s)));
  b.frames = s.measurement.covariance_si.rows() == kMeasurementParameterCount &&
             s.ims_chain_columns.size() == s.joint_count();
  Fitted f;
  if (b.frames) {
    f = fit_measurement(s, training, train_rows, max_lag);
    for (int i = 0; i < kMeasurementParameterCount; ++i) {
      b.parameter_names.emplace_back(kMeasurementParameterNames[std::size_t(i)]);
      b.parameters.push_back(f.p[i]);
      b.prior_sigma.push_back(std::sqrt(s.measurement.covariance_si(i, i)));
    }
    b.prior_chi2 = f.z.squaredNorm();
    b.prior_dof = double(f.z.size());
    b.prior_p_value = chi2_upper_tail(b.prior_chi2, b.prior_dof);
  } else {
    f.residual = s.gap_rad;
  }
  test_joints(s, f, heldout, max_lag, b);
  b.chi2 += b.prior_chi2;
  b.dof += b.prior_dof;
  b.p_value = chi2_upper_tail(b.chi2, b.dof);
  const double tests = double(s.joint_count() + (b.frames ? 1 : 0));
  b.corrected_alpha = 1.0 - std::pow(1.0 - alpha, 1.0 / tests);
  b.within = !b.frames || b.prior_p_value >= b.corrected_alpha;
  for (const MeasurementJoint& mj : b.joints)
    b.within = b.within && mj.p_value >= b.corrected_alpha;
  return b;
}

std::string measurement_in_words(const GapSignals& s, const MeasurementBudget& b) {
  if (!b.known) return {};
  std::vector<std::string> per_joint, beyond;
  for (std::size_t j = 0; j < b.joints.size(); ++j) {
    const MeasurementJoint& mj = b.joints[j];
    per_joint.push_back(fmt::format("{} {} against {}", s.joint_names[j], arcsec(mj.gap_rms_rad),
                                    arcsec(mj.expected_rms_rad)));
    if (mj.p_value < b.corrected_alpha) beyond.push_back(s.joint_names[j]);
  }
  std::string t = fmt::format(
      "The gap is {} what the measurement explains: chi2 = {:.1f} for {:.1f} effective degrees "
      "of freedom (p = {:.3g}; per joint and for the frames at the corrected level {:.2g}); gap "
      "RMS per joint against the measurement's expected RMS (IMS noise floor{}) {} arcsec.",
      b.within ? "within" : "beyond", b.chi2, b.dof, b.p_value, b.corrected_alpha,
      b.frames ? " and the frames' covariance" : "", fmt::join(per_joint, ", "));
  if (!beyond.empty())
    t += fmt::format(" Beyond it on joint{} {}.", beyond.size() > 1 ? "s" : "",
                     fmt::join(beyond, ", "));
  if (b.frames && b.prior_p_value < b.corrected_alpha)
    t += fmt::format(
        " The chain's frames fitted to the gap lie beyond their calibrated covariance (chi2 = "
        "{:.1f} for {:.0f}, p = {:.3g}): the calibration may not hold for this record.",
        b.prior_chi2, b.prior_dof, b.prior_p_value);
  return t;
}

nlohmann::json measurement_json(const GapSignals& s, const MeasurementBudget& b) {
  if (!b.known) return nullptr;
  nlohmann::json joints = nlohmann::json::array();
  for (std::size_t j = 0; j < b.joints.size(); ++j) {
    const MeasurementJoint& mj = b.joints[j];
    joints.push_back({{"joint", s.joint_names[j]},
                      {"gap_rms_rad", mj.gap_rms_rad},
                      {"residual_rms_rad", mj.residual_rms_rad},
                      {"expected_rms_rad", mj.expected_rms_rad},
                      {"noise_floor_rad", mj.noise_floor_rad},
                      {"chi2", mj.chi2},
                      {"dof", mj.dof},
                      {"p_value", mj.p_value}});
  }
  nlohmann::json fitted = nlohmann::json::array();
  for (std::size_t i = 0; i < b.parameter_names.size(); ++i)
    fitted.push_back({{"name", b.parameter_names[i]},
                      {"value", b.parameters[i]},
                      {"prior_sigma", b.prior_sigma[i]}});
  return {{"within", b.within},
          {"chi2", b.chi2},
          {"dof", b.dof},
          {"p_value", b.p_value},
          {"corrected_alpha", b.corrected_alpha},
          {"with_frames", b.frames},
          {"frames_chi2", b.prior_chi2},
          {"frames_dof", b.prior_dof},
          {"frames_p_value", b.prior_p_value},
          {"source", b.source},
          {"joints", joints},
          {"fitted_chain_errors", fitted}};
}

}  // namespace imscal::eval
