#include "calib/rest_stillness.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "core/input_error.hpp"
#include "ims/zupt_options.hpp"

namespace imscal::calib {
namespace {

// The searches for a still part test every pair of every candidate run (~K^4 / 24 pair tests
// for K blocks): longer intervals get longer blocks.
constexpr std::size_t kMaxBlocks = 40;

// One block of the interval: mean specific force and gyro rate, the block means of the gyro
// angle integrated from the interval's begin and of the time, and the flange rotation the
// readings show over it.
struct Block {
  double duration_s = 0.0;
  double t_mean_s = 0.0;
  Eigen::Vector3d acc_mean_m_s2 = Eigen::Vector3d::Zero();
  Eigen::Vector3d gyro_mean_rad_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d angle_mean_rad = Eigen::Vector3d::Zero();
  Eigen::Vector3d explained_rad = Eigen::Vector3d::Zero();
};

// What the sensor spec says about a pair of blocks at rest.
struct NoiseModel {
  double gyro_density = 0.0;     // ARW [rad/sqrt(s)]
  double gyro_lsb_rad = 0.0;     // increment quantisation [rad]
  double gyro_bias_bound = 0.0;  // 3 sigma of turn-on and in-run bias [rad/s]
  double acc_density = 0.0;      // VRW [m/s^2/sqrt(s)]
  double acc_lsb_m_s = 0.0;      // increment quantisation [m/s]
  std::vector<ims::GaussMarkovTerm> acc_drift;
  double earth_rate_up = 0.0;          // Omega sin(latitude) [rad/s]
  double earth_rate_horizontal = 0.0;  // Omega cos(latitude) [rad/s]
  double model_fraction = 0.0;
};

struct PairTest {
  double statistic = 0.0;        // sum of squared normalised components beyond the slack
  double unexplained_rad = 0.0;  // the components beyond the slack, as one angle
  double explained_rad = 0.0;
};

PairTest test_pair(const Block& a, const Block& b, double block_s, const Eigen::Vector3d& up,
                   const Eigen::Vector3d& horizontal, double gravity, const NoiseModel& m) {
  const double d = b.t_mean_s - a.t_mean_s;
  const Eigen::Vector3d angle = b.angle_mean_rad - a.angle_mean_rad;
  const double about_up = angle.dot(up) - m.earth_rate_up * d;
  const double about_horizontal = angle.dot(horizontal) - m.earth_rate_horizontal * d;
  const double tilt =
      -up.cross(b.acc_mean_m_s2 - a.acc_mean_m_s2).dot(up.cross(horizontal)) / gravity;
  // Noise at rest. Gyro: the integrated ARW between block means d apart, N^2 (d - L/3), and the
  // carried quantisation residuals (each uniform in +-LSB/2). Accelerometers: two block means
  // of white noise and quantisation, and the in-run bias drift over d.
  const double gyro_var = m.gyro_density * m.gyro_density * std::max(d - block_s / 3.0, 0.0) +
                          m.gyro_lsb_rad * m.gyro_lsb_rad / 6.0;
  double acc_var = 2.0 * (m.acc_density * m.acc_density / block_s +
                          m.acc_lsb_m_s * m.acc_lsb_m_s / (6.0 * block_s * block_s));
  for (const ims::GaussMarkovTerm& term : m.acc_drift)
    acc_var += 2.0 * term.sigma * term.sigma * (1.0 - std::exp(-d / term.correlation_time_s));
  const double tilt_sigma = std::sqrt(acc_var) / gravity;
  const double gyro_sigma = std::sqrt(gyro_var);
  // What the readings (and, for the gyros, a bias within its bound) explain, in any direction.
  PairTest t;
  t.explained_rad = (b.explained_rad - a.explained_rad).norm();
  const double slack = (1.0 + m.model_fraction) * t.explained_rad;
  const double gyro_slack = slack + m.gyro_bias_bound * d;
  const double up_beyond = std::max(std::abs(about_up) - gyro_slack, 0.0);
  const double horizontal_beyond = std::max(std::abs(about_horizontal) - gyro_slack, 0.0);
  const double tilt_beyond = std::max(std::abs(tilt) - slack, 0.0);
  t.statistic = std::pow(up_beyond / gyro_sigma, 2) + std::pow(horizontal_beyond / gyro_sigma, 2) +
                std::pow(tilt_beyond / tilt_sigma, 2);
  t.unexplained_rad = std::sqrt(up_beyond * up_beyond + horizontal_beyond * horizontal_beyond +
                                tilt_beyond * tilt_beyond);
  return t;
}

struct RunTest {
  bool still = true;
  PairTest worst;
  std::size_t worst_a = 0, worst_b = 0;
};

// Every pair of blocks [first, last] against the threshold, with the run's own up and
// horizontal directions (the mean specific force and the horizontal part of the mean gyro
// rate).
RunTest test_run(const std::vector<Block>& blocks, std::size_t first, std::size_t last,
                 double block_s, double threshold, const NoiseModel& m) {
  Eigen::Vector3d acc = Eigen::Vector3d::Zero(), gyro = Eigen::Vector3d::Zero();
  for (std::size_t k = first; k <= last; ++k) {
    acc += blocks[k].acc_mean_m_s2;
    gyro += blocks[k].gyro_mean_rad_s;
  }
  const double gravity = acc.norm() / double(last - first + 1);
  const Eigen::Vector3d up = acc.normalized();
  Eigen::Vector3d horizontal = gyro - gyro.dot(up) * up;
  // At the poles there is no horizontal Earth rate: any horizontal direction will do.
  if (!(horizontal.norm() > 0.0)) horizontal = up.unitOrthogonal();
  horizontal.normalize();
  RunTest r;
  for (std::size_t a = first; a < last; ++a) {
    for (std::size_t b = a + 1; b <= last; ++b) {
      const PairTest t = test_pair(blocks[a], blocks[b], block_s, up, horizontal, gravity, m);
      if (t.statistic > r.worst.statistic) {
        r.worst = t;
        r.worst_a = a;
        r.worst_b = b;
      }
    }
  }
  r.still = !(r.worst.statistic > threshold);
  return r;
}

}  // namespace

double chi_square_3_upper_quantile(double probability) {
  // Upper tail of chi-square(3): erfc(sqrt(c / 2)) + sqrt(2 c / pi) exp(-c / 2).
  const auto tail = [](double c) {
    return std::erfc(std::sqrt(c / 2.0)) +
           std::sqrt(2.0 * c / std::numbers::pi) * std::exp(-c / 2.0);
  };
  double low = 0.0, high = 1e3;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (low + high);
    (tail(mid) > probability ? low : high) = mid;
  }
  return 0.5 * (low + high);
}

std::string RestStillness::describe() const {
  if (!flagged) return "";
  return fmt::format(
      "the IMS shows the flange turn by {:.3g} rad ({:.3g} rad/s on average) between {:.3f} s and "
      "{:.3f} s beyond the {:.3g} rad the joint readings explain (test {:.3g} > {:.3g}, "
      "chi-square 3)",
      unexplained_rotation_rad, rate_change_rad_s, motion_begin_ims_s, motion_end_ims_s,
      explained_rotation_rad, test_statistic, threshold);
}

RestStillness assess_rest_stillness(const ims::ImuSeries& imu, const ims::EarthModel& earth,
                                    const ims::SensorSpec& sensor, double begin_ims_s,
                                    double end_ims_s, const ExplainedRotation& explained,
                                    const RestStillnessOptions& options) {
  RestStillness result;
  result.still_begin_ims_s = begin_ims_s;
  result.still_end_ims_s = end_ims_s;
  if (!(options.block_s > 0.0) || !(options.false_alarm_per_rest > 0.0))
    throw InputError(imu.source, 0, "rest stillness",
                     "block length and false-alarm rate must be > 0");
  const double duration = end_ims_s - begin_ims_s;
  const double block_s = std::max(options.block_s, duration / double(kMaxBlocks));
  const std::size_t count = std::size_t(std::floor(duration / block_s + 1e-9));
  if (count < 2) return result;

  // Samples in the interval and their increments (rates times the sample interval).
  const auto& samples = imu.samples;
  const auto begin_it =
      std::lower_bound(samples.begin(), samples.end(), begin_ims_s,
                       [](const ims::ImuSample& s, double t) { return s.t_s < t; });
  const bool increments = imu.quantity == ims::ImuQuantity::kIncrements;
  std::vector<Block> blocks(count);
  std::vector<std::size_t> sample_count(count, 0);
  Eigen::Vector3d angle = Eigen::Vector3d::Zero();
  for (auto it = begin_it; it != samples.end() && it->t_s < begin_ims_s + double(count) * block_s;
       ++it) {
    const std::size_t k = std::min(count - 1, std::size_t((it->t_s - begin_ims_s) / block_s));
    const double dt = it == samples.begin() ? imu.nominal_dt_s : it->t_s - (it - 1)->t_s;
    const Eigen::Vector3d d_angle = increments ? it->gyro : Eigen::Vector3d(it->gyro * dt);
    const Eigen::Vector3d d_velocity = increments ? it->acc : Eigen::Vector3d(it->acc * dt);
    angle += d_angle;
    Block& b = blocks[k];
    b.duration_s += dt;
    b.t_mean_s += it->t_s;
    b.acc_mean_m_s2 += d_velocity;
    b.gyro_mean_rad_s += d_angle;
    b.angle_mean_rad += angle;
    ++sample_count[k];
  }
  for (std::size_t k = 0; k < count; ++k) {
    Block& b = blocks[k];
    if (sample_count[k] == 0 || !(b.duration_s > 0.0))
      throw InputError(imu.source, 0, "rest stillness",
                       fmt::format("no IMS samples in {:.3f} .. {:.3f} s",
                                   begin_ims_s + k * block_s, begin_ims_s + (k + 1) * block_s));
    b.t_mean_s /= double(sample_count[k]);
    b.angle_mean_rad /= double(sample_count[k]);
    b.acc_mean_m_s2 /= b.duration_s;
    b.gyro_mean_rad_s /= b.duration_s;
    if (explained)
      b.explained_rad = explained(begin_ims_s + k * block_s, begin_ims_s + (k + 1) * block_s);
  }

  NoiseModel m;
  m.gyro_density = sensor.gyro.white_noise_density;
  m.gyro_lsb_rad = sensor.gyro.quantization_lsb;
  // 3 sigma of turn-on and in-run bias, as the rest detector bounds it (calib/rest_poses.cpp).
  m.gyro_bias_bound = 3.0 * ims::zupt_options_from_spec(sensor).initial_gyro_bias_sigma_rad_s;
  m.acc_density = sensor.acc.white_noise_density;
  m.acc_lsb_m_s = sensor.acc.quantization_lsb;
  m.acc_drift = sensor.acc.bias_instability;
  // W is ENU: the Earth rate's up and horizontal parts.
  m.earth_rate_up = earth.earth_rate_W().z();
  m.earth_rate_horizontal = earth.earth_rate_W().head<2>().norm();
  m.model_fraction = options.readings_model_fraction;

  const double pairs = double(count * (count - 1) / 2);
  result.threshold = chi_square_3_upper_quantile(options.false_alarm_per_rest / pairs);
  const RunTest whole = test_run(blocks, 0, count - 1, block_s, result.threshold, m);
  result.test_statistic = whole.worst.statistic;
  if (whole.still) return result;

  result.flagged = true;
  result.unexplained_rotation_rad = whole.worst.unexplained_rad;
  result.explained_rotation_rad = whole.worst.explained_rad;
  result.motion_begin_ims_s = blocks[whole.worst_a].t_mean_s;
  result.motion_end_ims_s = blocks[whole.worst_b].t_mean_s;
  result.rate_change_rad_s =
      result.unexplained_rotation_rad / (result.motion_end_ims_s - result.motion_begin_ims_s);
  // The longest still run (the latest of equally long ones: the arm settles towards a rest's
  // end), tested with the same threshold.
  const std::size_t min_blocks =
      std::max<std::size_t>(2, std::size_t(std::ceil(options.min_still_s / block_s - 1e-9)));
  result.usable = false;
  for (std::size_t length = count - 1; length >= min_blocks && !result.usable; --length) {
    for (std::size_t first = count - length + 1; first-- > 0;) {
      if (!test_run(blocks, first, first + length - 1, block_s, result.threshold, m).still)
        continue;
      result.usable = true;
      result.still_begin_ims_s = begin_ims_s + double(first) * block_s;
      result.still_end_ims_s = begin_ims_s + double(first + length) * block_s;
      break;
    }
  }
  return result;
}

}  // namespace imscal::calib
