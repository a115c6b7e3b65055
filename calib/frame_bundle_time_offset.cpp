// The time-offset model of the frame-and-bias bundle (calib/frame_bundle.hpp): the gyro rate in
// windows during motion against the flange rate of the joint readings at t_ims - dt, with the
// link share of the drives' viscous friction (calib/frame_calibration.hpp, measurements).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "calib/frame_bundle.hpp"
#include "core/input_error.hpp"
#include "robot/forward_kinematics.hpp"
#include "robot/jacobian.hpp"

namespace imscal::calib {
namespace {

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

// Each window's flange attitude from the robot series at the nearest robot sample.
void set_window_attitudes(const FrameCalibrationInput& input, double dt,
                          std::vector<RateWindow>& windows) {
  for (RateWindow& w : windows) {
    const double t_robot = w.mid_times[w.mid_times.size() / 2] - dt;
    std::size_t nearest = static_cast<std::size_t>(
        std::lower_bound(input.robot.t_robot_s.begin(), input.robot.t_robot_s.end(), t_robot) -
        input.robot.t_robot_s.begin());
    nearest = std::min(nearest, input.robot.q_rad.size() - 1);
    w.R_R_H_mid = forward_kinematics<double>(input.kinematics, input.robot.q_rad[nearest]).linear();
  }
}

}  // namespace

void set_up_time_offset(FrameBundle& b) {
  const FrameCalibrationInput& input = b.input;
  const FrameCalibrationOptions& options = b.options;
  if (!input.robot.t_robot_s.empty()) {
    b.rate_grid = make_flange_rate_grid(input.kinematics, input.robot, b.source);
    std::size_t overlap = 0;
    b.rate_windows = cut_rate_windows(input, options, b.rests, *b.rate_grid, b.x.dt[0], &overlap);
    if (overlap == 0) {
      throw InputError(b.source, 0, "time_offset_initial_s",
                       fmt::format("with the time offset {:.4f} s no IMS sample outside the rests "
                                   "falls inside the robot joint record [{:.3f} s, {:.3f} s] "
                                   "(robot clock): the records do not overlap",
                                   b.x.dt[0], b.rate_grid->t0_s, b.rate_grid->t_end_s()));
    }
    set_window_attitudes(input, b.x.dt[0], b.rate_windows);
  }
  b.time_offset_observed = options.estimate_time_offset && !b.rate_windows.empty();
  // The link share with dt, where the robot file gives the lags and the prior allows it.
  b.link_share_estimated = b.time_offset_observed && options.estimate_link_share &&
                           options.link_share_prior_sigma > 0.0 &&
                           input.robot.link_lag_per_share_s.cwiseAbs().maxCoeff() > 0.0;
  if (b.link_share_estimated) b.x.link_share[0] = options.link_share_prior_mean;
  b.rate_window_noise = input.noise.gyro_noise_density_rad_per_sqrt_s /
                        std::sqrt(std::max(options.rate_window_s, input.imu->nominal_dt_s));
}

RateResidual rate_functor(const FrameBundle& b, const RateWindow& w) {
  RateResidual f;
  f.omega_H = b.rate_grid->interpolator.get();
  f.grid_t0_s = b.rate_grid->t0_s;
  f.grid_step_s = b.rate_grid->step_s;
  f.mid_times_ims_s = w.mid_times;
  f.mean_rate = w.mean_rate;
  f.R_S_H = b.x.R_S_H();
  f.offset_S = Eigen::Map<const Eigen::Vector3d>(b.x.b_g) +
               f.R_S_H * w.R_R_H_mid.transpose() * b.x.R_W_R().transpose() * b.earth.earth_rate_W();
  f.sigma = b.rate_sigma;
  return f;
}

void add_time_offset(FrameBundle& b, FrameStage& stage) {
  stage.rate_functors.clear();
  if (b.rate_windows.empty()) return;
  ceres::Problem& problem = *stage.problem;
  const FrameCalibrationOptions& options = b.options;
  FrameUnknowns& x = b.x;
  problem.AddParameterBlock(x.dt, 1);
  problem.AddParameterBlock(x.link_share, 1);
  for (const RateWindow& w : b.rate_windows) {
    const RateResidual f = rate_functor(b, w);
    stage.rate_functors.push_back(f);
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<RateResidual, 3, 1, 1>(new RateResidual(f)),
        new ceres::HuberLoss(options.huber_scale_sigma * std::sqrt(3.0)), x.dt, x.link_share);
  }
  if (!options.estimate_time_offset) problem.SetParameterBlockConstant(x.dt);
  if (b.link_share_estimated) {
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

}  // namespace imscal::calib
