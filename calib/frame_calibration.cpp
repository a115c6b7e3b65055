// The frame-and-bias bundle (calib/frame_calibration.hpp). Design decisions:
//  - Unknowns: q_W_R, q_S_H (quaternions, left perturbation), p_S_H, b_g, b_a (per rest when it
//    drifts, ImuNoiseModel::acc_bias_drift_psd), dt with the link share, optional
//    scale factors, dq_i per rest (joints with prior sigma 0 held by a SubsetManifold). W's
//    origin is the sensor at the first rest: p_W_R is derived (never a parameter), and the
//    motion residuals only use position differences, so it needs no residual of its own.
//  - Residuals (calib/frame_residuals.hpp): rest means (6), motions (9, closed-form Brownian
//    covariance with the gravity cross terms, calib/frame_noise.hpp), gyro rate in windows
//    during motion (3 per window, for dt), joint-deviation priors. Scale factors enter only the
//    rests (where 100 ppm of g is 1e-3 m/s^2); the motions take the sensor's scale as exact.
//  - The rate windows carry dt alone (R_S_H, b_g from the previous solution; see RateResidual).
//  - Two solves: the first with a guessed rate-window sigma (1e-3 rad/s); then the window
//    sigma is set to the RMS of the first solve's rate residuals (model error of the joint
//    rates; windows ~independent), the preintegrations are re-linearised at the estimated biases
//    and the Earth rate of every window is taken from the first solution; the second solve gives
//    the result and its covariance.
//  - Huber loss per block with scale huber_scale_sigma * sqrt(block dimension), so that a block
//    at its expected chi-square is not down-weighted.
#include "calib/frame_calibration.hpp"

#include <ceres/ceres.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <tuple>

#include "calib/forward_kinematics.hpp"
#include "calib/frame_covariance.hpp"
#include "calib/frame_initialisation.hpp"
#include "calib/frame_measurements.hpp"
#include "calib/frame_noise.hpp"
#include "calib/frame_residuals.hpp"
#include "calib/jacobian.hpp"
#include "core/input_error.hpp"

namespace imscal::calib {
namespace {

constexpr double kDegPerRad = 180.0 / M_PI;
constexpr double kStandardGravity = 9.80665;

struct Parameters {
  double q_W_R[4] = {0, 0, 0, 1};  // Eigen order x, y, z, w
  double q_S_H[4] = {0, 0, 0, 1};
  double p_S_H[3] = {0, 0, 0};
  double b_g[3] = {0, 0, 0};
  // Accelerometer bias per rest (one shared block without drift: b_a_blocks all point to it).
  std::vector<std::array<double, 3>> b_a;
  std::vector<double*> b_a_blocks;
  double dt[1] = {0};
  double link_share[1] = {0};
  double s_g[3] = {0, 0, 0};
  double s_a[3] = {0, 0, 0};
  double m_w[6] = {0, 0, 0, 0, 0, 0};  // 1 - k_w (estimate_deflection_scale)
  double m_p[6] = {0, 0, 0, 0, 0, 0};  // 1 - k_p
  std::vector<std::array<double, 6>> dq;
  const std::vector<RestObservation>* rests = nullptr;

  Eigen::Matrix3d R_W_R() const {
    return Eigen::Map<const Eigen::Quaterniond>(q_W_R).toRotationMatrix();
  }
  Eigen::Matrix3d R_S_H() const {
    return Eigen::Map<const Eigen::Quaterniond>(q_S_H).toRotationMatrix();
  }
  ImuBiases biases() const {
    ImuBiases b;
    b.gyro_rad_s = Eigen::Map<const Eigen::Vector3d>(b_g);
    b.acc_m_s2 = Eigen::Map<const Eigen::Vector3d>(b_a_blocks.front());
    return b;
  }
  // dq_i plus the scaled wind-up and play of rest i.
  JointVector joint_deviation(std::size_t i) const {
    const RestObservation& r = (*rests)[i];
    return rest_deviation<double>(dq[i].data(), m_w, m_p, r.q_windup_rad, r.q_play_rad);
  }
};

void set_quaternion(double* q, const Eigen::Matrix3d& R) {
  const Eigen::Quaterniond quaternion = Eigen::Quaterniond(R).normalized();
  Eigen::Map<Eigen::Quaterniond> out(q);
  out = quaternion;
}

// The sensor's velocity in R at joint angles q and rates q_dot, for the sensor at p_H_S [m/s].
Eigen::Vector3d sensor_velocity_R(const KinematicModel& model, const JointVector& q,
                                  const JointVector& q_dot, const Eigen::Vector3d& p_H_S) {
  const Jacobian J = geometric_jacobian(model, q);
  const Eigen::Vector3d omega_R = J.bottomRows<3>() * q_dot;
  const Eigen::Matrix3d R_R_H = forward_kinematics<double>(model, q).linear();
  return J.topRows<3>() * q_dot + omega_R.cross(R_R_H * p_H_S);
}

// What a rest's creep (RestObservation::q_creep_*, q_rate_*) means for the sensor.
struct RestCreep {
  Eigen::Vector3d mean_rate_H = Eigen::Vector3d::Zero();          // [rad/s]
  Eigen::Vector3d mean_acceleration_R = Eigen::Vector3d::Zero();  // [m/s^2]
  Eigen::Vector3d velocity_begin_R = Eigen::Vector3d::Zero();     // [m/s]
  Eigen::Vector3d velocity_end_R = Eigen::Vector3d::Zero();
};

RestCreep rest_creep(const KinematicModel& model, const RestObservation& rest, double duration_s,
                     const Eigen::Vector3d& p_H_S) {
  RestCreep c;
  const JointVector q_begin = rest.q_link_rad + rest.q_creep_begin_rad;
  const JointVector q_end = rest.q_link_rad + rest.q_creep_end_rad;
  const Eigen::Matrix3d R_begin = forward_kinematics<double>(model, q_begin).linear();
  const Eigen::Matrix3d R_end = forward_kinematics<double>(model, q_end).linear();
  c.mean_rate_H =
      ims::quat_log<double>(Eigen::Quaterniond(R_begin.transpose() * R_end)) / duration_s;
  c.velocity_begin_R = sensor_velocity_R(model, q_begin, rest.q_rate_begin_rad_s, p_H_S);
  c.velocity_end_R = sensor_velocity_R(model, q_end, rest.q_rate_end_rad_s, p_H_S);
  c.mean_acceleration_R = (c.velocity_end_R - c.velocity_begin_R) / duration_s;
  return c;
}

// omega_H(t) and lag_H(t) (calib/frame_residuals.hpp, RateResidual) on a uniform robot-time
// grid, from the joint readings (central differences).
struct FlangeRateGrid {
  double t0_s = 0.0;
  double step_s = 1.0;
  std::vector<double> values;  // 6 per node
  std::unique_ptr<ceres::Grid1D<double, 6>> grid;
  std::unique_ptr<RateResidual::Interpolator> interpolator;
  double t_end_s() const { return t0_s + step_s * static_cast<double>(values.size() / 6 - 1); }
};

std::unique_ptr<FlangeRateGrid> make_flange_rate_grid(const KinematicModel& model,
                                                      const RobotJointSeries& robot,
                                                      const std::string& source) {
  const std::size_t n = robot.t_robot_s.size();
  if (n != robot.q_rad.size()) {
    throw InputError(source, 0, "robot",
                     fmt::format("{} robot times but {} joint samples", n, robot.q_rad.size()));
  }
  if (n < 4) throw InputError(source, 0, "robot", "fewer than 4 robot joint samples");
  std::vector<double> steps;
  for (std::size_t k = 1; k < n; ++k) {
    const double h = robot.t_robot_s[k] - robot.t_robot_s[k - 1];
    if (!(h > 0.0)) throw InputError(source, 0, "robot.t_robot_s", "robot time does not increase");
    steps.push_back(h);
  }
  std::nth_element(steps.begin(), steps.begin() + steps.size() / 2, steps.end());
  auto out = std::make_unique<FlangeRateGrid>();
  out->t0_s = robot.t_robot_s.front();
  out->step_s = steps[steps.size() / 2];
  const std::size_t nodes =
      static_cast<std::size_t>(std::floor((robot.t_robot_s.back() - out->t0_s) / out->step_s)) + 1;
  // Joint angles on the uniform grid (linear interpolation; identity for a uniform series).
  std::vector<JointVector> q(nodes);
  std::size_t j = 0;
  for (std::size_t k = 0; k < nodes; ++k) {
    const double t = out->t0_s + out->step_s * static_cast<double>(k);
    while (j + 2 < n && robot.t_robot_s[j + 1] < t) ++j;
    const double a = std::clamp(
        (t - robot.t_robot_s[j]) / (robot.t_robot_s[j + 1] - robot.t_robot_s[j]), 0.0, 1.0);
    q[k] = (1.0 - a) * robot.q_rad[j] + a * robot.q_rad[j + 1];
  }
  out->values.assign(6 * nodes, 0.0);
  for (std::size_t k = 0; k < nodes; ++k) {
    const std::size_t lo = k == 0 ? 0 : k - 1;
    const std::size_t hi = k + 1 == nodes ? k : k + 1;
    const JointVector q_dot = (q[hi] - q[lo]) / (out->step_s * static_cast<double>(hi - lo));
    // Second difference at the interior nodes (0 at the ends).
    const JointVector q_ddot =
        hi - lo == 2 ? JointVector((q[hi] - 2.0 * q[k] + q[lo]) / (out->step_s * out->step_s))
                     : JointVector::Zero();
    // omega_H of joint angles q and rates q_dot: R_H_R J_rotation(q) q_dot.
    const auto flange_rate = [&](const JointVector& angles, const JointVector& rates) {
      const Eigen::Matrix3d R_H_R = forward_kinematics<double>(model, angles).linear().transpose();
      return Eigen::Vector3d(R_H_R * (geometric_jacobian(model, angles).bottomRows<3>() * rates));
    };
    const Eigen::Vector3d omega_H = flange_rate(q[k], q_dot);
    // What the readings add when they lead the link angles by lag_j: q + lag q_dot is read
    // (first order in the lags: tens of microseconds).
    const JointVector& lag = robot.link_lag_per_share_s;
    const Eigen::Vector3d lag_H =
        lag.cwiseAbs().maxCoeff() > 0.0
            ? Eigen::Vector3d(
                  flange_rate(q[k] + lag.cwiseProduct(q_dot), q_dot + lag.cwiseProduct(q_ddot)) -
                  omega_H)
            : Eigen::Vector3d::Zero();
    for (int c = 0; c < 3; ++c) {
      out->values[6 * k + c] = omega_H[c];
      out->values[6 * k + 3 + c] = lag_H[c];
    }
  }
  out->grid =
      std::make_unique<ceres::Grid1D<double, 6>>(out->values.data(), 0, static_cast<int>(nodes));
  out->interpolator = std::make_unique<RateResidual::Interpolator>(*out->grid);
  return out;
}

struct RateWindow {
  std::size_t first = 0;
  std::size_t count = 0;
  Eigen::Vector3d mean_rate = Eigen::Vector3d::Zero();
  std::vector<double> mid_times;
  Eigen::Matrix3d R_R_H_mid = Eigen::Matrix3d::Identity();  // flange attitude (Earth-rate term)
};

// Windows of rate_window_s during motion (outside the rests), inside the robot record at dt.
std::vector<RateWindow> cut_rate_windows(const FrameCalibrationInput& input,
                                         const FrameCalibrationOptions& options,
                                         const std::vector<RestWindow>& rests,
                                         const FlangeRateGrid& grid, double dt,
                                         std::size_t* samples_in_overlap) {
  const ims::ImuSeries& imu = *input.imu;
  const std::size_t per_window = std::max<std::size_t>(
      2, static_cast<std::size_t>(std::lround(options.rate_window_s / imu.nominal_dt_s)));
  std::vector<bool> at_rest(imu.samples.size(), false);
  for (const RestWindow& r : rests) {
    for (std::size_t k = r.first_sample; k < r.first_sample + r.sample_count; ++k)
      at_rest[k] = true;
  }
  // Margin: a few grid steps inside the robot record (dt moves a little during the solve).
  const double margin = 3.0 * grid.step_s + 0.01;
  std::vector<RateWindow> windows;
  *samples_in_overlap = 0;
  std::size_t k = 1;
  while (k + per_window <= imu.samples.size()) {
    bool usable = true;
    RateWindow w;
    w.first = k;
    w.count = per_window;
    for (std::size_t s = k; s < k + per_window; ++s) {
      const double mid = 0.5 * (imu.samples[s].t_s + imu.samples[s - 1].t_s);
      const double t_robot = mid - dt;
      if (at_rest[s] || t_robot < grid.t0_s + margin || t_robot > grid.t_end_s() - margin) {
        usable = false;
      } else {
        ++*samples_in_overlap;
      }
      w.mid_times.push_back(mid);
    }
    if (usable) {
      Eigen::Vector3d force;
      mean_increments(imu, k, per_window,
                      imu.samples[k + per_window - 1].t_s - imu.samples[k - 1].t_s, &w.mean_rate,
                      &force);
      if (w.mean_rate.norm() > options.min_rate_rad_s) windows.push_back(std::move(w));
    }
    k += per_window;
  }
  return windows;
}

// The spec's prior of a bias triad, N(0, sigma) per axis (with known frames only, see below).
struct BiasPriorResidual {
  double inverse_sigma = 0.0;
  template <typename T>
  bool operator()(const T* bias, T* residual) const {
    for (int k = 0; k < 3; ++k) residual[k] = bias[k] * T(inverse_sigma);
    return true;
  }
};

struct Stage {
  std::unique_ptr<ceres::Problem> problem;
  std::vector<ImuPreintegration> motions;
  std::vector<RestResidual> rest_functors;
  std::vector<MotionResidual> motion_functors;
  std::vector<Eigen::Matrix<double, 9, 9>> motion_covariance_factor;  // L (raw = L * whitened)
  std::vector<RateResidual> rate_functors;
  ceres::Solver::Summary summary;
};

}  // namespace

Eigen::Isometry3d frame_calibration_truth_convention(const Eigen::Isometry3d& T_R_W_true,
                                                     const Eigen::Isometry3d& T_S_H_true,
                                                     const KinematicModel& kinematics,
                                                     const JointVector& q_link_first_rest_rad) {
  const Eigen::Isometry3d T_W_S_1 = T_R_W_true.inverse() *
                                    forward_kinematics<double>(kinematics, q_link_first_rest_rad) *
                                    T_S_H_true.inverse();
  Eigen::Isometry3d T_W_Wnew = Eigen::Isometry3d::Identity();
  T_W_Wnew.translation() = T_W_S_1.translation();
  return T_R_W_true * T_W_Wnew;
}

FrameCalibrationResult calibrate_frames(const FrameCalibrationInput& input,
                                        const FrameCalibrationOptions& options) {
  const std::string source = input.source.empty() ? std::string("frame calibration") : input.source;
  if (input.imu == nullptr || input.imu->samples.empty()) {
    throw InputError(source, 0, "imu", "no IMS samples");
  }
  if (input.imu->quantity != ims::ImuQuantity::kIncrements) {
    throw InputError(source, 0, "imu", "the frame calibration needs increments, not rates");
  }
  const bool frames_known = input.known_frames.has_value();
  if (frames_known && input.rests.empty()) {
    throw InputError(source, 0, "rests",
                     "no rest pose: with the frames known (from " + input.known_frames->source +
                         ") at least one is needed for the biases");
  }
  if (!frames_known && input.rests.size() < 3) {
    throw InputError(source, 0, "rests",
                     fmt::format("{} rest poses; at least 3 are needed (T_R_W and T_S_H from "
                                 "rotations about two different axes)",
                                 input.rests.size()));
  }
  const ims::ImuSeries& imu = *input.imu;
  const ims::EarthModel earth(input.site);
  std::vector<RestWindow> rests;
  for (std::size_t i = 0; i < input.rests.size(); ++i) {
    const RestObservation& r = input.rests[i];
    if (i > 0 && r.begin_ims_s < input.rests[i - 1].end_ims_s) {
      throw InputError(source, 0, "rests", fmt::format("{}: rests are not in time order", r.label));
    }
    rests.push_back(cut_rest_window(imu, r.begin_ims_s, r.end_ims_s, r.label, source));
  }

  // Initial values.
  const std::vector<ImuPreintegration> chain_motions = integrate_motions(imu, rests, ImuBiases{});
  // With known frames: those, held constant (no hand-eye: it needs >= 3 rests).
  const FrameInitialValues init = [&] {
    if (!frames_known) return initial_frame_values(input, rests, chain_motions, earth);
    FrameInitialValues known;
    known.T_S_H = input.known_frames->T_S_H;
    known.T_R_W.linear() = input.known_frames->R_W_R.transpose();
    known.time_offset_s = input.time_offset_initial_s;
    for (const RestObservation& r : input.rests)
      known.T_R_H_rest.push_back(forward_kinematics<double>(input.kinematics, r.q_link_rad));
    return known;
  }();
  Parameters x;
  set_quaternion(x.q_W_R, init.T_R_W.linear().transpose());
  set_quaternion(x.q_S_H, init.T_S_H.linear());
  Eigen::Map<Eigen::Vector3d>(x.p_S_H) = init.T_S_H.translation();
  x.dt[0] = init.time_offset_s;
  x.dq.assign(rests.size(), std::array<double, 6>{0, 0, 0, 0, 0, 0});
  const bool acc_bias_drifts = input.noise.acc_bias_drift_psd > 0.0;
  x.b_a.assign(acc_bias_drifts ? rests.size() : 1, std::array<double, 3>{0, 0, 0});
  for (std::size_t i = 0; i < rests.size(); ++i)
    x.b_a_blocks.push_back(x.b_a[acc_bias_drifts ? i : 0].data());
  x.rests = &input.rests;
  // Deflection scales: per joint, only where some rest has a modelled wind-up / play.
  JointVector windup_inverse_sigma = JointVector::Zero(), play_inverse_sigma = JointVector::Zero();
  std::vector<int> fixed_windup, fixed_play;
  for (int k = 0; k < kJointCount; ++k) {
    double windup = 0.0, play = 0.0;
    for (const RestObservation& r : input.rests) {
      windup = std::max(windup, std::abs(r.q_windup_rad[k]));
      play = std::max(play, std::abs(r.q_play_rad[k]));
    }
    const bool estimate = options.estimate_deflection_scale && options.deflection_scale_sigma > 0.0;
    if (estimate && windup > 0.0)
      windup_inverse_sigma[k] = 1.0 / options.deflection_scale_sigma;
    else
      fixed_windup.push_back(k);
    if (estimate && play > 0.0)
      play_inverse_sigma[k] = 1.0 / options.deflection_scale_sigma;
    else
      fixed_play.push_back(k);
  }

  // Rate windows for the time offset.
  std::unique_ptr<FlangeRateGrid> rate_grid;
  std::vector<RateWindow> rate_windows;
  if (!input.robot.t_robot_s.empty()) {
    rate_grid = make_flange_rate_grid(input.kinematics, input.robot, source);
    std::size_t overlap = 0;
    rate_windows = cut_rate_windows(input, options, rests, *rate_grid, x.dt[0], &overlap);
    if (overlap == 0) {
      throw InputError(source, 0, "time_offset_initial_s",
                       fmt::format("with the time offset {:.4f} s no IMS sample outside the rests "
                                   "falls inside the robot joint record [{:.3f} s, {:.3f} s] "
                                   "(robot clock): the records do not overlap",
                                   x.dt[0], rate_grid->t0_s, rate_grid->t_end_s()));
    }
    for (RateWindow& w : rate_windows) {
      const double t_robot = w.mid_times[w.mid_times.size() / 2] - x.dt[0];
      // Flange attitude from the robot series at the nearest robot sample.
      std::size_t nearest = static_cast<std::size_t>(
          std::lower_bound(input.robot.t_robot_s.begin(), input.robot.t_robot_s.end(), t_robot) -
          input.robot.t_robot_s.begin());
      nearest = std::min(nearest, input.robot.q_rad.size() - 1);
      w.R_R_H_mid =
          forward_kinematics<double>(input.kinematics, input.robot.q_rad[nearest]).linear();
    }
  }
  const bool time_offset_observed = options.estimate_time_offset && !rate_windows.empty();
  // The link share with dt, where the robot file gives the lags and the prior allows it.
  const bool link_share_estimated = time_offset_observed && options.estimate_link_share &&
                                    options.link_share_prior_sigma > 0.0 &&
                                    input.robot.link_lag_per_share_s.cwiseAbs().maxCoeff() > 0.0;
  if (link_share_estimated) x.link_share[0] = options.link_share_prior_mean;

  FrameCalibrationResult result;
  result.initial_T_R_W = init.T_R_W;
  result.initial_T_S_H = init.T_S_H;
  result.initial_time_offset_s = init.time_offset_s;

  const double window_noise = input.noise.gyro_noise_density_rad_per_sqrt_s /
                              std::sqrt(std::max(options.rate_window_s, imu.nominal_dt_s));
  double rate_sigma = 1e-3;  // first solve: a guess [rad/s]; the second uses the data's RMS

  // A rate window's functor at the current R_S_H, b_g, R_W_R.
  auto make_rate_functor = [&](const RateWindow& w) {
    RateResidual f;
    f.omega_H = rate_grid->interpolator.get();
    f.grid_t0_s = rate_grid->t0_s;
    f.grid_step_s = rate_grid->step_s;
    f.mid_times_ims_s = w.mid_times;
    f.mean_rate = w.mean_rate;
    f.R_S_H = x.R_S_H();
    f.offset_S = Eigen::Map<const Eigen::Vector3d>(x.b_g) +
                 f.R_S_H * w.R_R_H_mid.transpose() * x.R_W_R().transpose() * earth.earth_rate_W();
    f.sigma = rate_sigma;
    return f;
  };

  auto build_and_solve = [&](Stage& stage, const ImuBiases& linearisation) {
    ceres::Problem::Options problem_options;
    stage.problem = std::make_unique<ceres::Problem>(problem_options);
    ceres::Problem& problem = *stage.problem;
    stage.motions = integrate_motions(imu, rests, linearisation);
    problem.AddParameterBlock(x.q_W_R, 4, new ceres::EigenQuaternionManifold);
    problem.AddParameterBlock(x.q_S_H, 4, new ceres::EigenQuaternionManifold);
    problem.AddParameterBlock(x.p_S_H, 3);
    if (frames_known) {
      problem.SetParameterBlockConstant(x.q_W_R);
      problem.SetParameterBlockConstant(x.q_S_H);
      problem.SetParameterBlockConstant(x.p_S_H);
    }
    problem.AddParameterBlock(x.b_g, 3);
    for (auto& b : x.b_a) problem.AddParameterBlock(b.data(), 3);
    if (frames_known) {
      // With few rests and no motion between them the tilt of a rest (its joint deviations:
      // backlash play, deflection; priors of up to ~1e-3 rad) trades with the accelerometer bias
      // (1e-3 rad of tilt = 1000 ug); a full session separates them through the motions. The
      // spec's turn-on priors (ImuNoiseModel::*_bias_sigma) keep the biases to what the unit
      // can have (measured on the two-session chain: 1 rest gave acc_bias 1200 ug 1-sigma
      // without them and joint errors that diverged from the first move on).
      for (auto [block, sigma] : {std::pair{x.b_g, input.noise.gyro_bias_sigma_rad_s},
                                  std::pair{x.b_a_blocks.front(), input.noise.acc_bias_sigma_m_s2}})
        if (sigma > 0.0)
          problem.AddResidualBlock(new ceres::AutoDiffCostFunction<BiasPriorResidual, 3, 3>(
                                       new BiasPriorResidual{1.0 / sigma}),
                                   nullptr, block);
    }
    for (std::size_t i = 0; acc_bias_drifts && i + 1 < rests.size(); ++i) {
      // Between the rests' mid-times.
      const double gap_s = 0.5 * (rests[i + 1].begin_s + rests[i + 1].end_s) -
                           0.5 * (rests[i].begin_s + rests[i].end_s);
      BiasDriftResidual drift;
      drift.inverse_sigma = 1.0 / std::sqrt(input.noise.acc_bias_drift_psd * gap_s);
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<BiasDriftResidual, 3, 3, 3>(new BiasDriftResidual(drift)),
          nullptr, x.b_a_blocks[i], x.b_a_blocks[i + 1]);
    }
    problem.AddParameterBlock(x.s_g, 3);
    problem.AddParameterBlock(x.s_a, 3);
    problem.AddParameterBlock(x.m_w, 6);
    problem.AddParameterBlock(x.m_p, 6);
    for (auto [block, fixed] : {std::pair{x.m_w, &fixed_windup}, std::pair{x.m_p, &fixed_play}}) {
      if (fixed->size() == static_cast<std::size_t>(kJointCount))
        problem.SetParameterBlockConstant(block);
      else if (!fixed->empty())
        problem.SetManifold(block, new ceres::SubsetManifold(6, *fixed));
    }
    if (fixed_windup.size() + fixed_play.size() < static_cast<std::size_t>(2 * kJointCount)) {
      DeflectionScalePriorResidual prior;
      prior.inverse_sigma_windup = windup_inverse_sigma;
      prior.inverse_sigma_play = play_inverse_sigma;
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<DeflectionScalePriorResidual, 12, 6, 6>(
              new DeflectionScalePriorResidual(prior)),
          nullptr, x.m_w, x.m_p);
    }
    if (!options.estimate_scale_factors) {
      problem.SetParameterBlockConstant(x.s_g);
      problem.SetParameterBlockConstant(x.s_a);
    }
    for (std::size_t i = 0; i < rests.size(); ++i) {
      problem.AddParameterBlock(x.dq[i].data(), 6);
      std::vector<int> fixed;
      for (int k = 0; k < kJointCount; ++k) {
        if (!(input.rests[i].q_link_sigma_rad[k] > 0.0)) fixed.push_back(k);
      }
      if (fixed.size() == static_cast<std::size_t>(kJointCount)) {
        problem.SetParameterBlockConstant(x.dq[i].data());
      } else {
        if (!fixed.empty())
          problem.SetManifold(x.dq[i].data(), new ceres::SubsetManifold(6, fixed));
        JointPriorResidual prior;
        for (int k = 0; k < kJointCount; ++k) {
          const double s = input.rests[i].q_link_sigma_rad[k];
          prior.inverse_sigma[k] = s > 0.0 ? 1.0 / s : 0.0;
        }
        problem.AddResidualBlock(new ceres::AutoDiffCostFunction<JointPriorResidual, 6, 6>(
                                     new JointPriorResidual(prior)),
                                 nullptr, x.dq[i].data());
      }
    }
    // Absolute positions of the rests (gravity field only), from the current estimate.
    std::vector<Eigen::Vector3d> p_abs(rests.size());
    {
      const Eigen::Matrix3d R_W_R = x.R_W_R();
      const Eigen::Matrix3d R_H_S = x.R_S_H().transpose();
      const Eigen::Vector3d p_H_S = -R_H_S * Eigen::Map<const Eigen::Vector3d>(x.p_S_H);
      Eigen::Vector3d first = Eigen::Vector3d::Zero();
      for (std::size_t i = 0; i < rests.size(); ++i) {
        const Eigen::Isometry3d T_R_H = forward_kinematics<double>(
            input.kinematics, JointVector(input.rests[i].q_link_rad + x.joint_deviation(i)));
        const Eigen::Vector3d p = R_W_R * (T_R_H.translation() + T_R_H.linear() * p_H_S);
        if (i == 0) first = p;
        p_abs[i] = p - first + input.first_rest_position_W_m;
      }
    }
    std::vector<RestCreep> creep(rests.size());
    {
      const Eigen::Vector3d p_H_S =
          -(x.R_S_H().transpose() * Eigen::Map<const Eigen::Vector3d>(x.p_S_H));
      for (std::size_t i = 0; i < rests.size(); ++i)
        creep[i] = rest_creep(input.kinematics, input.rests[i], rests[i].duration_s(), p_H_S);
    }
    stage.rest_functors.clear();
    for (std::size_t i = 0; i < rests.size(); ++i) {
      RestResidual f;
      f.model = &input.kinematics;
      f.q = input.rests[i].q_link_rad;
      f.windup = input.rests[i].q_windup_rad;
      f.play = input.rests[i].q_play_rad;
      f.mean_rate = rests[i].mean_rate_rad_s;
      f.mean_force = rests[i].mean_specific_force_m_s2;
      f.earth_rate_W = earth.earth_rate_W();
      f.gravity_W = earth.gravity_W(p_abs[i]);
      f.creep_rate_H = creep[i].mean_rate_H;
      f.creep_acceleration_R = creep[i].mean_acceleration_R;
      const RestSigmas sig = rest_sigmas(input.noise, rests[i].duration_s());
      // The creep as the joint readings see it is good to a fraction (transmission error, the
      // friction's share at the gear output).
      f.rate_sigma =
          std::hypot(sig.rate_rad_s, options.creep_model_fraction * creep[i].mean_rate_H.norm());
      f.force_sigma = std::hypot(
          sig.force_m_s2, options.creep_model_fraction * creep[i].mean_acceleration_R.norm());
      stage.rest_functors.push_back(f);
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<RestResidual, 6, 4, 4, 6, 3, 3, 3, 3, 6, 6>(
              new RestResidual(f)),
          new ceres::HuberLoss(options.huber_scale_sigma * std::sqrt(6.0)), x.q_W_R, x.q_S_H,
          x.dq[i].data(), x.b_g, x.b_a_blocks[i], x.s_g, x.s_a, x.m_w, x.m_p);
    }
    stage.motion_functors.clear();
    stage.motion_covariance_factor.clear();
    for (std::size_t i = 0; i + 1 < rests.size(); ++i) {
      MotionResidual f;
      f.model = &input.kinematics;
      f.preintegration = &stage.motions[i];
      f.q_i = input.rests[i].q_link_rad;
      f.q_j = input.rests[i + 1].q_link_rad;
      f.creep_i = input.rests[i].q_creep_end_rad;
      f.creep_j = input.rests[i + 1].q_creep_begin_rad;
      f.velocity_start_R = creep[i].velocity_end_R;
      f.velocity_end_R = creep[i + 1].velocity_begin_R;
      f.windup_i = input.rests[i].q_windup_rad;
      f.play_i = input.rests[i].q_play_rad;
      f.windup_j = input.rests[i + 1].q_windup_rad;
      f.play_j = input.rests[i + 1].q_play_rad;
      f.earth_rate_W = earth.earth_rate_W();
      f.gravity_start_W = earth.gravity_W(p_abs[i]);
      f.gravity_gradient_W = earth.gravity_gradient_W();
      Eigen::Matrix<double, 9, 9> cov = motion_covariance(
          input.noise, stage.motions[i].duration_s(), rests[i].mean_specific_force_m_s2);
      // The creep velocities at the ends are good to the same fraction.
      const double creep_velocity =
          options.creep_model_fraction *
          std::hypot(creep[i].velocity_end_R.norm(), creep[i + 1].velocity_begin_R.norm());
      const double creep_position = options.creep_model_fraction * creep[i].velocity_end_R.norm() *
                                    stage.motions[i].duration_s();
      for (int k = 0; k < 3; ++k) {
        cov(3 + k, 3 + k) += creep_velocity * creep_velocity;
        cov(6 + k, 6 + k) += creep_position * creep_position;
      }
      f.whitening = whitening_matrix(cov);
      stage.motion_covariance_factor.push_back(
          Eigen::LLT<Eigen::Matrix<double, 9, 9>>(cov).matrixL());
      stage.motion_functors.push_back(f);
      if (acc_bias_drifts) {
        problem.AddResidualBlock(
            new ceres::AutoDiffCostFunction<MotionResidual, 9, 4, 4, 3, 6, 6, 3, 3, 3, 6, 6>(
                new MotionResidual(f)),
            new ceres::HuberLoss(options.huber_scale_sigma * 3.0), x.q_W_R, x.q_S_H, x.p_S_H,
            x.dq[i].data(), x.dq[i + 1].data(), x.b_g, x.b_a_blocks[i], x.b_a_blocks[i + 1], x.m_w,
            x.m_p);
      } else {
        problem.AddResidualBlock(
            new ceres::AutoDiffCostFunction<MotionResidualConstantBias, 9, 4, 4, 3, 6, 6, 3, 3, 6,
                                            6>(new MotionResidualConstantBias{f}),
            new ceres::HuberLoss(options.huber_scale_sigma * 3.0), x.q_W_R, x.q_S_H, x.p_S_H,
            x.dq[i].data(), x.dq[i + 1].data(), x.b_g, x.b_a_blocks[i], x.m_w, x.m_p);
      }
    }
    stage.rate_functors.clear();
    if (!rate_windows.empty()) {
      problem.AddParameterBlock(x.dt, 1);
      problem.AddParameterBlock(x.link_share, 1);
      for (const RateWindow& w : rate_windows) {
        const RateResidual f = make_rate_functor(w);
        stage.rate_functors.push_back(f);
        problem.AddResidualBlock(
            new ceres::AutoDiffCostFunction<RateResidual, 3, 1, 1>(new RateResidual(f)),
            new ceres::HuberLoss(options.huber_scale_sigma * std::sqrt(3.0)), x.dt, x.link_share);
      }
      if (!options.estimate_time_offset) problem.SetParameterBlockConstant(x.dt);
      if (link_share_estimated) {
        LinkSharePriorResidual prior;
        prior.mean = options.link_share_prior_mean;
        prior.inverse_sigma = 1.0 / options.link_share_prior_sigma;
        problem.AddResidualBlock(new ceres::AutoDiffCostFunction<LinkSharePriorResidual, 1, 1>(
                                     new LinkSharePriorResidual(prior)),
                                 nullptr, x.link_share);
      } else {
        problem.SetParameterBlockConstant(x.link_share);
      }
    }
    ceres::Solver::Options solver;
    solver.linear_solver_type = options.sparse ? ceres::SPARSE_NORMAL_CHOLESKY : ceres::DENSE_QR;
    solver.max_num_iterations = options.max_iterations;
    solver.minimizer_progress_to_stdout = options.report_progress;
    solver.function_tolerance = 1e-15;
    solver.gradient_tolerance = 1e-15;
    solver.parameter_tolerance = 1e-14;
    solver.num_threads = 1;
    ceres::Solve(solver, &problem, &stage.summary);
  };

  Stage first;
  build_and_solve(first, ImuBiases{});
  // Window sigma from the data: RMS of the first solve's unweighted rate residuals.
  if (!rate_windows.empty()) {
    double sum_sq = 0.0;
    for (const RateWindow& w : rate_windows) {
      const RateResidual f = make_rate_functor(w);
      double r[3];
      f(x.dt, x.link_share, r);
      for (double v : r) sum_sq += (v * f.sigma) * (v * f.sigma);
    }
    const double rms = std::sqrt(sum_sq / (3.0 * static_cast<double>(rate_windows.size())));
    rate_sigma = std::max(rms, window_noise);
  }
  Stage stage;
  build_and_solve(stage, x.biases());
  ceres::Problem& problem = *stage.problem;

  // Results.
  const Eigen::Matrix3d R_W_R = x.R_W_R();
  const Eigen::Matrix3d R_S_H = x.R_S_H();
  const Eigen::Vector3d p_S_H = Eigen::Map<const Eigen::Vector3d>(x.p_S_H);
  result.T_S_H.linear() = R_S_H;
  result.T_S_H.translation() = p_S_H;
  {
    const Eigen::Isometry3d T_R_H_1 = forward_kinematics<double>(
        input.kinematics, JointVector(input.rests[0].q_link_rad + x.joint_deviation(0)));
    const Eigen::Vector3d p_R_S_1 =
        T_R_H_1.translation() + T_R_H_1.linear() * (-(R_S_H.transpose() * p_S_H));
    Eigen::Isometry3d T_W_R = Eigen::Isometry3d::Identity();
    T_W_R.linear() = R_W_R;
    T_W_R.translation() = -R_W_R * p_R_S_1;  // the sensor at rest 1 at W's origin
    result.T_R_W = T_W_R.inverse();
  }
  result.biases = x.biases();
  for (const double* b : x.b_a_blocks) result.acc_bias_at_rests_m_s2.emplace_back(b[0], b[1], b[2]);
  result.gyro_scale_factor = Eigen::Map<const Eigen::Vector3d>(x.s_g);
  result.acc_scale_factor = Eigen::Map<const Eigen::Vector3d>(x.s_a);
  result.time_offset_s = x.dt[0];
  if (link_share_estimated) result.link_share = x.link_share[0];
  for (int k = 0; k < kJointCount; ++k) {
    result.windup_scale[k] = 1.0 - x.m_w[k];
    result.play_scale[k] = 1.0 - x.m_p[k];
  }
  for (std::size_t i = 0; i < rests.size(); ++i)
    result.joint_deviation_rad.push_back(x.joint_deviation(i));
  result.solver_brief_report = stage.summary.BriefReport();
  result.iterations = static_cast<int>(stage.summary.iterations.size());
  result.final_cost = stage.summary.final_cost;
  result.converged = stage.summary.IsSolutionUsable() &&
                     stage.summary.termination_type == ceres::CONVERGENCE &&
                     first.summary.IsSolutionUsable();

  // Covariance.
  std::vector<CovarianceBlock> blocks = {
      {"R_W_R", x.q_W_R, 3, 2.0, {"east", "north", "up"}},
      {"R_S_H", x.q_S_H, 3, 2.0, {"x", "y", "z"}},
      {"p_S_H", x.p_S_H, 3, 1.0, {"x", "y", "z"}},
      {"gyro_bias", x.b_g, 3, 1.0, {"x", "y", "z"}},
      {"acc_bias", x.b_a_blocks.front(), 3, 1.0, {"x", "y", "z"}}};
  int offset_dt = -1;
  if (time_offset_observed) {
    offset_dt = 15;
    blocks.push_back({"time_offset", x.dt, 1, 1.0, {"dt"}});
  }
  if (options.estimate_scale_factors) {
    blocks.push_back({"gyro_scale_factor", x.s_g, 3, 1.0, {"x", "y", "z"}});
    blocks.push_back({"acc_scale_factor", x.s_a, 3, 1.0, {"x", "y", "z"}});
  }
  const bool windup_estimated = fixed_windup.size() < static_cast<std::size_t>(kJointCount);
  const bool play_estimated = fixed_play.size() < static_cast<std::size_t>(kJointCount);
  const std::vector<std::string> joint_names = {"A1", "A2", "A3", "A4", "A5", "A6"};
  // Only the estimated joints of a block are in the covariance: a SubsetManifold's tangent
  // space leaves out the fixed ones.
  auto estimated_names = [&](const std::vector<int>& fixed) {
    std::vector<std::string> names;
    for (int k = 0; k < kJointCount; ++k)
      if (std::find(fixed.begin(), fixed.end(), k) == fixed.end()) names.push_back(joint_names[k]);
    return names;
  };
  const std::vector<std::string> windup_names = estimated_names(fixed_windup);
  const std::vector<std::string> play_names = estimated_names(fixed_play);
  if (windup_estimated)
    blocks.push_back({"windup_scale_deviation", x.m_w, static_cast<int>(windup_names.size()), 1.0,
                      windup_names});
  if (play_estimated)
    blocks.push_back(
        {"play_scale_deviation", x.m_p, static_cast<int>(play_names.size()), 1.0, play_names});
  if (link_share_estimated) blocks.push_back({"link_share", x.link_share, 1, 1.0, {"s"}});
  // A failed solve has no estimate to take a covariance at (ceres::Covariance on it aborts).
  FrameCovariance cov;
  if (stage.summary.IsSolutionUsable()) {
    cov = compute_frame_covariance(problem, blocks);
  } else {
    cov.message = "no covariance: the solve failed (" + stage.summary.message + ")";
  }
  if (frames_known && cov.computed) {
    // The held frames have no covariance from this problem (constant blocks: zero); theirs is
    // the earlier session's, reported as it is (the other unknowns are conditional on them).
    cov.covariance.topLeftCorner<9, 9>() = input.known_frames->covariance;
    cov.covariance.topRightCorner(9, cov.covariance.cols() - 9).setZero();
    cov.covariance.bottomLeftCorner(cov.covariance.rows() - 9, 9).setZero();
    const Eigen::VectorXd sigma = cov.covariance.diagonal().cwiseMax(0.0).cwiseSqrt();
    for (Eigen::Index i = 0; i < sigma.size(); ++i)
      for (Eigen::Index j = 0; j < sigma.size(); ++j) {
        const double d = sigma[i] * sigma[j];
        cov.correlation(i, j) = d > 0.0 ? cov.covariance(i, j) / d : (i == j ? 1.0 : 0.0);
      }
  }
  result.parameter_names = cov.parameter_names;
  result.covariance = cov.covariance;
  result.correlation = cov.correlation;
  result.covariance_rank_deficient = cov.rank_deficient;
  if (cov.computed) {
    auto sigma_of = [&](int offset, int n) {
      Eigen::VectorXd s(n);
      for (int k = 0; k < n; ++k)
        s[k] = std::sqrt(std::max(0.0, cov.covariance(offset + k, offset + k)));
      return s;
    };
    const Eigen::Vector3d rotvec_W_R = ims::quat_log<double>(Eigen::Quaterniond(R_W_R));
    const Eigen::Vector3d rotvec_S_H = ims::quat_log<double>(Eigen::Quaterniond(R_S_H));
    result.estimates.push_back({"R_W_R.rotation_vector (sigma: small angles about W east/north/up)",
                                "deg",
                                {"east", "north", "up"},
                                rotvec_W_R * kDegPerRad,
                                sigma_of(0, 3) * kDegPerRad});
    result.estimates.push_back({"T_S_H.rotation_vector (sigma: small angles about S axes)",
                                "deg",
                                {"x", "y", "z"},
                                rotvec_S_H * kDegPerRad,
                                sigma_of(3, 3) * kDegPerRad});
    result.estimates.push_back(
        {"T_S_H.translation", "mm", {"x", "y", "z"}, p_S_H * 1e3, sigma_of(6, 3) * 1e3});
    result.estimates.push_back({"gyro_bias",
                                "deg/h",
                                {"x", "y", "z"},
                                result.biases.gyro_rad_s * kDegPerRad * 3600.0,
                                sigma_of(9, 3) * kDegPerRad * 3600.0});
    result.estimates.push_back({"acc_bias",
                                "ug",
                                {"x", "y", "z"},
                                result.biases.acc_m_s2 / kStandardGravity * 1e6,
                                sigma_of(12, 3) / kStandardGravity * 1e6});
    int next = 15;
    if (time_offset_observed) {
      result.estimates.push_back({"time_offset",
                                  "ms",
                                  {"dt"},
                                  Eigen::VectorXd::Constant(1, x.dt[0] * 1e3),
                                  sigma_of(15, 1) * 1e3});
      next = 16;
    }
    if (options.estimate_scale_factors) {
      result.estimates.push_back({"gyro_scale_factor",
                                  "ppm",
                                  {"x", "y", "z"},
                                  result.gyro_scale_factor * 1e6,
                                  sigma_of(next, 3) * 1e6});
      result.estimates.push_back({"acc_scale_factor",
                                  "ppm",
                                  {"x", "y", "z"},
                                  result.acc_scale_factor * 1e6,
                                  sigma_of(next + 3, 3) * 1e6});
    }
  }
  // The deflection scales k = 1 - m with their 1-sigma, per estimated joint.
  if (cov.computed) {
    for (auto [prefix, factor, sigma, label] :
         {std::tuple{"windup_scale_deviation.", &result.windup_scale, &result.windup_scale_sigma,
                     "windup_scale (gear wind-up found / robot file's)"},
          std::tuple{"play_scale_deviation.", &result.play_scale, &result.play_scale_sigma,
                     "play_scale (backlash play found at rest / robot file's)"}}) {
      std::vector<std::string> components;
      std::vector<double> values, sigmas;
      for (std::size_t i = 0; i < cov.parameter_names.size(); ++i) {
        const std::string& name = cov.parameter_names[i];
        if (name.rfind(prefix, 0) != 0) continue;
        const int joint = name.back() - '1';
        const double s = std::sqrt(std::max(0.0, cov.covariance(Eigen::Index(i), Eigen::Index(i))));
        (*sigma)[joint] = s;
        components.push_back(joint_names[static_cast<std::size_t>(joint)]);
        values.push_back((*factor)[joint]);
        sigmas.push_back(s);
      }
      if (values.empty()) continue;
      result.estimates.push_back(
          {label, "1", components,
           Eigen::Map<const Eigen::VectorXd>(values.data(), Eigen::Index(values.size())),
           Eigen::Map<const Eigen::VectorXd>(sigmas.data(), Eigen::Index(sigmas.size()))});
    }
    const auto share = std::find(cov.parameter_names.begin(), cov.parameter_names.end(),
                                 std::string("link_share.s"));
    if (share != cov.parameter_names.end()) {
      const auto i = Eigen::Index(share - cov.parameter_names.begin());
      result.link_share_sigma = std::sqrt(std::max(0.0, cov.covariance(i, i)));
      result.estimates.push_back(
          {"link_share (of the drives' viscous friction, at the gear output)",
           "1",
           {"s"},
           Eigen::VectorXd::Constant(1, result.link_share),
           Eigen::VectorXd::Constant(1, result.link_share_sigma)});
    }
  }
  std::vector<Eigen::Matrix3d> flange_rotations;
  for (std::size_t i = 0; i + 1 < rests.size(); ++i) {
    flange_rotations.push_back(init.T_R_H_rest[i].linear().transpose() *
                               init.T_R_H_rest[i + 1].linear());
  }
  result.weak_directions = describe_weak_directions(cov, 0, 3, 6, offset_dt, time_offset_observed,
                                                    R_S_H, flange_rotations);
  if (frames_known) {
    // The frames are not estimated from this record's poses: what its poses do not excite is no
    // weakness of the frames (their sigma is the earlier session's).
    std::erase_if(result.weak_directions, [](const WeakDirection& w) {
      return w.description.rfind("the poses hardly turn the flange", 0) == 0;
    });
  }

  // Residuals per rest and motion, outliers.
  for (std::size_t i = 0; i < rests.size(); ++i) {
    const RestResidual& f = stage.rest_functors[i];
    Eigen::Matrix<double, 6, 1> r;
    f(x.q_W_R, x.q_S_H, x.dq[i].data(), x.b_g, x.b_a_blocks[i], x.s_g, x.s_a, x.m_w, x.m_p,
      r.data());
    PoseResidual p;
    p.label = input.rests[i].label;
    p.normalised = std::sqrt(r.squaredNorm() / 6.0);
    p.rotation_rad = (r.tail<3>() * f.force_sigma).norm() / f.gravity_W.norm();
    p.outlier = p.normalised > options.outlier_threshold_sigma;
    if (p.outlier) {
      result.outliers.push_back(fmt::format(
          "{}: the mean rate and specific force at rest disagree with the model by {:.1f} sigma "
          "(tilt equivalent {:.2g} deg): robot not still, mount slipped, or wrong joint angles",
          p.label, p.normalised, p.rotation_rad * kDegPerRad));
    }
    result.rest_residuals.push_back(p);
  }
  for (std::size_t i = 0; i + 1 < rests.size(); ++i) {
    const MotionResidual& f = stage.motion_functors[i];
    Eigen::Matrix<double, 9, 1> r;
    f(x.q_W_R, x.q_S_H, x.p_S_H, x.dq[i].data(), x.dq[i + 1].data(), x.b_g, x.b_a_blocks[i],
      x.b_a_blocks[i + 1], x.m_w, x.m_p, r.data());
    const Eigen::Matrix<double, 9, 1> raw = stage.motion_covariance_factor[i] * r;
    PoseResidual p;
    p.label = fmt::format("{} -> {}", input.rests[i].label, input.rests[i + 1].label);
    p.normalised = std::sqrt(r.squaredNorm() / 9.0);
    p.rotation_rad = raw.head<3>().norm();
    p.position_m = raw.tail<3>().norm();
    p.outlier = p.normalised > options.outlier_threshold_sigma;
    if (p.outlier) {
      result.outliers.push_back(fmt::format(
          "motion {}: the IMS's motion disagrees with the forward kinematics by {:.1f} sigma "
          "(rotation {:.2g} deg, position {:.3f} mm): slipped mount, rest boundaries inside the "
          "motion, or joint readings off",
          p.label, p.normalised, p.rotation_rad * kDegPerRad, p.position_m * 1e3));
    }
    result.motion_residuals.push_back(p);
  }
  return result;
}

}  // namespace imscal::calib
