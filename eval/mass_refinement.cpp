#include "eval/mass_refinement.hpp"

#include <fmt/format.h>

#include <Eigen/Cholesky>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "sim/rigid_body_dynamics.hpp"

namespace imscal::eval {
namespace {

constexpr int kPerLink = 4;  // mass, centre of mass x, y, z
constexpr int kParameters = calib::kJointCount * kPerLink;
using Parameters = Eigen::Matrix<double, kParameters, 1>;
using Matrix = Eigen::Matrix<double, kParameters, kParameters>;
using Torques = std::vector<calib::JointVector>;  // [row]

Parameters parameters_of(const calib::RobotDescription& robot) {
  Parameters p;
  for (int i = 0; i < calib::kJointCount; ++i) {
    const calib::RigidBodyParameters& link = robot.joints[std::size_t(i)].link;
    p(kPerLink * i) = link.mass_kg;
    p.segment<3>(kPerLink * i + 1) = link.com_m;
  }
  return p;
}

ModelTorqueSource with_parameters(ModelTorqueSource model, const Parameters& p) {
  for (int i = 0; i < calib::kJointCount; ++i) {
    calib::RigidBodyParameters& link = model.robot.joints[std::size_t(i)].link;
    link.mass_kg = p(kPerLink * i);
    link.com_m = p.segment<3>(kPerLink * i + 1);
  }
  return model;
}

// The record at every decimation-th sample: the desired path's state (central differences on
// the full record), the payload, the joint error; runs of consecutive rows, one per segment.
struct DecimatedRecord {
  std::vector<calib::JointVector> q, qd, qdd, error;
  std::vector<double> payload_kg;
  std::vector<std::pair<std::size_t, std::size_t>> runs;
  // With payload_centre_free: payload_centre_columns (else empty).
  std::array<Torques, 3> payload_centre;
};

DecimatedRecord decimated(const ident::JointErrorLog& log, int decimation) {
  DecimatedRecord out;
  const double dt = log.cycle_s;
  for (const auto& [begin, end] : log.segments()) {
    const std::size_t first_row = out.q.size();
    for (std::size_t k = begin + 1; k + 1 < end; k += std::size_t(decimation)) {
      calib::JointVector q, qd, qdd, e;
      for (int j = 0; j < calib::kJointCount; ++j) {
        const auto& x = log.q_desired_rad[std::size_t(j)];
        q(j) = x[k];
        qd(j) = (x[k + 1] - x[k - 1]) / (2.0 * dt);
        qdd(j) = (x[k + 1] - 2.0 * x[k] + x[k - 1]) / (dt * dt);
        e(j) = log.q_measured_rad[std::size_t(j)][k] - x[k];
      }
      out.q.push_back(q);
      out.qd.push_back(qd);
      out.qdd.push_back(qdd);
      out.error.push_back(e);
      out.payload_kg.push_back(log.payload_kg[k]);
    }
    if (out.q.size() > first_row) out.runs.emplace_back(first_row, out.q.size());
  }
  return out;
}

Torques torques_of(const ModelTorqueSource& model, const DecimatedRecord& r) {
  PayloadDynamics dynamics(model);
  Torques out(r.q.size());
  for (std::size_t i = 0; i < r.q.size(); ++i)
    out[i] = dynamics.torque(r.payload_kg[i], r.q[i], r.qd[i], r.qdd[i]);
  return out;
}

// The record at rest in its poses (speeds and accelerations 0): its torques are gravity's.
DecimatedRecord at_rest(DecimatedRecord r) {
  for (auto* signal : {&r.qd, &r.qdd})
    for (calib::JointVector& v : *signal) v.setZero();
  return r;
}

// ∂τ/∂π_p [row] for every parameter: the torque is linear in a link's mass (its centre of
// mass and inertia fixed), so the mass's difference quotient is exact; 1 mm for the centre of
// mass (the parallel-axis term is quadratic in it). Gravity only (gravity_first_moments): the
// static torque's derivatives by the centres of mass, exact (gravity is linear in them), and
// zero columns for the masses, which then keep their nominal values.
std::vector<Torques> torque_jacobian(const ModelTorqueSource& nominal, const Parameters& p,
                                     const DecimatedRecord& moving, const Torques& at_p_moving,
                                     const MassRefinementOptions& o) {
  const DecimatedRecord rest = o.gravity_first_moments ? at_rest(moving) : DecimatedRecord{};
  const DecimatedRecord& r = o.gravity_first_moments ? rest : moving;
  const Torques at_p =
      o.gravity_first_moments ? torques_of(with_parameters(nominal, p), r) : at_p_moving;
  std::vector<Torques> out;
  for (int k = 0; k < kParameters; ++k) {
    if (o.gravity_first_moments && k % kPerLink == 0) {
      out.emplace_back(r.q.size(), calib::JointVector::Zero());
      continue;
    }
    const double step = k % kPerLink == 0 ? std::max(0.01 * p(k), 0.01) : 1e-3;
    Parameters moved = p;
    moved(k) += step;
    Torques t = torques_of(with_parameters(nominal, moved), r);
    for (std::size_t i = 0; i < t.size(); ++i) t[i] = (t[i] - at_p[i]) / step;
    out.push_back(std::move(t));
  }
  return out;
}

// The rows the ARX models use: those with their whole history inside their run.
std::vector<std::size_t> model_rows(const DecimatedRecord& r, const MassRefinementOptions& o) {
  const std::size_t history =
      std::size_t(std::max({o.error_lags, o.input_taps - 1, o.further_input_taps - 1}));
  std::vector<std::size_t> rows;
  const double slow = o.gravity_first_moments ? o.gravity_max_speed_rad_s : 0.0;
  const auto is_slow = [&](std::size_t i) {
    for (std::size_t l = 0; l <= history; ++l)
      if (r.qd[i - l].cwiseAbs().maxCoeff() >= slow) return false;
    return true;
  };
  for (const auto& [begin, end] : r.runs)
    for (std::size_t i = begin + history; i < end; ++i)
      if (!(slow > 0.0) || is_slow(i)) rows.push_back(i);
  return rows;
}

// One joint's ARX fit with the torque τ: its columns' orthonormal basis Q, the residual, its
// variance and the torque's coefficients.
struct JointFit {
  Eigen::MatrixXd basis;
  Eigen::VectorXd residual;
  Eigen::VectorXd torque_taps;
  double variance = 1.0;
};

// The residual's integrated correlation time in rows, 1 + 2 Σ ρ_k up to its first negative
// autocorrelation: the rows are that many times fewer independent ones, so the information the
// data give is that many times less than white residuals would give.
double correlation_time(const Eigen::VectorXd& r) {
  const double r0 = r.squaredNorm();
  if (!(r0 > 0.0)) return 1.0;
  double sum = 1.0;
  for (Eigen::Index lag = 1; lag < std::min<Eigen::Index>(r.size() / 4, 500); ++lag) {
    const double rho = r.head(r.size() - lag).dot(r.tail(r.size() - lag)) / r0;
    if (rho <= 0.0) break;
    sum += 2.0 * rho;
  }
  return sum;
}

// The static gravity torque's derivative by the payload's centre of mass along T's axes
// [N m / m], [axis][row] (zero on rows without payload); exact, gravity is linear in it.
std::array<Torques, 3> payload_centre_columns(const ModelTorqueSource& model,
                                              const DecimatedRecord& r) {
  sim::RigidBodyDynamics dynamics(model.robot, std::nullopt, model.gravity_in_base_m_s2);
  std::array<Torques, 3> out;
  for (auto& column : out) column.assign(r.q.size(), calib::JointVector::Zero());
  constexpr double kStepM = 0.01;
  for (std::size_t i = 0; i < r.q.size(); ++i) {
    if (!(r.payload_kg[i] > 0.0)) continue;
    calib::RigidBodyParameters payload;
    payload.mass_kg = r.payload_kg[i];
    dynamics.set_payload(payload);
    const calib::JointVector at_origin = dynamics.gravity_torque(r.q[i]);
    for (int a = 0; a < 3; ++a) {
      payload.com_m = kStepM * Eigen::Vector3d::Unit(a);
      dynamics.set_payload(payload);
      out[std::size_t(a)][i] = (dynamics.gravity_torque(r.q[i]) - at_origin) / kStepM;
    }
  }
  return out;
}

// The distinct payload masses of the rows (at most a few per program), positive ones only.
std::vector<double> payload_masses(const DecimatedRecord& r, const std::vector<std::size_t>& rows) {
  std::vector<double> masses;
  for (const std::size_t i : rows)
    if (r.payload_kg[i] > 0.0 && std::ranges::find(masses, r.payload_kg[i]) == masses.end())
      masses.push_back(r.payload_kg[i]);
  return masses;
}

// The taps the drive model gives a further input (0: not taken; the torque and the direction
// have their own columns).
int further_taps(ident::TableInput input, const MassRefinementOptions& o) {
  switch (input) {
    case ident::TableInput::kModelTorque:
    case ident::TableInput::kDirection:
      return 0;
    case ident::TableInput::kTorqueSign:
      return 1;
    default:
      return o.further_input_taps;
  }
}

// The further inputs' columns of joint j from column `first` on: each input's value at the
// row's sample and its earlier ones (the plain pairs, no gear mode).
void fill_further_columns(int j, const DecimatedRecord& r, const Torques& tau,
                          const std::vector<std::size_t>& rows, const MassRefinementOptions& o,
                          Eigen::MatrixXd& x, int first) {
  ident::ExogenousParameters p = o.further_parameters[std::size_t(j)];
  p.transmission_error_mode_rad_s = 0.0;
  int column = first;
  for (const ident::TableInput input : o.further_inputs) {
    const int taps = further_taps(input, o);
    for (int l = 0; l < taps; ++l, ++column)
      for (std::size_t n = 0; n < rows.size(); ++n) {
        const std::size_t i = rows[n] - std::size_t(l);
        x(Eigen::Index(n), column) =
            ident::exogenous_value(input, p, {r.q[i](j), r.qd[i](j), tau[i](j)});
      }
  }
}

// Joint j's payload-centre columns from column `first` on: three per payload mass of the rows.
void fill_payload_centre_columns(int j, const DecimatedRecord& r,
                                 const std::vector<std::size_t>& rows,
                                 const std::vector<double>& masses, Eigen::MatrixXd& x, int first) {
  for (std::size_t m = 0; m < masses.size(); ++m)
    for (std::size_t a = 0; a < 3; ++a)
      for (std::size_t n = 0; n < rows.size(); ++n) {
        const std::size_t i = rows[n];
        x(Eigen::Index(n), Eigen::Index(first + 3 * m + a)) =
            r.payload_kg[i] == masses[m] ? r.payload_centre[a][i](j) : 0.0;
      }
}

JointFit fit_joint(int j, const DecimatedRecord& r, const Torques& tau,
                   const std::vector<std::size_t>& rows, const MassRefinementOptions& o) {
  const int na = o.error_lags, nb = o.input_taps;
  int further = 0;
  for (const ident::TableInput input : o.further_inputs) further += further_taps(input, o);
  const std::vector<double> masses =
      r.payload_centre[0].empty() ? std::vector<double>{} : payload_masses(r, rows);
  const int columns = na + 2 * nb + 2 + further + 3 * int(masses.size());
  Eigen::MatrixXd x(Eigen::Index(rows.size()), columns);
  Eigen::VectorXd y(Eigen::Index(rows.size()));
  for (std::size_t n = 0; n < rows.size(); ++n) {
    const std::size_t i = rows[n];
    const auto row = Eigen::Index(n);
    y(row) = r.error[i](j);
    for (int l = 1; l <= na; ++l) x(row, l - 1) = -r.error[i - std::size_t(l)](j);
    for (int l = 0; l < nb; ++l) {
      x(row, na + l) = r.qd[i - std::size_t(l)](j);
      x(row, na + nb + l) = tau[i - std::size_t(l)](j);
    }
    x(row, na + 2 * nb) = std::tanh(r.qd[i](j) / o.direction_speed_scale_rad_s);
    x(row, na + 2 * nb + 1) = 1.0;
  }
  fill_further_columns(j, r, tau, rows, o, x, na + 2 * nb + 2);
  fill_payload_centre_columns(j, r, rows, masses, x, na + 2 * nb + 2 + further);
  // Columns scaled to unit RMS: torques [N m] and errors [rad] differ by ~1e8.
  const Eigen::VectorXd scale =
      (x.colwise().norm().array() / std::sqrt(double(rows.size()))).max(1e-300).matrix();
  const Eigen::MatrixXd scaled = x * scale.cwiseInverse().asDiagonal();
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(scaled);
  JointFit fit;
  fit.basis = qr.householderQ() * Eigen::MatrixXd::Identity(scaled.rows(), columns);
  fit.residual = y - fit.basis * (fit.basis.transpose() * y);
  const Eigen::VectorXd theta = qr.solve(y).cwiseQuotient(scale);
  fit.torque_taps = theta.segment(na + nb, nb);
  fit.variance = std::max(fit.residual.squaredNorm() / double(rows.size() - columns), 1e-300) *
                 correlation_time(fit.residual);
  return fit;
}

// The joint's columns Σ_l c_l ∂τ_j/∂π(i − l), its ARX columns projected out.
Eigen::MatrixXd projected_columns(int j, const JointFit& fit, const std::vector<Torques>& jac,
                                  const std::vector<std::size_t>& rows) {
  Eigen::MatrixXd z(Eigen::Index(rows.size()), kParameters);
  for (int p = 0; p < kParameters; ++p)
    for (std::size_t n = 0; n < rows.size(); ++n) {
      double sum = 0.0;
      for (Eigen::Index l = 0; l < fit.torque_taps.size(); ++l)
        sum += fit.torque_taps(l) * jac[std::size_t(p)][rows[n] - std::size_t(l)](j);
      z(Eigen::Index(n), p) = sum;
    }
  return z - fit.basis * (fit.basis.transpose() * z);
}

// Gravity only: the 1σ of link i's centre of mass [m] that covers its first moment's prior,
// its own centre of mass and mass, and the masses beyond it acting as its first moment over the
// DH offsets of its two joints (mass_prior_fraction of each).
double gravity_com_prior_m(const calib::RobotDescription& robot, int i,
                           const MassRefinementOptions& o) {
  const auto& joints = robot.joints;
  const double mass_kg = std::max(joints[std::size_t(i)].link.mass_kg, 1e-3);
  double beyond_kg = 0.0;
  for (std::size_t l = std::size_t(i) + 1; l < joints.size(); ++l)
    beyond_kg += joints[l].link.mass_kg;
  double lever_m = 0.0;
  for (std::size_t l = std::size_t(i); l <= std::size_t(i) + 1 && l < robot.kinematics.dh.size();
       ++l)
    lever_m += std::abs(robot.kinematics.dh[l].a_m) + std::abs(robot.kinematics.dh[l].d_m);
  const double own_m = joints[std::size_t(i)].link.com_m.norm();
  return o.com_prior_m + o.mass_prior_fraction * (own_m + beyond_kg / mass_kg * lever_m);
}

Parameters prior_precision(const calib::RobotDescription& robot, const Parameters& nominal,
                           const MassRefinementOptions& o) {
  Parameters precision;
  for (int k = 0; k < kParameters; ++k) {
    const int link = k / kPerLink;
    const double com_sigma_m =
        o.gravity_first_moments ? gravity_com_prior_m(robot, link, o) : o.com_prior_m;
    const double sigma =
        k % kPerLink == 0 ? std::max(o.mass_prior_fraction * nominal(k), 1e-3) : com_sigma_m;
    precision(k) = 1.0 / (sigma * sigma);
  }
  return precision;
}

// The data's information about π on a set of rows at π = p (the drive models fitted on those
// rows): the normal matrix Σ_j Z_jᵀ Z_j / w_j and the gradient Σ_j Z_jᵀ r_j / w_j, w_j the
// joint's residual variance times its correlation time.
struct Information {
  Matrix normal = Matrix::Zero();
  Parameters gradient = Parameters::Zero();
};

Information information(const DecimatedRecord& r, const Torques& tau,
                        const std::vector<Torques>& jac, const std::vector<std::size_t>& rows,
                        const MassRefinementOptions& o) {
  Information info;
  for (int j = 0; j < calib::kJointCount; ++j) {
    const JointFit fit = fit_joint(j, r, tau, rows, o);
    const Eigen::MatrixXd z = projected_columns(j, fit, jac, rows);
    info.normal += z.transpose() * z / fit.variance;
    info.gradient += z.transpose() * fit.residual / fit.variance;
  }
  return info;
}

// The Gauss–Newton step with the prior at the nominal values p0, over the parameters `free`
// (the others stay): δ = (N + P)⁻¹ (g − P (p − p0)) on the free block; its covariance there.
struct Step {
  Parameters delta = Parameters::Zero();
  Matrix covariance = Matrix::Zero();
};

Step prior_step(const Information& info, const Parameters& precision, const Parameters& p0,
                const Parameters& p, const std::array<bool, calib::kJointCount>& free) {
  std::vector<int> index;
  for (int k = 0; k < kParameters; ++k)
    if (free[std::size_t(k / kPerLink)]) index.push_back(k);
  Step step;
  if (index.empty()) return step;
  const auto n = Eigen::Index(index.size());
  Eigen::MatrixXd normal(n, n);
  Eigen::VectorXd gradient(n);
  for (Eigen::Index a = 0; a < n; ++a) {
    const int k = index[std::size_t(a)];
    gradient(a) = info.gradient(k) - precision(k) * (p(k) - p0(k));
    for (Eigen::Index b = 0; b < n; ++b) normal(a, b) = info.normal(k, index[std::size_t(b)]);
    normal(a, a) += precision(k);
  }
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(normal);
  const Eigen::VectorXd delta = ldlt.solve(gradient);
  const Eigen::MatrixXd covariance = ldlt.solve(Eigen::MatrixXd::Identity(n, n));
  for (Eigen::Index a = 0; a < n; ++a) {
    step.delta(index[std::size_t(a)]) = delta(a);
    for (Eigen::Index b = 0; b < n; ++b)
      step.covariance(index[std::size_t(a)], index[std::size_t(b)]) = covariance(a, b);
  }
  return step;
}

// The rows of one of two folds: blocks of `block_rows` consecutive rows, alternately.
std::vector<std::size_t> fold_rows(const std::vector<std::size_t>& rows, int fold, int block_rows) {
  std::vector<std::size_t> out;
  for (const std::size_t i : rows)
    if (int(i / std::size_t(std::max(block_rows, 1)) % 2) == fold) out.push_back(i);
  return out;
}

// Each link's held-out test (two folds, each link's step from one fold judged on the other, the
// other links as the fold's step leaves them): z = Σ g_hᵀδ / √(Σ δᵀ N_h δ), standard normal
// when the nominal link is right (g_h ~ N(0, N_h), independent of δ), and the held-out χ²
// change Σ (2 g_hᵀδ − δᵀ N_h δ), > 0 where the step improves the held-out fit.
struct HeldOutTest {
  std::array<double, calib::kJointCount> z{}, chi2_gain{};
};

HeldOutTest held_out_test(const DecimatedRecord& r, const Torques& tau,
                          const std::vector<Torques>& jac, const std::vector<std::size_t>& rows,
                          const Parameters& precision, const Parameters& p0,
                          const MassRefinementOptions& o) {
  std::array<Information, 2> fold;
  for (int f = 0; f < 2; ++f)
    fold[std::size_t(f)] = information(r, tau, jac, fold_rows(rows, f, o.held_out_block_rows), o);
  std::array<bool, calib::kJointCount> all{};
  all.fill(true);
  HeldOutTest test;
  std::array<double, calib::kJointCount> score{}, variance{};
  for (int f = 0; f < 2; ++f) {
    const Parameters delta = prior_step(fold[std::size_t(f)], precision, p0, p0, all).delta;
    const Information& held_out = fold[std::size_t(1 - f)];
    for (int i = 0; i < calib::kJointCount; ++i) {
      const auto d = delta.segment<kPerLink>(kPerLink * i);
      const double g = held_out.gradient.segment<kPerLink>(kPerLink * i).dot(d);
      const double v =
          d.dot(held_out.normal.block<kPerLink, kPerLink>(kPerLink * i, kPerLink * i) * d);
      score[std::size_t(i)] += g;
      variance[std::size_t(i)] += v;
      test.chi2_gain[std::size_t(i)] += 2.0 * g - v;
    }
  }
  for (std::size_t i = 0; i < score.size(); ++i)
    test.z[i] = variance[i] > 0.0 ? score[i] / std::sqrt(variance[i]) : 0.0;
  return test;
}

// The links the held-out test accepts: z above the one-sided normal quantile of the level
// divided among the links (Bonferroni), and a held-out χ² gain.
std::array<bool, calib::kJointCount> accepted_links(const HeldOutTest& test,
                                                    const MassRefinementOptions& o) {
  std::array<bool, calib::kJointCount> out{};
  for (std::size_t i = 0; i < out.size(); ++i)
    out[i] = !o.held_out_test || (test.z[i] > o.held_out_z && test.chi2_gain[i] > 0.0);
  return out;
}

// The torque-sign scale of each joint: the options' fraction of its RMS model torque.
MassRefinementOptions with_torque_sign_scales(MassRefinementOptions o, const Torques& tau) {
  for (int j = 0; j < calib::kJointCount; ++j) {
    double sum = 0.0;
    for (const calib::JointVector& t : tau) sum += t(j) * t(j);
    const double rms = std::sqrt(sum / double(std::max<std::size_t>(tau.size(), 1)));
    o.further_parameters[std::size_t(j)].torque_sign_scale_nm =
        std::max(o.torque_sign_scale_fraction * rms, 1e-9);
  }
  return o;
}

}  // namespace

MassRefinement refine_mass_parameters(const ident::JointErrorLog& log,
                                      const ModelTorqueSource& nominal,
                                      const MassRefinementOptions& given) {
  if (log.joint_count() != std::size_t(calib::kJointCount))
    throw std::invalid_argument("refine_mass_parameters: the record needs the robot's 6 joints");
  DecimatedRecord record = decimated(log, std::max(given.decimation, 1));
  if (given.gravity_first_moments && given.payload_centre_free)
    record.payload_centre = payload_centre_columns(nominal, record);
  const std::vector<std::size_t> rows = model_rows(record, given);
  if (rows.size() < std::size_t(10 * kParameters))
    throw std::invalid_argument("refine_mass_parameters: the record is too short");
  const Parameters p0 = parameters_of(nominal.robot);
  const Parameters precision = prior_precision(nominal.robot, p0, given);
  const Torques tau0 = torques_of(nominal, record);
  const MassRefinementOptions options = with_torque_sign_scales(given, tau0);
  const std::vector<Torques> jac0 = torque_jacobian(nominal, p0, record, tau0, options);
  MassRefinement out;
  const HeldOutTest test = held_out_test(record, tau0, jac0, rows, precision, p0, options);
  const std::array<bool, calib::kJointCount> accepted = accepted_links(test, options);
  std::array<bool, calib::kJointCount> all{};
  all.fill(true);
  // Every link's estimate with its 1σ (reported), and the accepted links' (used).
  const Information info = information(record, tau0, jac0, rows, options);
  const Step estimate = prior_step(info, precision, p0, p0, all);
  Parameters p = p0;
  Step step = prior_step(info, precision, p0, p, accepted);
  for (out.iterations = 1;; ++out.iterations) {
    p += step.delta;
    for (int i = 0; i < calib::kJointCount; ++i)  // a mass stays positive
      p(kPerLink * i) = std::max(p(kPerLink * i), 0.1 * p0(kPerLink * i));
    if (out.iterations >= std::max(options.iterations, 1)) break;
    const Torques tau = torques_of(with_parameters(nominal, p), record);
    step = prior_step(
        information(record, tau, torque_jacobian(nominal, p, record, tau, options), rows, options),
        precision, p0, p, accepted);
  }
  out.model = with_parameters(nominal, p);
  for (int i = 0; i < calib::kJointCount; ++i) {
    LinkMassEstimate& link = out.links[std::size_t(i)];
    const bool used = accepted[std::size_t(i)];
    const Parameters& value = used ? p : Parameters(p0 + estimate.delta);
    const Parameters sigma = (used ? step : estimate).covariance.diagonal().cwiseSqrt();
    link.refined = used;
    link.held_out_z = test.z[std::size_t(i)];
    link.nominal_mass_kg = p0(kPerLink * i);
    link.mass_kg = value(kPerLink * i);
    link.mass_sigma_kg = sigma(kPerLink * i);
    link.nominal_com_m = p0.segment<3>(kPerLink * i + 1);
    link.com_m = value.segment<3>(kPerLink * i + 1);
    link.com_sigma_m = sigma.segment<3>(kPerLink * i + 1);
  }
  return out;
}

std::vector<ident::LinkMassParameters> table_links(const MassRefinement& refinement) {
  std::vector<ident::LinkMassParameters> out;
  for (const LinkMassEstimate& l : refinement.links) {
    ident::LinkMassParameters t;
    t.refined = l.refined;
    t.held_out_z = l.held_out_z;
    t.nominal_mass_kg = l.nominal_mass_kg;
    t.mass_kg = l.mass_kg;
    t.mass_sigma_kg = l.mass_sigma_kg;
    for (int a = 0; a < 3; ++a) {
      t.nominal_com_m[std::size_t(a)] = l.nominal_com_m(a);
      t.com_m[std::size_t(a)] = l.com_m(a);
      t.com_sigma_m[std::size_t(a)] = l.com_sigma_m(a);
    }
    out.push_back(t);
  }
  return out;
}

std::string describe_link(const ident::LinkMassParameters& l) {
  return fmt::format(
      "{} (held-out z {:.2f}): mass {:.2f} ± {:.2f} kg (nominal {:.2f}), centre of mass [{:.3f} "
      "{:.3f} {:.3f}] ± [{:.3f} {:.3f} {:.3f}] m (nominal [{:.3f} {:.3f} {:.3f}])",
      l.refined ? "refined" : "nominal kept", l.held_out_z, l.mass_kg, l.mass_sigma_kg,
      l.nominal_mass_kg, l.com_m[0], l.com_m[1], l.com_m[2], l.com_sigma_m[0], l.com_sigma_m[1],
      l.com_sigma_m[2], l.nominal_com_m[0], l.nominal_com_m[1], l.nominal_com_m[2]);
}

}  // namespace imscal::eval
