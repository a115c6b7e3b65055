#include "eval/gap_signals.hpp"

#include <algorithm>
#include <cmath>
#include <span>
#include <stdexcept>

#include <Eigen/Geometry>
#include <Eigen/LU>

#include "core/parallel_tasks.hpp"
#include "core/units.hpp"
#include "ident/arx_model.hpp"
#include "ident/cell_blending.hpp"
#include "ident/operating_point.hpp"
#include "robot/forward_kinematics.hpp"
#include "robot/jacobian.hpp"
#include "sim/rigid_body_dynamics.hpp"

namespace imscal::eval {
namespace {

// Central differences within each run, one-sided at its ends; a one-sample run has 0.
std::vector<double> derivative(std::span<const double> x,
                               std::span<const std::pair<std::size_t, std::size_t>> runs,
                               double dt) {
  std::vector<double> d(x.size(), 0.0);
  for (const auto& [b, e] : runs) {
    if (e - b < 2) continue;
    d[b] = (x[b + 1] - x[b]) / dt;
    d[e - 1] = (x[e - 1] - x[e - 2]) / dt;
    for (std::size_t k = b + 1; k + 1 < e; ++k) d[k] = (x[k + 1] - x[k - 1]) / (2.0 * dt);
  }
  return d;
}

double operating_value(ident::OperatingQuantity q, double speed, double acceleration,
                       double position, double payload) {
  switch (q) {
    case ident::OperatingQuantity::kSpeed:
      return speed;
    case ident::OperatingQuantity::kAcceleration:
      return acceleration;
    case ident::OperatingQuantity::kPosition:
      return position;
    case ident::OperatingQuantity::kPayload:
      return payload;
  }
  return 0.0;
}

// A point mass at the tool frame origin (the joint errors log only the payload's mass).
calib::RigidBodyParameters point_mass(double mass_kg) {
  calib::RigidBodyParameters body;
  body.mass_kg = mass_kg;
  body.com_m.setZero();
  body.inertia_kg_m2.setZero();
  return body;
}

// Velocity scale of the smooth backlash sign [rad/s], as the precontrol's default.
constexpr double kBacklashVelocityScale = 0.002;

using Twist = Eigen::Matrix<double, 6, 1>;  // translation [m], rotation [rad]

// Body twist of a near-identity transform (first order).
Twist small_twist(const Eigen::Isometry3d& e) {
  const Eigen::Matrix3d& r = e.linear();
  Twist xi;
  xi << e.translation(), 0.5 * (r(2, 1) - r(1, 2)), 0.5 * (r(0, 2) - r(2, 0)),
      0.5 * (r(1, 0) - r(0, 1));
  return xi;
}

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

// Adjoint of T on body twists (translation first): xi in the frame after T -> before it.
Eigen::Matrix<double, 6, 6> adjoint(const Eigen::Isometry3d& t) {
  Eigen::Matrix<double, 6, 6> a = Eigen::Matrix<double, 6, 6>::Zero();
  a.topLeftCorner<3, 3>() = t.linear();
  a.topRightCorner<3, 3>() = skew(t.translation()) * t.linear();
  a.bottomRightCorner<3, 3>() = t.linear();
  return a;
}

// Damping of the body Jacobian's inverse [m or rad]: far below any regular singular value of an
// industrial arm (~0.1 m .. 1), it only keeps the map finite at a wrist singularity.
constexpr double kJacobianDamping = 1e-3;

// The body Jacobian (flange axes, translation first) from the geometric one and the flange's
// attitude R = R_R_H.
Eigen::Matrix<double, 6, 6> body_jacobian(const calib::Jacobian& jg, const Eigen::Matrix3d& R) {
  Eigen::Matrix<double, 6, 6> jb;
  jb.topRows<3>() = R.transpose() * jg.topRows<3>();
  jb.bottomRows<3>() = R.transpose() * jg.bottomRows<3>();
  return jb;
}

// Damped least-squares inverse Jb^T (Jb Jb^T + λ² I)^-1.
Eigen::Matrix<double, 6, 6> damped_inverse(const Eigen::Matrix<double, 6, 6>& jb) {
  return jb.transpose() * (jb * jb.transpose() + kJacobianDamping * kJacobianDamping *
                                                     Eigen::Matrix<double, 6, 6>::Identity())
                              .inverse();
}

// Central-difference step of the DH numbers [m, rad]: truncation ~step² far below the 1e-6
// relative accuracy the fit needs, rounding ~1e-16 / step harmless.
constexpr double kDhStep = 1e-6;

// DH sensitivities at joint angles q (chain poses `poses`, flange T): a change of link i's numbers
// is a local twist xi_l after link frame i+1 (central differences of the link transform alone),
// moved to the flange by the adjoint. The perturbed numbers are a +- da etc. with da = 0 for the
// others, as written (alpha + 0 and alpha - 0 differ in the sign of a zero alpha). A sample's
// seven transforms of a link share their trigonometry (calib::dh_link_transform of cos and sin).
Eigen::Matrix<double, 6, 18> dh_twists(const calib::KinematicModel& kin,
                                       const calib::JointVector& q,
                                       const calib::ChainPoses<double>& poses,
                                       const Eigen::Isometry3d& T) {
  Eigen::Matrix<double, 6, 18> dh_twist;
  for (int i = 0; i < 6; ++i) {
    const calib::DhParameters& dh = kin.dh[i];
    using calib::cos_sin;
    const calib::CosSin<double> theta = cos_sin(q[i] + dh.offset_rad);
    const calib::CosSin<double> alpha_plus = cos_sin(dh.alpha_rad + 0.0),
                                alpha_minus = cos_sin(dh.alpha_rad - 0.0);
    const calib::CosSin<double> alpha_stepped[2] = {cos_sin(dh.alpha_rad + kDhStep),
                                                    cos_sin(dh.alpha_rad - kDhStep)};
    const Eigen::Isometry3d a_inv =
        calib::dh_link_transform(kin.convention, dh.a_m, alpha_minus, dh.d_m, theta).inverse();
    const Eigen::Isometry3d T_next_H = poses.T_R_link[std::size_t(i) + 1].inverse() * T;
    const Eigen::Matrix<double, 6, 6> to_flange = adjoint(T_next_H.inverse());
    for (int p = 0; p < 3; ++p) {
      const double da = p == 0 ? kDhStep : 0.0, dd = p == 2 ? kDhStep : 0.0;
      const Eigen::Isometry3d plus = calib::dh_link_transform(
          kin.convention, dh.a_m + da, p == 1 ? alpha_stepped[0] : alpha_plus, dh.d_m + dd, theta);
      const Eigen::Isometry3d minus = calib::dh_link_transform(
          kin.convention, dh.a_m - da, p == 1 ? alpha_stepped[1] : alpha_minus, dh.d_m - dd, theta);
      const Twist local =
          (small_twist(a_inv * plus) - small_twist(a_inv * minus)) / (2.0 * kDhStep);
      dh_twist.col(3 * i + p) = to_flange * local;
    }
  }
  return dh_twist;
}

// The joint angles and rates along which the chain's columns are formed.
struct ChainInputs {
  const calib::KinematicModel& kin;
  const std::vector<std::vector<double>>& q_rad;
  const std::vector<std::vector<double>>& qd_rad_s;
  const std::vector<double>& time_s;

  calib::JointVector joints_at(std::size_t k, const std::vector<std::vector<double>>& x) const {
    calib::JointVector v;
    for (std::size_t j = 0; j < std::size_t(calib::kJointCount); ++j) v[long(j)] = x[j][k];
    return v;
  }
};

// Where the chain starts: the flange pose and body Jacobian at the first sample.
struct ChainStart {
  Eigen::Isometry3d T_R_H0;
  Eigen::Matrix<double, 6, 6> jb0;
};

// What the gyro's integrals need of a sample: the rates of the attitude error per unit bias and
// scale error (base frame) and the gap per unit body twist.
struct ChainRates {
  Eigen::Matrix3d bias_rate, scale_rate;
  Eigen::Matrix<double, 6, 6> gap_per_twist;
};

// Sample k's rows of every column except the gyro's (those integrate over the earlier samples:
// fill_gyro_integral_columns, from `rates`).
void fill_chain_sample(const ChainInputs& in, const ChainStart& start, std::size_t k,
                       std::vector<GapSignals::ImsChainColumns>& out, ChainRates& rates) {
  const calib::JointVector q = in.joints_at(k, in.q_rad), qd = in.joints_at(k, in.qd_rad_s);
  const calib::ChainPoses<double> poses = calib::chain_poses<double>(in.kin, q);
  const Eigen::Isometry3d T = poses.T_R_H;
  const Eigen::Matrix3d& R = T.linear();
  const calib::Jacobian jg = calib::geometric_jacobian(poses);
  // The gap per unit body twist of the flange pose error: -(q_m - q).
  const Eigen::Matrix<double, 6, 6> gap_per_twist = -damped_inverse(body_jacobian(jg, R));
  const Eigen::Matrix<double, 6, 6> mounting_twist =
      adjoint((start.T_R_H0.inverse() * T).inverse()) - Eigen::Matrix<double, 6, 6>::Identity();
  Twist accel_twist = Twist::Zero();
  accel_twist.head<3>() = R.transpose() * (T.translation() - start.T_R_H0.translation());

  // The start pose: the chain starts its smoothing at the first sample's pose from that rest's
  // estimated joint angles q0 + dq0, and the IMS measures only the motion from there, so every
  // later flange pose carries the same base-frame error D = T(q0 + dq0) T(q0)^-1; in the flange
  // at time t that is the body twist Ad(T(t)^-1 T(q0)) Jb(q0) dq0, which the inverse kinematics
  // turns into the gap -Jb(q(t))^-1 of it (-dq0 at the start).
  const Eigen::Matrix<double, 6, 6> start_gap =
      gap_per_twist * adjoint(T.inverse() * start.T_R_H0) * start.jb0;
  const Eigen::Matrix<double, 6, 18> dh_gap = gap_per_twist * dh_twists(in.kin, q, poses, T);
  const Eigen::Matrix<double, 6, 6> mounting_gap = gap_per_twist * mounting_twist;
  const Twist accel_gap = gap_per_twist * accel_twist;
  const Eigen::Matrix<double, 6, 3> world_gap =
      gap_per_twist.rightCols<3>() * R.transpose() * (in.time_s[k] - in.time_s[0]);
  const Eigen::Index row = Eigen::Index(k);
  for (std::size_t j = 0; j < out.size(); ++j) {
    const Eigen::Index jr = Eigen::Index(j);
    out[j].dh.row(row) = dh_gap.row(jr);
    out[j].mounting.row(row) = mounting_gap.row(jr);
    out[j].accel_scale(row, 0) = accel_gap[jr];
    out[j].world_rate.row(row) = world_gap.row(jr);
    out[j].start_pose.row(row) = start_gap.row(jr);
  }
  const Eigen::Vector3d w_body = R.transpose() * (jg.bottomRows<3>() * qd);
  rates.bias_rate = R;  // column i: R e_i
  rates.scale_rate = R * w_body.asDiagonal();
  rates.gap_per_twist = gap_per_twist;
}

// The gyro bias and scale columns: attitude error integrals (trapezoid over the sample times,
// base frame) of the rates, in sample order.
void fill_gyro_integral_columns(const std::vector<double>& time_s,
                                const std::vector<ChainRates>& rates,
                                std::vector<GapSignals::ImsChainColumns>& out) {
  Eigen::Matrix3d bias_integral = Eigen::Matrix3d::Zero(), scale_integral = bias_integral;
  for (std::size_t k = 0; k < rates.size(); ++k) {
    const ChainRates& r = rates[k];
    if (k > 0) {
      const double dt = time_s[k] - time_s[k - 1];
      bias_integral += 0.5 * dt * (r.bias_rate + rates[k - 1].bias_rate);
      scale_integral += 0.5 * dt * (r.scale_rate + rates[k - 1].scale_rate);
    }
    const Eigen::Matrix3d& R = r.bias_rate;
    Eigen::Matrix<double, 6, 3> bias_twist = Eigen::Matrix<double, 6, 3>::Zero(),
                                scale_twist = bias_twist;
    bias_twist.bottomRows<3>() = R.transpose() * bias_integral;
    scale_twist.bottomRows<3>() = R.transpose() * scale_integral;
    const Eigen::Matrix<double, 6, 3> bias_gap = r.gap_per_twist * bias_twist;
    const Eigen::Matrix<double, 6, 3> scale_gap = r.gap_per_twist * scale_twist;
    for (std::size_t j = 0; j < out.size(); ++j) {
      out[j].gyro_bias.row(Eigen::Index(k)) = bias_gap.row(Eigen::Index(j));
      out[j].gyro_scale.row(Eigen::Index(k)) = scale_gap.row(Eigen::Index(j));
    }
  }
}

// The arm with the logged payload, with 1 kg at the tool origin and bare.
struct PayloadDynamics {
  sim::RigidBodyDynamics *logged, *unit, *bare;
};

// The rigid-body torque and the unit payload's torque along the drive's actual motion (q_internal
// and its derivatives) at sample k.
void set_actual_motion_torques(GapSignals& g, const std::vector<std::vector<double>>& qdd_internal,
                               std::size_t k, const PayloadDynamics& d) {
  calib::JointVector qi, qdi, qddi;
  for (std::size_t j = 0; j < g.joint_count(); ++j) {
    qi[long(j)] = g.q_internal_rad[j][k];
    qdi[long(j)] = g.qd_internal_rad_s[j][k];
    qddi[long(j)] = qdd_internal[j][k];
  }
  const calib::JointVector tau = d.logged->inverse_dynamics(qi, qdi, qddi);
  const calib::JointVector tau_unit =
      d.unit->inverse_dynamics(qi, qdi, qddi) - d.bare->inverse_dynamics(qi, qdi, qddi);
  for (std::size_t j = 0; j < g.joint_count(); ++j) {
    g.torque_internal_nm[j][k] = tau[long(j)];
    g.unit_payload_internal_nm_kg[j][k] = tau_unit[long(j)];
  }
}

// Torques of the desired motion at samples [begin, end): the logged payload as a point mass at
// the tool origin (the log has no centre of mass); the unit-payload torque is the change for 1 kg
// more; the mass matrix; and the actual motion's torques where the drive's motion is known. Each
// block has its own dynamics, so blocks are independent.
void fill_model_torques(GapSignals& g, const std::vector<double>& payload_kg,
                        const calib::RobotDescription& robot,
                        const std::vector<std::vector<double>>& qdd_internal, std::size_t begin,
                        std::size_t end) {
  const std::size_t nj = g.joint_count();
  const bool internal = !g.torque_internal_nm.empty();
  const Eigen::Vector3d gravity(0.0, 0.0, -kStandardGravity_m_s2);
  sim::RigidBodyDynamics dynamics(robot, std::nullopt, gravity);
  sim::RigidBodyDynamics unit(robot, point_mass(1.0), gravity);
  sim::RigidBodyDynamics bare(robot, std::nullopt, gravity);
  double current_mass = 0.0;
  for (std::size_t k = begin; k < end; ++k) {
    if (payload_kg[k] != current_mass) {
      current_mass = payload_kg[k];
      dynamics.set_payload(current_mass > 0.0 ? std::optional(point_mass(current_mass))
                                              : std::nullopt);
    }
    calib::JointVector q, qd, qdd;
    for (std::size_t j = 0; j < nj; ++j) {
      q[long(j)] = g.q_desired_rad[j][k];
      qd[long(j)] = g.qd_desired_rad_s[j][k];
      qdd[long(j)] = g.qdd_desired_rad_s2[j][k];
    }
    const calib::JointVector tau = dynamics.inverse_dynamics(q, qd, qdd);
    if (internal) set_actual_motion_torques(g, qdd_internal, k, {&dynamics, &unit, &bare});
    const calib::JointVector tau_gravity = dynamics.gravity_torque(q);
    const sim::JointMatrix mass = dynamics.mass_matrix(q);
    for (std::size_t i = 0; i < nj; ++i)
      for (std::size_t j = 0; j < nj; ++j)
        g.mass_matrix_kg_m2[i * nj + j][k] = mass(long(i), long(j));
    const calib::JointVector tau_unit =
        unit.inverse_dynamics(q, qd, qdd) - bare.inverse_dynamics(q, qd, qdd);
    for (std::size_t j = 0; j < nj; ++j) {
      g.torque_nm[j][k] = tau[long(j)];
      g.gravity_torque_nm[j][k] = tau_gravity[long(j)];
      g.unit_payload_nm_kg[j][k] = tau_unit[long(j)];
    }
  }
}

}  // namespace

std::vector<GapSignals::ImsChainColumns> ims_chain_columns(
    const calib::KinematicModel& kin, const std::vector<std::vector<double>>& q_rad,
    const std::vector<std::vector<double>>& qd_rad_s, const std::vector<double>& time_s) {
  const std::size_t n = time_s.size(), nj = calib::kJointCount;
  std::vector<GapSignals::ImsChainColumns> out(nj);
  for (auto& c : out) {
    c.dh.setZero(Eigen::Index(n), 18);
    c.mounting.setZero(Eigen::Index(n), 6);
    c.gyro_bias.setZero(Eigen::Index(n), 3);
    c.gyro_scale.setZero(Eigen::Index(n), 3);
    c.accel_scale.setZero(Eigen::Index(n), 1);
    c.world_rate.setZero(Eigen::Index(n), 3);
  }
  if (n == 0) return out;
  for (auto& c : out) c.start_pose.setZero(Eigen::Index(n), 6);
  const ChainInputs in{kin, q_rad, qd_rad_s, time_s};
  ChainStart start;
  start.T_R_H0 = calib::forward_kinematics<double>(kin, in.joints_at(0, q_rad));
  start.jb0 =
      body_jacobian(calib::geometric_jacobian(kin, in.joints_at(0, q_rad)), start.T_R_H0.linear());
  // Blocks of samples are independent tasks on the cores (core/parallel_tasks.hpp); the gyro
  // integrals run over all samples afterwards, in sample order.
  std::vector<ChainRates> rates(n);
  constexpr std::size_t kBlock = 4096;
  run_parallel_tasks((n + kBlock - 1) / kBlock, [&](std::size_t b) {
    for (std::size_t k = b * kBlock; k < std::min(n, (b + 1) * kBlock); ++k)
      fill_chain_sample(in, start, k, out, rates[k]);
  });
  fill_gyro_integral_columns(time_s, rates, out);
  return out;
}

std::vector<std::vector<double>> measured_joint_errors(const ident::JointErrorLog& log) {
  std::vector<std::vector<double>> e(log.joint_count());
  for (std::size_t j = 0; j < log.joint_count(); ++j) {
    e[j].resize(log.sample_count());
    for (std::size_t k = 0; k < log.sample_count(); ++k)
      e[j][k] = log.q_desired_rad[j][k] - log.q_measured_rad[j][k];
  }
  return e;
}

std::vector<std::vector<double>> predict_table_joint_errors(const ident::ParameterTable& table,
                                                            const ident::JointErrorLog& log) {
  if (table.joints.size() != log.joint_count())
    throw std::invalid_argument("parameter table has " + std::to_string(table.joints.size()) +
                                " joints, the joint errors " + std::to_string(log.joint_count()));
  if (table.model_form != ident::TableForm::kForward || !table.extra_inputs.empty())
    throw std::invalid_argument(
        "the parameter table is not a single-input forward error model (an inverse-form or "
        "multi-input table does not predict the joint error from q_d alone); use the forward "
        "table `imscal identify` writes beside it, forward_parameters.json");
  const auto runs = log.segments();
  const std::size_t n = log.sample_count();
  std::vector<std::vector<double>> out(log.joint_count(), std::vector<double>(n, 0.0));
  for (std::size_t j = 0; j < log.joint_count(); ++j) {
    const ident::JointParameters& jp = table.joints[j];
    if (jp.name != log.joint_names[j])
      throw std::invalid_argument("parameter table joint '" + jp.name +
                                  "' where the joint errors have '" + log.joint_names[j] + "'");
    const std::vector<double>& qd = log.q_desired_rad[j];
    const ident::OperatingSignals ops = ident::operating_signals(qd, runs, log.cycle_s);
    const std::vector<double> velocity = derivative(qd, runs, log.cycle_s);
    // Every cell's free-run error on the whole log (runs restart from the model's own rest state).
    std::vector<std::vector<double>> cell_error(jp.cells.size(), std::vector<double>(n, 0.0));
    for (std::size_t c = 0; c < jp.cells.size(); ++c) {
      const ident::ArxModel model = jp.cells[c].model(table.sample_time_s);
      const std::size_t lag = std::size_t(model.structure().max_lag());
      const double gain = model.static_gain();
      for (const auto& [b, e] : runs) {
        if (e - b <= lag) continue;
        // At rest before the run the model's output is its steady state G * q_d(start).
        std::vector<double> initial(std::max<std::size_t>(lag, 1),
                                    std::isfinite(gain) ? gain * qd[b] : qd[b]);
        std::span<const double> input(qd.data() + b, e - b);
        std::span<double> err(cell_error[c].data() + b, e - b);
        model.predict_joint_error(input, initial, err);
      }
    }
    // Blend by the operating point (cell centres per dimension).
    std::vector<std::vector<double>> centres;
    for (const auto& dim : jp.dimensions) centres.push_back(dim.centres());
    std::vector<std::span<const double>> centre_spans(centres.begin(), centres.end());
    std::vector<double> point(jp.dimensions.size());
    const long lag = long(jp.backlash_lag_samples);
    for (std::size_t k = 0; k < n; ++k) {
      for (std::size_t d = 0; d < jp.dimensions.size(); ++d)
        point[d] = operating_value(jp.dimensions[d].quantity, ops.speed_rad_s[k],
                                   ops.acceleration_rad_s2[k], qd[k], log.payload_kg[k]);
      const ident::CellBlend blend = ident::blend_cells(centre_spans, point);
      double v = 0.0;
      for (int c = 0; c < blend.count; ++c)
        v += blend.weight[std::size_t(c)] * cell_error[std::size_t(blend.cell[std::size_t(c)])][k];
      const long kl = std::max(0L, long(k) - lag);
      v += jp.backlash_l_rad * std::tanh(velocity[std::size_t(kl)] / kBacklashVelocityScale);
      out[j][k] = v;
    }
  }
  return out;
}

GapSignals make_gap_signals(const ident::JointErrorLog& real,
                            const std::vector<std::vector<double>>& sim_joint_error_rad,
                            const calib::RobotDescription& robot,
                            const ident::ParameterTable* table_or_null) {
  const std::size_t nj = real.joint_count(), n = real.sample_count();
  if (nj != calib::kJointCount)
    throw std::invalid_argument("the joint errors have " + std::to_string(nj) +
                                " joints, the robot " + std::to_string(calib::kJointCount));
  for (std::size_t j = 0; j < nj; ++j)
    if (robot.joints[j].name != real.joint_names[j])
      throw std::invalid_argument("joint " + std::to_string(j + 1) + " is '" + real.joint_names[j] +
                                  "' in the joint errors but '" + robot.joints[j].name +
                                  "' in the robot " + robot.name);
  if (sim_joint_error_rad.size() != nj)
    throw std::invalid_argument("sim joint errors: wrong joint count");
  for (const auto& s : sim_joint_error_rad)
    if (s.size() != n) throw std::invalid_argument("sim joint errors: wrong sample count");

  GapSignals g;
  g.cycle_s = real.cycle_s;
  g.joint_names = real.joint_names;
  g.time_s = real.time_s;
  g.payload_kg = real.payload_kg;
  g.runs = real.segments();
  g.q_desired_rad = real.q_desired_rad;
  // Without the encoders' q_internal the drive's actual motion stays unknown (empty): the
  // candidates then take the desired motion, and the transmission error is not tried.
  const bool internal = real.has_q_internal();
  g.q_internal_rad = real.q_internal_rad;
  g.gap_rad.assign(nj, std::vector<double>(n));
  for (std::size_t j = 0; j < nj; ++j) {
    g.qd_desired_rad_s.push_back(derivative(real.q_desired_rad[j], g.runs, g.cycle_s));
    g.qdd_desired_rad_s2.push_back(derivative(g.qd_desired_rad_s[j], g.runs, g.cycle_s));
    for (std::size_t k = 0; k < n; ++k)
      g.gap_rad[j][k] =
          real.q_desired_rad[j][k] - real.q_measured_rad[j][k] - sim_joint_error_rad[j][k];
    if (internal)
      g.qd_internal_rad_s.push_back(derivative(real.q_internal_rad[j], g.runs, g.cycle_s));
    g.gear_ratio.push_back(robot.joints[j].drive.gear_ratio);
    g.max_speed_rad_s.push_back(robot.joints[j].max_velocity_rad_s);
    const auto& drive = robot.joints[j].drive;
    g.nominal_compliance_rad_per_nm.push_back(
        drive.stiffness_nm_per_rad > 0.0 ? 1.0 / drive.stiffness_nm_per_rad : 0.0);
    g.nominal_half_play_rad.push_back(0.5 * drive.backlash_rad);
    g.nominal_coulomb_nm.push_back(drive.coulomb_nm);
  }
  g.torque_nm.assign(nj, std::vector<double>(n));
  g.gravity_torque_nm.assign(nj, std::vector<double>(n));
  g.unit_payload_nm_kg.assign(nj, std::vector<double>(n));
  if (internal) {
    g.torque_internal_nm.assign(nj, std::vector<double>(n));
    g.unit_payload_internal_nm_kg.assign(nj, std::vector<double>(n));
  }
  g.mass_matrix_kg_m2.assign(nj * nj, std::vector<double>(n));
  std::vector<std::vector<double>> qdd_internal;
  for (const auto& qd_internal : g.qd_internal_rad_s)
    qdd_internal.push_back(derivative(qd_internal, g.runs, g.cycle_s));
  // Blocks of samples are independent tasks on the cores (core/parallel_tasks.hpp).
  constexpr std::size_t kBlock = 4096;
  run_parallel_tasks((n + kBlock - 1) / kBlock, [&](std::size_t b) {
    fill_model_torques(g, real.payload_kg, robot, qdd_internal, b * kBlock,
                       std::min(n, (b + 1) * kBlock));
  });
  g.ims_chain_columns =
      ims_chain_columns(robot.kinematics, g.q_desired_rad, g.qd_desired_rad_s, g.time_s);
  if (table_or_null) {
    for (const auto& jp : table_or_null->joints) {
      g.table_dimensions.push_back(jp.dimensions);
      std::vector<bool> identified;
      for (const auto& c : jp.cells)
        identified.push_back(c.status == ident::CellStatus::kIdentified);
      g.table_cell_identified.push_back(identified);
    }
  }
  return g;
}

}  // namespace imscal::eval
