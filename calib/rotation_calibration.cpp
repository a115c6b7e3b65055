#include "calib/rotation_calibration.hpp"

#include <ceres/ceres.h>
#include <fmt/format.h>
#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <random>
#include <vector>

#include "core/input_error.hpp"
#include "ims/so3.hpp"

namespace imscal::calib {

Eigen::Matrix3d gyro_scale_matrix(const Eigen::Vector3d& scale, const Eigen::Vector3d& coupling) {
  Eigen::Matrix3d k = scale.asDiagonal();
  k(0, 1) = k(1, 0) = coupling.x();
  k(0, 2) = k(2, 0) = coupling.y();
  k(1, 2) = k(2, 1) = coupling.z();
  return k;
}

Eigen::Vector3d calibrated_rate_S(const RotationCalibration& calibration,
                                  const Eigen::Vector3d& reading) {
  return gyro_scale_matrix(calibration.gyro_scale, calibration.gyro_cross_coupling)
      .partialPivLu()
      .solve(reading - calibration.gyro_bias_rad_s);
}

namespace {

// The gyro-integrated rotation over samples [first, last] of the sensor clock, corrected by
// bias and scale, in S: product of exp(omega_mid * dt) over the sample intervals (trapezoidal
// rate per interval; the rates are ~100 Hz samples of a motion well below 10 Hz).
Eigen::Quaterniond integrate_gyro(const ToolImuRecord& record, std::size_t first, std::size_t last,
                                  const Eigen::Vector3d& bias, const Eigen::Matrix3d& to_rate) {
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  for (std::size_t k = first; k < last; ++k) {
    const Eigen::Vector3d mean_reading = 0.5 * (record.gyro_rad_s[k] + record.gyro_rad_s[k + 1]);
    const Eigen::Vector3d omega_S = to_rate * (mean_reading - bias);
    q = q * ims::quat_exp<double>(omega_S * (record.t_s[k + 1] - record.t_s[k]));
  }
  return q;
}

// (gyro reading - bias) -> rate in S: the inverse of the gyro's scale-and-coupling matrix.
Eigen::Matrix3d gyro_rate_matrix(const double* scale, const double* coupling) {
  return gyro_scale_matrix(Eigen::Vector3d(scale[0], scale[1], scale[2]),
                           Eigen::Vector3d(coupling[0], coupling[1], coupling[2]))
      .inverse();
}

struct WindowCost {
  const ToolImuRecord* record;
  std::size_t first;
  std::size_t last;

  bool operator()(const double* q_coeffs, const double* bias_p, const double* scale_p,
                  const double* coupling_p, const double* offset_p, double* residual) const {
    const Eigen::Quaterniond q_T_S =
        Eigen::Quaterniond(q_coeffs[3], q_coeffs[0], q_coeffs[1], q_coeffs[2]).normalized();
    const Eigen::Map<const Eigen::Vector3d> bias(bias_p);
    const Eigen::Quaterniond dq_S =
        integrate_gyro(*record, first, last, bias, gyro_rate_matrix(scale_p, coupling_p));
    Eigen::Quaterniond q_a, q_b;
    if (!robot_orientation_at(*record, record->t_s[first] - offset_p[0], q_a) ||
        !robot_orientation_at(*record, record->t_s[last] - offset_p[0], q_b)) {
      return false;
    }
    const Eigen::Quaterniond dq_T_robot = q_a.conjugate() * q_b;
    const Eigen::Quaterniond dq_T_gyro = q_T_S * dq_S * q_T_S.conjugate();
    const Eigen::Vector3d r = ims::quat_log(Eigen::Quaterniond(dq_T_robot.conjugate() * dq_T_gyro));
    residual[0] = r.x();
    residual[1] = r.y();
    residual[2] = r.z();
    return true;
  }
};

using Window = std::pair<std::size_t, std::size_t>;  // first and last sample of a window

// The calibration's unknowns in Ceres' layout (quaternion x, y, z, w).
struct Unknowns {
  double q[4];
  double bias[3];
  double scale[3];
  double coupling[3];
  double offset[1];
};

// The rests' gyro mean as a prior on the bias: residual weight * (b - mean) per axis, with
// weight = (the windows' RMS residual) / (the rest mean's 1 sigma) [rad / (rad/s)].
struct BiasPrior {
  Eigen::Vector3d mean_rad_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d weight_s = Eigen::Vector3d::Zero();

  template <typename T>
  bool operator()(const T* bias, T* residual) const {
    for (int i = 0; i < 3; ++i) residual[i] = T(weight_s[i]) * (bias[i] - T(mean_rad_s[i]));
    return true;
  }
};

// The calibration's problems have 11 unknowns: dense QR on one thread, as the whole record and
// each bootstrap replicate solve it.
ceres::Solver::Summary solve_small_problem(ceres::Problem& problem, int max_iterations) {
  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_QR;
  solver_options.max_num_iterations = max_iterations;
  solver_options.num_threads = 1;
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);
  return summary;
}

// The window residuals on the unknowns `x`, as calibrate_rotation and each bootstrap replicate
// solve them.
void add_windows(const ToolImuRecord& record, const std::vector<Window>& windows,
                 const RotationCalibrationOptions& options, const BiasPrior* prior, Unknowns& x,
                 ceres::Problem& problem) {
  for (const auto& [a, b] : windows) {
    auto* cost = new ceres::NumericDiffCostFunction<WindowCost, ceres::CENTRAL, 3, 4, 3, 3, 3, 1>(
        new WindowCost{&record, a, b});
    problem.AddResidualBlock(cost, new ceres::CauchyLoss(options.cauchy_scale_rad), x.q, x.bias,
                             x.scale, x.coupling, x.offset);
  }
  if (prior != nullptr) {
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<BiasPrior, 3, 3>(new BiasPrior(*prior)), nullptr, x.bias);
  }
  problem.SetManifold(x.q, new ceres::EigenQuaternionManifold);
  if (!options.estimate_scale) problem.SetParameterBlockConstant(x.scale);
  if (!options.estimate_cross_coupling) problem.SetParameterBlockConstant(x.coupling);
}

// Solves the window residuals from `x` (updated in place).
bool solve_windows(const ToolImuRecord& record, const std::vector<Window>& windows,
                   const RotationCalibrationOptions& options, const BiasPrior* prior, Unknowns& x) {
  ceres::Problem problem;
  add_windows(record, windows, options, prior, x, problem);
  return solve_small_problem(problem, options.max_iterations).IsSolutionUsable();
}

double window_residual_sq(const ToolImuRecord& record, const Window& w, const Unknowns& x,
                          bool& finite) {
  double r[3] = {0.0, 0.0, 0.0};
  finite = WindowCost{&record, w.first, w.second}(x.q, x.bias, x.scale, x.coupling, x.offset, r) &&
           std::isfinite(r[0] + r[1] + r[2]);
  return r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
}

Eigen::Quaterniond rotation_of(const Unknowns& x) {
  return Eigen::Quaterniond(x.q[3], x.q[0], x.q[1], x.q[2]).normalized();
}

// The resampling units of the bootstrap. Motion segments: the windows from one stop of the robot
// to the next (the motion and the rest after it), so a replicate draws whole motions and the
// spread holds how the estimate moves with the motions a record holds. Blocks: every run of
// `block` consecutive windows (a moving block).
std::vector<std::vector<Window>> resampling_units(const ToolImuRecord& record,
                                                  const std::vector<Window>& windows,
                                                  const RotationCalibrationOptions& options,
                                                  double time_offset_s) {
  std::vector<std::vector<Window>> units;
  if (options.sigma_resampling == SigmaResampling::kMotionSegments) {
    const std::vector<MotionSegment> segments =
        motion_segments(record, robot_tool_rate(record), time_offset_s, options.segment_rate_rad_s,
                        options.min_segment_angle_rad);
    units.resize(std::max<std::size_t>(segments.size(), 1));
    for (const Window& w : windows) {
      const double middle_s = 0.5 * (record.t_s[w.first] + record.t_s[w.second]);
      std::size_t started = 0;  // segments begun by the window's middle
      while (started < segments.size() && segments[started].begin_s <= middle_s) ++started;
      units[started > 0 ? started - 1 : 0].push_back(w);
    }
    std::erase_if(units, [](const auto& unit) { return unit.empty(); });
    return units;
  }
  const std::size_t n = windows.size();
  const std::size_t block = std::clamp<std::size_t>(
      static_cast<std::size_t>(std::lround(options.bootstrap_block_s / options.window_stride_s)), 1,
      n);
  for (std::size_t start = 0; start + block <= n; ++start) {
    units.emplace_back(windows.begin() + static_cast<std::ptrdiff_t>(start),
                       windows.begin() + static_cast<std::ptrdiff_t>(start + block));
  }
  return units;
}

// Per component the normal-consistent median absolute deviation, 1.4826 * median |d - median d|
// ([RousseeuwCroux1993]): a replicate that drew no motion about one axis leaves
// that axis's scale unobservable and lands tens of degrees away; up to half of such replicates
// do not move it, where they would dominate a standard deviation.
template <int N>
Eigen::Matrix<double, N, 1> robust_spread(const std::vector<Eigen::Matrix<double, N, 1>>& values) {
  Eigen::Matrix<double, N, 1> spread;
  std::vector<double> column(values.size());
  auto median = [](std::vector<double>& v) {
    const auto middle = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
    std::nth_element(v.begin(), middle, v.end());
    const double upper = *middle;
    if (v.size() % 2 == 1) return upper;
    return 0.5 * (upper + *std::max_element(v.begin(), middle));
  };
  for (int i = 0; i < N; ++i) {
    for (std::size_t k = 0; k < values.size(); ++k) column[k] = values[k][i];
    const double centre = median(column);
    for (std::size_t k = 0; k < values.size(); ++k) column[k] = std::abs(values[k][i] - centre);
    spread[i] = 1.4826 * median(column);
  }
  return spread;
}

// Bootstrap of dependent data (moving blocks: [Kunsch1989]; whole motions as clusters:
// [DavisonHinkley1997] 2.4):
// the windows' residuals are correlated in time (overlapping windows, the poses' timing jitter,
// motion-dependent model errors), so the covariance of independent windows is too small. Units
// of windows, drawn with replacement until the window count is reached (the last one cut), are
// re-solved from the estimate; the spread of the estimates over the replicates is the 1 sigma.
// Rotation deviations as small angles about the T axes, log(q_b * q^-1).
// The rests' prior is data apart from the windows and enters every replicate unchanged.
void block_bootstrap_sigma(const ToolImuRecord& record, const std::vector<Window>& windows,
                           const RotationCalibrationOptions& options, const BiasPrior* prior,
                           const Unknowns& estimate, RotationCalibration& result) {
  const std::size_t n = windows.size();
  const auto units = resampling_units(record, windows, options, estimate.offset[0]);
  result.bootstrap_unit_count = units.size();
  if (units.size() < 2) return;
  std::mt19937 random(options.bootstrap_seed);
  std::uniform_int_distribution<std::size_t> pick(0, units.size() - 1);
  std::vector<Eigen::Matrix<double, 13, 1>> deviations;
  for (int replicate = 0; replicate < options.bootstrap_replicates; ++replicate) {
    std::vector<Window> sample;
    while (sample.size() < n) {
      const auto& unit = units[pick(random)];
      for (std::size_t i = 0; i < unit.size() && sample.size() < n; ++i) sample.push_back(unit[i]);
    }
    Unknowns x = estimate;
    if (!solve_windows(record, sample, options, prior, x))
      continue;  // counted in bootstrap_replicates
    Eigen::Matrix<double, 13, 1> d;
    d.head<3>() =
        ims::quat_log(Eigen::Quaterniond(rotation_of(x) * rotation_of(estimate).conjugate()));
    for (int i = 0; i < 3; ++i) {
      d[3 + i] = x.bias[i] - estimate.bias[i];
      d[6 + i] = x.scale[i] - estimate.scale[i];
      d[10 + i] = x.coupling[i] - estimate.coupling[i];
    }
    d[9] = x.offset[0] - estimate.offset[0];
    deviations.push_back(d);
  }
  result.bootstrap_replicates = deviations.size();
  if (deviations.size() < 10) return;  // too few to tell a spread: keep the covariance's
  const Eigen::Matrix<double, 13, 1> sigma = robust_spread(deviations);
  // Per component the larger of the two: a few blocks may miss a motion's spread, and the
  // covariance is the floor that white residuals alone would give.
  result.sigma_rotation_rad = result.sigma_rotation_rad.cwiseMax(sigma.head<3>());
  result.sigma_bias_rad_s = result.sigma_bias_rad_s.cwiseMax(sigma.segment<3>(3));
  if (options.estimate_scale) result.sigma_scale = result.sigma_scale.cwiseMax(sigma.segment<3>(6));
  result.sigma_time_offset_s = std::max(result.sigma_time_offset_s, sigma[9]);
  if (options.estimate_cross_coupling) result.sigma_cross_coupling = sigma.segment<3>(10);
  result.sigma_from_bootstrap = true;
  result.sigma_resampling = options.sigma_resampling;
}

// Windows of samples, skipping gaps, rails and spans without valid robot poses (with a margin
// of 0.15 s for the offset to move, probed every 5 ms: shorter than any pose gap that
// robot_orientation_at refuses, 0.2 s). Counts the skipped ones in `skipped`.
std::vector<Window> usable_windows(const ToolImuRecord& record, const ToolImuAnalysis& analysis,
                                   const RotationCalibrationOptions& options, double offset,
                                   std::size_t& skipped) {
  constexpr double kOffsetMargin_s = 0.15;
  constexpr double kOffsetProbeStep_s = 0.005;
  std::vector<Window> windows;
  const auto& t = record.t_s;
  std::size_t first = 0;
  while (first < t.size()) {
    std::size_t last = first;
    bool usable = true;
    while (last + 1 < t.size() && t[last] - t[first] < options.window_s) {
      if (t[last + 1] - t[last] > options.max_sample_step_s) usable = false;
      ++last;
    }
    if (t[last] - t[first] < 0.5 * options.window_s) break;
    for (const auto& [begin_s, end_s] : analysis.missed_motion_spans_s) {
      if (t[last] >= begin_s && t[first] <= end_s) usable = false;  // motion the sensor lost
    }
    for (std::size_t k = first; k <= last && usable; ++k) {
      if (record.gyro_rad_s[k].isZero(0.0)) usable = false;  // placeholder rows
      for (std::size_t i = 0; i < analysis.clipped_axes.size(); ++i) {
        const int axis = analysis.clipped_axes[i];
        if (std::abs(record.gyro_rad_s[k][axis]) >= 0.99 * analysis.clipped_axis_rail_rad_s[i]) {
          usable = false;
        }
      }
    }
    // Robot poses at both ends for every offset within the margin, not only at its two limits:
    // a gap of invalid poses between them (interpolated across a quaternion sign flip, up to
    // 0.2 s) would leave the window without a residual at the initial offset, and the solve
    // could not start.
    Eigen::Quaterniond q;
    for (double margin = -kOffsetMargin_s; margin <= kOffsetMargin_s + 1e-9 && usable;
         margin += kOffsetProbeStep_s) {
      if (!robot_orientation_at(record, t[first] - offset + margin, q) ||
          !robot_orientation_at(record, t[last] - offset + margin, q)) {
        usable = false;
      }
    }
    if (usable) {
      windows.emplace_back(first, last);
    } else {
      ++skipped;
    }
    // Next window start: stride later.
    std::size_t next = first + 1;
    while (next < t.size() && t[next] - t[first] < options.window_stride_s) ++next;
    first = next;
  }
  return windows;
}

// Every window has a finite residual at the initial values (else the solve cannot start: names
// the first that has none). Returns the RMS residual per component [rad].
double initial_rms_residual(const ToolImuRecord& record, const std::vector<Window>& windows,
                            const Unknowns& x) {
  double sum = 0.0;
  for (const Window& w : windows) {
    bool finite = false;
    sum += window_residual_sq(record, w, x, finite);
    if (!finite) {
      throw InputError(
          record.file, record.lines[w.first], "gyro_x_dps",
          fmt::format("the rotation calibration's window of lines {}-{} has no "
                      "finite residual at the initial values (R_T_S, bias, scale "
                      "{:.4g}, time offset {:.4f} s)",
                      record.lines[w.first], record.lines[w.second], x.scale[0], x.offset[0]));
    }
  }
  return std::sqrt(sum / (3.0 * static_cast<double>(windows.size())));
}

// Solves `problem` from x; a failed solve has no estimate and no covariance (ceres::Covariance
// on it aborts), so it is refused.
void solve_or_refuse(const ToolImuRecord& record, const RotationCalibrationOptions& options,
                     ceres::Problem& problem, RotationCalibration& result) {
  const ceres::Solver::Summary summary = solve_small_problem(problem, options.max_iterations);
  result.summary = summary.BriefReport();
  result.iterations += static_cast<int>(summary.iterations.size());
  if (!summary.IsSolutionUsable()) {
    throw InputError(
        record.file, 0, "gyro_x_dps",
        fmt::format("the rotation calibration's solve failed ({}): {}",
                    ceres::TerminationTypeToString(summary.termination_type), summary.message));
  }
}

// The RMS window residual per component at x [rad], and the windows above 3 Cauchy scales.
double window_rms(const ToolImuRecord& record, const std::vector<Window>& windows,
                  const RotationCalibrationOptions& options, const Unknowns& x,
                  std::size_t& outliers) {
  double sum = 0.0;
  outliers = 0;
  for (const Window& w : windows) {
    // The solver accepts only steps where every window evaluates; this holds at its result.
    bool finite = false;
    const double norm_sq = window_residual_sq(record, w, x, finite);
    sum += norm_sq;
    if (std::sqrt(norm_sq) > 3.0 * options.cauchy_scale_rad) ++outliers;
  }
  return std::sqrt(sum / (3.0 * static_cast<double>(windows.size())));
}

// Covariance, scaled by the residual variance per component (the windows' residuals are not in
// units of their sigma): the 1 sigma of rotation, bias, scale and offset in `result`.
void covariance_sigma(const RotationCalibrationOptions& options, std::size_t window_count,
                      ceres::Problem& problem, Unknowns& x, RotationCalibration& result) {
  ceres::Covariance::Options covariance_options;
  covariance_options.algorithm_type = ceres::DENSE_SVD;
  covariance_options.null_space_rank = -1;  // pseudo-inverse when rank deficient
  ceres::Covariance covariance(covariance_options);
  std::vector<std::pair<const double*, const double*>> blocks = {
      {x.q, x.q}, {x.bias, x.bias}, {x.offset, x.offset}};
  if (options.estimate_scale) blocks.emplace_back(x.scale, x.scale);
  if (!covariance.Compute(blocks, &problem)) return;
  const std::size_t parameter_count =
      7 + (options.estimate_scale ? 3 : 0) + (options.estimate_cross_coupling ? 3 : 0);
  const double sum =
      3.0 * static_cast<double>(window_count) * result.rms_residual_rad * result.rms_residual_rad;
  const double dof = std::max(1.0, 3.0 * static_cast<double>(window_count) - parameter_count);
  const double variance = sum / dof;
  double c3[9];
  // The 3x3 tangent-space block of the rotation. (GetCovarianceMatrixInTangentSpace with the
  // list {q, q} would write the 6x6 joint matrix of that list into this 9-double buffer.)
  covariance.GetCovarianceBlockInTangentSpace(x.q, x.q, c3);
  for (int i = 0; i < 3; ++i) result.sigma_rotation_rad[i] = std::sqrt(c3[4 * i] * variance);
  // A negative variance means a numerically rank-deficient problem: no usable sigma.
  result.covariance_ok = result.sigma_rotation_rad.allFinite();
  covariance.GetCovarianceBlock(x.bias, x.bias, c3);
  for (int i = 0; i < 3; ++i) result.sigma_bias_rad_s[i] = std::sqrt(c3[4 * i] * variance);
  if (options.estimate_scale) {
    covariance.GetCovarianceBlock(x.scale, x.scale, c3);
    for (int i = 0; i < 3; ++i) result.sigma_scale[i] = std::sqrt(c3[4 * i] * variance);
  }
  double c1 = 0.0;
  covariance.GetCovarianceBlock(x.offset, x.offset, &c1);
  result.sigma_time_offset_s = std::sqrt(c1 * variance);
  result.covariance_ok = result.covariance_ok && result.sigma_bias_rad_s.allFinite() &&
                         result.sigma_scale.allFinite() &&
                         std::isfinite(result.sigma_time_offset_s);
}

// Gravity's direction in B from the still samples.
Eigen::Vector3d up_in_base(const ToolImuRecord& record, const RotationCalibration& calibration,
                           double rest_rate_rad_s) {
  const RobotRateSeries robot = robot_tool_rate(record);
  Eigen::Vector3d up_sum = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < record.t_s.size(); ++k) {
    Eigen::Vector3d w;
    Eigen::Quaterniond q_B_T;
    const double t_robot_s = record.t_s[k] - calibration.time_offset_s;
    if (record.acc_m_s2[k].isZero(0.0)) continue;
    if (!robot_rate_at(robot, t_robot_s, w) || w.norm() > rest_rate_rad_s) continue;
    if (!robot_orientation_at(record, t_robot_s, q_B_T)) continue;
    up_sum += q_B_T * (calibration.q_T_S * record.acc_m_s2[k]).normalized();
  }
  return up_sum.norm() > 0.0 ? Eigen::Vector3d(up_sum.normalized()) : Eigen::Vector3d::UnitZ();
}

// The bias prior from the rests (null without one), weighted against windows whose RMS residual
// per component is window_rms_rad. A zero sigma (identical readings) is floored at 1e-6 rad/s.
std::optional<BiasPrior> rest_bias_prior(const GyroRestBias& rest, double window_rms_rad) {
  if (rest.sample_count == 0) return std::nullopt;
  BiasPrior prior;
  prior.mean_rad_s = rest.mean_rad_s;
  prior.weight_s = window_rms_rad * rest.sigma_rad_s.cwiseMax(1e-6).cwiseInverse();
  return prior;
}
}  // namespace

bool gyro_bias_at_rest(const ToolImuRecord& record, double time_offset_s, double rest_rate_rad_s,
                       Eigen::Vector3d& bias_rad_s, double max_time_s) {
  GyroRestBias rest;
  if (!gyro_rest_bias(record, time_offset_s, rest_rate_rad_s, rest, max_time_s)) return false;
  bias_rad_s = rest.mean_rad_s;
  return true;
}

RotationCalibration calibrate_rotation(const ToolImuRecord& record, const ToolImuAnalysis& analysis,
                                       const RotationCalibrationOptions& options) {
  if (!record.has_raw_imu) {
    throw InputError(record.file, 0, "gyro_x_dps", "rotation calibration needs raw gyro columns");
  }
  RotationCalibration result;
  const double offset = analysis.time_offset_s;
  const Eigen::Quaterniond q_T_S(analysis.R_T_S);
  GyroRestBias rest;
  if (gyro_rest_bias(record, offset, options.rest_rate_rad_s, rest)) {
    result.rest_bias_rad_s = rest.mean_rad_s;
    result.sigma_rest_bias_rad_s = rest.sigma_rad_s;
    result.rest_sample_count = rest.sample_count;
  }
  const double scale = analysis.gyro_scale_ratio;
  const std::vector<Window> windows =
      usable_windows(record, analysis, options, offset, result.skipped_window_count);
  if (windows.size() < 10) {
    throw InputError(record.file, 0, "t_s",
                     fmt::format("only {} usable windows of {:.2f} s for the rotation calibration",
                                 windows.size(), options.window_s));
  }
  const Eigen::Vector3d& bias = rest.mean_rad_s;  // zero without rests
  Unknowns x{{q_T_S.x(), q_T_S.y(), q_T_S.z(), q_T_S.w()},
             {bias.x(), bias.y(), bias.z()},
             {scale, scale, scale},
             {0.0, 0.0, 0.0},
             {offset}};
  result.initial_rms_residual_rad = initial_rms_residual(record, windows, x);
  result.window_count = windows.size();

  // First the windows alone; then, with the rests as a prior weighted by that fit's scatter,
  // again from its result.
  auto problem = std::make_unique<ceres::Problem>();
  add_windows(record, windows, options, nullptr, x, *problem);
  solve_or_refuse(record, options, *problem, result);
  result.rms_residual_rad = window_rms(record, windows, options, x, result.outlier_window_count);
  const std::optional<BiasPrior> prior =
      options.rest_bias_prior ? rest_bias_prior(rest, result.rms_residual_rad) : std::nullopt;
  if (prior) {
    problem = std::make_unique<ceres::Problem>();
    add_windows(record, windows, options, &*prior, x, *problem);
    solve_or_refuse(record, options, *problem, result);
    result.rms_residual_rad = window_rms(record, windows, options, x, result.outlier_window_count);
    result.rest_bias_prior_used = true;
  }

  result.q_T_S = rotation_of(x);
  result.gyro_bias_rad_s = Eigen::Vector3d(x.bias);
  result.gyro_scale = Eigen::Vector3d(x.scale);
  result.gyro_cross_coupling = Eigen::Vector3d(x.coupling);
  result.time_offset_s = x.offset[0];
  covariance_sigma(options, windows.size(), *problem, x, result);
  result.covariance_sigma_rotation_rad = result.sigma_rotation_rad;
  result.covariance_sigma_time_offset_s = result.sigma_time_offset_s;
  if (options.bootstrap_replicates > 0) {
    block_bootstrap_sigma(record, windows, options, prior ? &*prior : nullptr, x, result);
  }
  result.up_B = up_in_base(record, result, options.rest_rate_rad_s);
  return result;
}

}  // namespace imscal::calib
