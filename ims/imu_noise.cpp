#include "ims/imu_noise.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace imscal::ims {

double NormalDraws::next() {
  if (has_spare_) {
    has_spare_ = false;
    return spare_;
  }
  double u, v, s;
  do {
    // Uniform in (-1, 1) from the top 53 bits.
    u = static_cast<double>(rng_() >> 11) * 0x1.0p-52 - 1.0;
    v = static_cast<double>(rng_() >> 11) * 0x1.0p-52 - 1.0;
    s = u * u + v * v;
  } while (s >= 1.0 || s == 0.0);
  const double factor = std::sqrt(-2.0 * std::log(s) / s);
  spare_ = v * factor;
  has_spare_ = true;
  return u * factor;
}

namespace {
TriadErrors draw_triad(const TriadSpec& spec, NormalDraws& normal) {
  TriadErrors t;
  for (int i = 0; i < 3; ++i) t.bias[i] = spec.turn_on_bias_sigma * normal.next();
  for (int i = 0; i < 3; ++i) t.scale_factor[i] = spec.scale_factor_sigma * normal.next();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      if (r != c) t.misalignment(r, c) = spec.misalignment_sigma * normal.next();
    }
  }
  return t;
}

// The running stochastic state of one triad.
class TriadNoise {
 public:
  TriadNoise(const TriadSpec& spec, const TriadErrors& errors, NormalDraws& normal)
      : spec_(spec), errors_(errors), normal_(normal) {
    for (const auto& term : spec.bias_instability) {
      Eigen::Vector3d b;
      for (int i = 0; i < 3; ++i) b[i] = term.sigma * normal_.next();  // stationary start
      gm_state_.push_back(b);
    }
  }

  // Output increment for the ideal increment over dt.
  Eigen::Vector3d step(const Eigen::Vector3d& ideal, double dt) {
    in_run_mean_.setZero();
    Eigen::Vector3d raw = errors_.apply(ideal, dt);
    const double white_sigma = spec_.white_noise_density * std::sqrt(dt);
    for (int i = 0; i < 3; ++i) raw[i] += white_sigma * normal_.next();
    for (std::size_t j = 0; j < gm_state_.size(); ++j) {
      const GaussMarkovTerm& term = spec_.bias_instability[j];
      const double rho = std::exp(-dt / term.correlation_time_s);
      // 1 - rho^2 = -expm1(-2 dt / tau), without the cancellation for dt << tau.
      const double drive = term.sigma * std::sqrt(-std::expm1(-2.0 * dt / term.correlation_time_s));
      const Eigen::Vector3d before = gm_state_[j];
      for (int i = 0; i < 3; ++i) gm_state_[j][i] = rho * before[i] + drive * normal_.next();
      raw += 0.5 * (before + gm_state_[j]) * dt;
      in_run_mean_ += 0.5 * (before + gm_state_[j]);
    }
    if (spec_.range > 0.0) {
      const double limit = spec_.range * dt;
      raw = raw.cwiseMax(-limit).cwiseMin(limit);
    }
    if (spec_.quantization_lsb > 0.0) {
      const Eigen::Vector3d wanted = raw + residual_;
      for (int i = 0; i < 3; ++i) {
        // + 0.0 turns a -0 (a negative value rounded to zero LSB) into +0.
        raw[i] = spec_.quantization_lsb * std::round(wanted[i] / spec_.quantization_lsb) + 0.0;
      }
      residual_ = wanted - raw;
    }
    return raw;
  }

  // The in-run bias over the last step's interval (sum of the Gauss-Markov terms' means).
  const Eigen::Vector3d& in_run_mean() const { return in_run_mean_; }

 private:
  const TriadSpec& spec_;
  const TriadErrors& errors_;
  NormalDraws& normal_;
  std::vector<Eigen::Vector3d> gm_state_;
  Eigen::Vector3d residual_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d in_run_mean_ = Eigen::Vector3d::Zero();
};
}  // namespace

SensorErrorModel draw_sensor_errors(const SensorSpec& spec, std::mt19937_64& rng) {
  NormalDraws normal(rng);
  SensorErrorModel model;
  model.gyro = draw_triad(spec.gyro, normal);
  model.acc = draw_triad(spec.acc, normal);
  return model;
}

ImuSeries corrupt(const ImuSeries& ideal, const SensorErrorModel& errors, const SensorSpec& spec,
                  std::uint64_t seed, InRunBias* in_run) {
  std::mt19937_64 rng(seed);
  NormalDraws normal(rng);
  TriadNoise gyro(spec.gyro, errors.gyro, normal);
  TriadNoise acc(spec.acc, errors.acc, normal);
  ImuSeries out = ideal;
  const bool rates = ideal.quantity == ImuQuantity::kRates;
  for (std::size_t k = 0; k < ideal.samples.size(); ++k) {
    const double dt = sample_interval(ideal, k);
    if (!(dt > 0.0)) {
      throw std::invalid_argument("corrupt: sample times must increase (sample " +
                                  std::to_string(k) + ")");
    }
    const double to_increment = rates ? dt : 1.0;
    ImuSample& s = out.samples[k];
    s.gyro = gyro.step(ideal.samples[k].gyro * to_increment, dt) / to_increment;
    s.acc = acc.step(ideal.samples[k].acc * to_increment, dt) / to_increment;
    if (in_run != nullptr) {
      in_run->t_s.push_back(s.t_s);
      in_run->gyro_rad_s.push_back(gyro.in_run_mean());
      in_run->acc_m_s2.push_back(acc.in_run_mean());
    }
  }
  return out;
}

}  // namespace imscal::ims
