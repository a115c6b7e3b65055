#include "ims/coarse_alignment.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "ims/so3.hpp"

namespace imscal::ims {
namespace {

double wrap_pi(double angle) {
  return std::remainder(angle, 2.0 * M_PI);
}

// One block of the interval: specific force averaged in the frame m, at its mean time.
struct Block {
  Eigen::Vector3d force_sum_m = Eigen::Vector3d::Zero();  // sum of velocity increments [m/s]
  double duration_s = 0.0;
  double time_weighted_s = 0.0;  // sum of dt * (midpoint time - t_ref)
  bool used = true;
  Eigen::Vector3d force() const { return force_sum_m / duration_s; }
  double time() const { return time_weighted_s / duration_s; }  // relative to t_ref
};

// Least-squares line F = f_ref + s t over the used blocks, per axis.
struct LineFit {
  Eigen::Vector3d f_ref = Eigen::Vector3d::Zero();
  Eigen::Vector3d slope = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> residuals;  // per used block
  std::vector<double> times;               // per used block, relative to t_ref [s]
  Eigen::MatrixXd weights;                 // 2 x n: rows give f_ref and slope from the data
};

LineFit fit_line(const std::vector<Block>& blocks, const Eigen::Vector3d& omega_m) {
  LineFit fit;
  std::vector<Eigen::Vector3d> derotated;
  for (const Block& block : blocks) {
    if (!block.used) continue;
    const double t = block.time();
    // W turned by exp(t [omega x]) since t_ref; undo it so that F is constant at rest.
    derotated.push_back(quat_exp(Eigen::Vector3d(-t * omega_m)) * block.force());
    fit.times.push_back(t);
  }
  const int n = static_cast<int>(fit.times.size());
  Eigen::MatrixXd design(n, 2);
  for (int k = 0; k < n; ++k) design.row(k) << 1.0, fit.times[k];
  fit.weights = (design.transpose() * design).inverse() * design.transpose();
  for (int k = 0; k < n; ++k) {
    fit.f_ref += fit.weights(0, k) * derotated[k];
    fit.slope += fit.weights(1, k) * derotated[k];
  }
  for (int k = 0; k < n; ++k) {
    fit.residuals.push_back(derotated[k] - fit.f_ref - fit.slope * fit.times[k]);
  }
  return fit;
}

// Gauss-Newton on the horizontal Earth-rate direction; the vertical part is known.
struct RateSolution {
  Eigen::Vector3d omega_m = Eigen::Vector3d::Zero();
  LineFit fit;
  int iterations = 0;
};

RateSolution solve_rate(const std::vector<Block>& blocks, double vertical_rate_rad_s,
                        int max_iterations) {
  RateSolution solution;
  for (int it = 0; it < max_iterations; ++it) {
    solution.fit = fit_line(blocks, solution.omega_m);
    const Eigen::Vector3d& f = solution.fit.f_ref;
    const Eigen::Vector3d up = f.normalized();
    const Eigen::Vector3d correction = f.cross(solution.fit.slope) / f.squaredNorm();
    Eigen::Vector3d horizontal = solution.omega_m - solution.omega_m.dot(up) * up + correction;
    horizontal -= horizontal.dot(up) * up;
    solution.omega_m = horizontal + vertical_rate_rad_s * up;
    solution.iterations = it + 1;
    // 1e-14 rad/s is 1e-10 of the horizontal Earth rate: far below any heading resolution.
    if (correction.norm() < 1e-14) break;
  }
  solution.fit = fit_line(blocks, solution.omega_m);
  return solution;
}

// Attitude of S at t_ref from the line parameters: f_ref (up) and the horizontal Earth rate,
// perturbed by a slope change ds (which moves the rate by f x ds / |f|^2). TRIAD with the
// specific force as the primary vector, against the model's f_W = -g_W and omega_ie_W (the
// normal-gravity plumb line deviates from the ellipsoid normal by ~1e-7 rad at 300 m height).
Eigen::Matrix3d attitude_from(const Eigen::Vector3d& f_ref, const Eigen::Vector3d& omega_m,
                              const Eigen::Vector3d& slope_change, const EarthModel& earth) {
  auto triad = [](const Eigen::Vector3d& primary, const Eigen::Vector3d& secondary) {
    Eigen::Matrix3d axes;
    axes.col(0) = primary.normalized();
    axes.col(1) = primary.cross(secondary).normalized();
    axes.col(2) = axes.col(0).cross(axes.col(1));
    return axes;
  };
  const Eigen::Vector3d omega = omega_m + f_ref.cross(slope_change) / f_ref.squaredNorm();
  const Eigen::Matrix3d in_S = triad(f_ref, omega);
  const Eigen::Matrix3d in_W = triad(-earth.gravity_origin_W(), earth.earth_rate_W());
  return in_W * in_S.transpose();  // R_W_S
}

// White + random-walk model of one axis' residuals, Sigma = sigma^2 (I + lambda K) with K the
// random walk anchored at t_ref (shared history only on the same side of t_ref). lambda is
// chosen on a grid by restricted maximum likelihood (REML: the likelihood of the residuals of
// the line fit, which does not depend on the line), sigma^2 in closed form for each lambda.
// Returns the covariance of the (f_ref, slope) of that axis from the least-squares weights.
Eigen::Matrix2d axis_parameter_covariance(const LineFit& fit, int axis) {
  const int n = static_cast<int>(fit.times.size());
  double t_max = 0.0;
  for (double t : fit.times) t_max = std::max(t_max, std::abs(t));
  Eigen::MatrixXd walk(n, n);  // K, scaled to at most 1
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const double ti = fit.times[i], tj = fit.times[j];
      walk(i, j) = (ti * tj > 0.0) ? std::min(std::abs(ti), std::abs(tj)) / t_max : 0.0;
    }
  }
  Eigen::MatrixXd design(n, 2);
  Eigen::VectorXd residual(n);
  for (int k = 0; k < n; ++k) {
    design.row(k) << 1.0, fit.times[k];
    residual[k] = fit.residuals[k][axis];
  }
  double best_log_likelihood = -std::numeric_limits<double>::infinity();
  double white_log_likelihood = 0.0;
  Eigen::MatrixXd white_covariance;
  Eigen::MatrixXd best_covariance;
  // lambda = 0 (white only) and 10^-3 .. 10^5 in steps of 10^0.25 (a 78 % step in the ratio,
  // about what the likelihood can resolve with a few tens of blocks).
  for (int g = -1; g <= 32; ++g) {
    const double lambda = g < 0 ? 0.0 : std::pow(10.0, -3.0 + 0.25 * g);
    const Eigen::MatrixXd V = Eigen::MatrixXd::Identity(n, n) + lambda * walk;
    const Eigen::LLT<Eigen::MatrixXd> llt(V);
    if (llt.info() != Eigen::Success) continue;
    const Eigen::MatrixXd Vinv_A = llt.solve(design);
    const Eigen::Matrix2d AtVinvA = design.transpose() * Vinv_A;
    const Eigen::VectorXd Vinv_r = llt.solve(residual);
    const Eigen::VectorXd projected =
        Vinv_r - Vinv_A * AtVinvA.ldlt().solve(design.transpose() * Vinv_r);
    const double quadratic = residual.dot(projected);
    if (!(quadratic > 0.0)) continue;
    const double sigma_sq = quadratic / (n - 2);
    double log_det_V = 0.0;
    for (int i = 0; i < n; ++i) log_det_V += 2.0 * std::log(llt.matrixL()(i, i));
    const double log_likelihood =
        -0.5 * ((n - 2) * std::log(sigma_sq) + log_det_V + std::log(AtVinvA.determinant()));
    if (g < 0) {
      white_log_likelihood = log_likelihood;
      white_covariance = sigma_sq * V;
    }
    if (log_likelihood > best_log_likelihood) {
      best_log_likelihood = log_likelihood;
      best_covariance = sigma_sq * V;
    }
  }
  if (white_covariance.size() == 0) return Eigen::Matrix2d::Zero();  // noise-free residuals
  // The random walk is taken only when it is significant: a likelihood-ratio test at 99 % (half
  // the chi^2(1) quantile 6.63). White noise alone otherwise often fits a spurious walk, which
  // inflates the slope's sigma several times in those draws (seen on synthetic white noise).
  if (best_log_likelihood - white_log_likelihood < 3.32) best_covariance = white_covariance;
  return fit.weights * best_covariance * fit.weights.transpose();
}

}  // namespace

AttitudeAngles attitude_angles(const Eigen::Matrix3d& R_W_S) {
  const Eigen::Vector3d x_W = R_W_S.col(0), y_W = R_W_S.col(1), z_W = R_W_S.col(2);
  AttitudeAngles angles;
  angles.pitch_rad = std::asin(std::clamp(y_W.z(), -1.0, 1.0));
  angles.roll_rad = std::atan2(-x_W.z(), z_W.z());
  angles.yaw_rad = std::atan2(-y_W.x(), y_W.y());
  angles.heading_rad = std::atan2(y_W.x(), y_W.y());
  if (angles.heading_rad < 0.0) angles.heading_rad += 2.0 * M_PI;
  return angles;
}

Eigen::Matrix3d R_W_S_from_angles(double roll_rad, double pitch_rad, double yaw_rad) {
  return (Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(pitch_rad, Eigen::Vector3d::UnitX()) *
          Eigen::AngleAxisd(roll_rad, Eigen::Vector3d::UnitY()))
      .toRotationMatrix();
}

SampleRange samples_in_interval(const ImuSeries& series, double start_s, double duration_s) {
  const auto& s = series.samples;
  // Tolerance for time stamps computed as t0 + k dt: far below one interval.
  const double tolerance = 1e-6 * series.nominal_dt_s;
  const auto begin = std::lower_bound(s.begin(), s.end(), start_s + series.nominal_dt_s - tolerance,
                                      [](const ImuSample& a, double t) { return a.t_s < t; });
  const auto end = std::upper_bound(s.begin(), s.end(), start_s + duration_s + tolerance,
                                    [](double t, const ImuSample& a) { return t < a.t_s; });
  SampleRange range;
  range.first = static_cast<std::size_t>(begin - s.begin());
  range.count = end > begin ? static_cast<std::size_t>(end - begin) : 0;
  return range;
}

CoarseAlignment align_at_rest(const ImuSeries& series, SampleRange range, const EarthModel& earth,
                              const CoarseAlignmentOptions& options) {
  const int block_count = options.block_count;
  if (block_count < 8) throw std::invalid_argument("coarse alignment: block_count must be >= 8");
  if (range.first + range.count > series.samples.size() ||
      range.count < static_cast<std::size_t>(4 * block_count)) {
    throw std::invalid_argument("coarse alignment: the interval holds " +
                                std::to_string(range.count) + " samples, need at least " +
                                std::to_string(4 * block_count));
  }
  if (std::abs(earth.site().latitude_deg) > 89.0) {
    throw std::invalid_argument("coarse alignment: no gyrocompassing within 1 deg of a pole");
  }
  const bool increments = series.quantity == ImuQuantity::kIncrements;
  const auto& samples = series.samples;
  auto interval_of = [&](std::size_t k) {
    if (k > 0) return samples[k].t_s - samples[k - 1].t_s;
    return series.nominal_dt_s;
  };

  CoarseAlignment result;
  result.first_sample = range.first;
  result.sample_count = range.count;
  result.start_s = samples[range.first].t_s - interval_of(range.first);
  result.end_s = samples[range.first + range.count - 1].t_s;
  const double duration = result.end_s - result.start_s;
  if (!(duration > 0.0))
    throw std::invalid_argument("coarse alignment: time stamps not increasing");
  const std::size_t ref_index = range.first + range.count / 2 - 1;
  result.t_ref_s = samples[ref_index].t_s;

  // Integrate the attitude of S in a non-rotating frame b (= S at the first sample) and sum the
  // velocity increments per block in b; rotated into m (= S at t_ref) afterwards.
  std::vector<Block> blocks(block_count);
  Eigen::Quaterniond q_b_S = Eigen::Quaterniond::Identity();
  Eigen::Quaterniond q_b_m = Eigen::Quaterniond::Identity();
  const double block_length = duration / block_count;
  for (std::size_t k = range.first; k < range.first + range.count; ++k) {
    const double dt = interval_of(k);
    if (!(dt > 0.0)) throw std::invalid_argument("coarse alignment: time stamps not increasing");
    const Eigen::Vector3d dtheta =
        increments ? samples[k].gyro : Eigen::Vector3d(samples[k].gyro * dt);
    const Eigen::Vector3d dv = increments ? samples[k].acc : Eigen::Vector3d(samples[k].acc * dt);
    const double mid_time = samples[k].t_s - 0.5 * dt;
    const int index = std::clamp(static_cast<int>((mid_time - result.start_s) / block_length), 0,
                                 block_count - 1);
    // First-order rotation compensation of the velocity increment (rotation during the sample).
    blocks[index].force_sum_m += q_b_S * (dv + 0.5 * dtheta.cross(dv));
    blocks[index].duration_s += dt;
    blocks[index].time_weighted_s += dt * (mid_time - result.t_ref_s);
    q_b_S = q_b_S * quat_exp(dtheta);
    q_b_S.normalize();
    if (k == ref_index) q_b_m = q_b_S;
  }
  for (Block& block : blocks) {
    if (block.duration_s <= 0.0) throw std::invalid_argument("coarse alignment: empty block");
    block.force_sum_m = q_b_m.conjugate() * block.force_sum_m;
  }

  // Earth rate along the plumb line (~Omega sin(lat)); the horizontal part is measured.
  const double vertical_rate = earth.earth_rate_W().dot(-earth.gravity_origin_W().normalized());
  RateSolution solution = solve_rate(blocks, vertical_rate, options.max_iterations);
  // Drop blocks that a disturbance's linear acceleration left off the line, then refit.
  std::vector<double> norms;
  for (const auto& r : solution.fit.residuals) norms.push_back(r.norm());
  std::vector<double> sorted = norms;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const double median = sorted[sorted.size() / 2];
  // 1e-9 m/s^2 (0.1 ng) keeps noise-free data from losing blocks to rounding.
  const double limit = std::max(options.outlier_factor * median, 1e-9);
  int rejected = 0;
  for (int k = 0; k < block_count; ++k) {
    if (norms[k] > limit && block_count - rejected > 8) {
      blocks[k].used = false;
      ++rejected;
    }
  }
  if (rejected > 0) solution = solve_rate(blocks, vertical_rate, options.max_iterations);

  const LineFit& fit = solution.fit;
  const Eigen::Matrix3d R_W_S =
      attitude_from(fit.f_ref, solution.omega_m, Eigen::Vector3d::Zero(), earth);
  result.q_W_S = Eigen::Quaterniond(R_W_S).normalized();
  result.angles = attitude_angles(R_W_S);

  // Covariance of the 6 line parameters (f_ref, slope), axes independent.
  Eigen::Matrix<double, 6, 6> parameter_cov = Eigen::Matrix<double, 6, 6>::Zero();
  for (int axis = 0; axis < 3; ++axis) {
    const Eigen::Matrix2d c = axis_parameter_covariance(fit, axis);
    parameter_cov(axis, axis) = c(0, 0);
    parameter_cov(3 + axis, 3 + axis) = c(1, 1);
    parameter_cov(axis, 3 + axis) = parameter_cov(3 + axis, axis) = c(0, 1);
  }
  // Jacobian of (roll, pitch, heading) by central differences. Steps: 1e-7 of |f| for f_ref
  // (angle change ~1e-7 rad, well inside the linear range and far above rounding), and a slope
  // step that turns the rate by ~1e-5 of its horizontal magnitude.
  const double force = fit.f_ref.norm();
  const Eigen::Vector3d omega_h =
      solution.omega_m - solution.omega_m.dot(fit.f_ref / force) * (fit.f_ref / force);
  const double steps[2] = {1e-7 * force, 1e-5 * omega_h.norm() * force};
  Eigen::Matrix<double, 3, 6> jacobian;
  for (int p = 0; p < 6; ++p) {
    Eigen::Vector3d df = Eigen::Vector3d::Zero(), ds = Eigen::Vector3d::Zero();
    const double h = steps[p / 3];
    (p < 3 ? df : ds)[p % 3] = h;
    const AttitudeAngles plus =
        attitude_angles(attitude_from(fit.f_ref + df, solution.omega_m, ds, earth));
    const AttitudeAngles minus =
        attitude_angles(attitude_from(fit.f_ref - df, solution.omega_m, -ds, earth));
    jacobian(0, p) = wrap_pi(plus.roll_rad - minus.roll_rad) / (2 * h);
    jacobian(1, p) = (plus.pitch_rad - minus.pitch_rad) / (2 * h);
    jacobian(2, p) = wrap_pi(plus.heading_rad - minus.heading_rad) / (2 * h);
  }
  result.angle_covariance = jacobian * parameter_cov * jacobian.transpose();
  result.sigma_roll_rad = std::sqrt(result.angle_covariance(0, 0));
  result.sigma_pitch_rad = std::sqrt(result.angle_covariance(1, 1));
  result.sigma_heading_rad = std::sqrt(result.angle_covariance(2, 2));

  result.specific_force_m_s2 = force;
  result.expected_gravity_m_s2 = earth.normal_gravity_magnitude();
  result.earth_rate_horizontal_rad_s = omega_h.norm();
  result.expected_earth_rate_horizontal_rad_s = earth.earth_rate_W().y();
  result.blocks_used = block_count - rejected;
  result.blocks_rejected = rejected;
  result.block_duration_s = block_length;
  result.iterations = solution.iterations;
  return result;
}

std::vector<CoarseAlignment> align_windows(const ImuSeries& series, SampleRange range,
                                           double window_s, const EarthModel& earth,
                                           const CoarseAlignmentOptions& options) {
  if (!(window_s > 0.0)) throw std::invalid_argument("coarse alignment: window must be > 0 s");
  std::vector<CoarseAlignment> windows;
  if (range.count == 0) return windows;
  const auto& s = series.samples;
  const double dt0 =
      range.first > 0 ? s[range.first].t_s - s[range.first - 1].t_s : series.nominal_dt_s;
  const double start = s[range.first].t_s - dt0;
  const double end = s[range.first + range.count - 1].t_s;
  // Half a sample of tolerance so that time stamps t0 + k dt fill a window exactly.
  for (int j = 0; start + (j + 1) * window_s <= end + 0.5 * series.nominal_dt_s; ++j) {
    const SampleRange window = samples_in_interval(series, start + j * window_s, window_s);
    windows.push_back(align_at_rest(series, window, earth, options));
  }
  return windows;
}

AngleSpread angle_spread(const std::vector<CoarseAlignment>& windows, AngleKind kind) {
  AngleSpread spread;
  if (windows.empty()) return spread;
  auto value = [&](const CoarseAlignment& a) {
    switch (kind) {
      case AngleKind::kRoll:
        return a.angles.roll_rad;
      case AngleKind::kPitch:
        return a.angles.pitch_rad;
      case AngleKind::kHeading:
        break;
    }
    return a.angles.heading_rad;
  };
  const double first = value(windows.front());
  std::vector<double> values;
  for (const auto& w : windows) values.push_back(first + wrap_pi(value(w) - first));
  double sum = 0.0;
  for (double v : values) sum += v;
  spread.mean_rad = sum / values.size();
  double sq = 0.0;
  for (double v : values) sq += (v - spread.mean_rad) * (v - spread.mean_rad);
  spread.std_rad = values.size() > 1 ? std::sqrt(sq / (values.size() - 1)) : 0.0;
  spread.min_rad = *std::min_element(values.begin(), values.end());
  spread.max_rad = *std::max_element(values.begin(), values.end());
  if (kind == AngleKind::kHeading) {
    const double shift =
        spread.mean_rad - std::fmod(std::fmod(spread.mean_rad, 2 * M_PI) + 2 * M_PI, 2 * M_PI);
    spread.mean_rad -= shift;
    spread.min_rad -= shift;
    spread.max_rad -= shift;
  }
  return spread;
}

}  // namespace imscal::ims
