#include "ims/zupt_smoother.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>

#include "core/input_error.hpp"
#include "ims/error_state_model.hpp"
#include "ims/sensor_error_model.hpp"
#include "ims/so3.hpp"
#include "ims/strapdown.hpp"
#include "ims/zupt_smoother_records.hpp"

namespace imscal::ims {
using namespace error_state;
using namespace zupt_records;

namespace {

constexpr double kChi2Dof3Quantile95 = 7.8147;  // chi-square(3) 95% quantile

using Matrix3x15 = Eigen::Matrix<double, 3, kSize>;

ErrorProcessNoise process_noise_of(const ZuptOptions& o) {
  ErrorProcessNoise noise;
  noise.gyro_white_psd.setConstant(o.gyro_noise_density_rad_per_sqrt_s *
                                   o.gyro_noise_density_rad_per_sqrt_s);
  noise.acc_white_psd.setConstant(o.acc_noise_density_m_s_per_sqrt_s *
                                  o.acc_noise_density_m_s_per_sqrt_s);
  // The bias state holds the turn-on bias (constant) plus the in-run Gauss-Markov part, so it
  // does not decay: it is modelled as a random walk driven by the Gauss-Markov noise, 2 sigma^2
  // / tau. That is exact for spans << tau and overstates the drift for longer ones.
  noise.gyro_bias_correlation_time_s = std::numeric_limits<double>::infinity();
  noise.acc_bias_correlation_time_s = std::numeric_limits<double>::infinity();
  const auto drive = [](double sigma, double tau) {
    return std::isfinite(tau) && tau > 0.0 ? 2.0 * sigma * sigma / tau : 0.0;
  };
  noise.gyro_bias_drive_psd.setConstant(
      drive(o.gyro_bias_instability_rad_s, o.gyro_bias_correlation_time_s));
  noise.acc_bias_drive_psd.setConstant(
      drive(o.acc_bias_instability_m_s2, o.acc_bias_correlation_time_s));
  return noise;
}

void check_options(const ImuSamples& imu, const ZuptOptions& o) {
  auto refuse = [&](const char* field, const char* problem) {
    throw InputError(imu.source, 0, field, problem);
  };
  if (imu.quantity != ImuQuantity::kIncrements) {
    refuse("quantity", "zero-velocity smoothing needs increments");
  }
  if (imu.samples.empty()) refuse("samples", "empty record");
  if (!(imu.nominal_dt_s > 0.0)) refuse("nominal_dt_s", "must be positive");
  if (!(o.gyro_noise_density_rad_per_sqrt_s > 0.0) || !(o.acc_noise_density_m_s_per_sqrt_s > 0.0)) {
    refuse("noise density", "gyro and accelerometer noise densities must be positive");
  }
  if (!(o.zero_velocity_sigma_m_s > 0.0)) refuse("zero_velocity_sigma_m_s", "must be positive");
  if (!(o.propagation_interval_s > 0.0)) refuse("propagation_interval_s", "must be positive");
  if (!(o.innovation_gate_chi2 > 0.0)) refuse("innovation_gate_chi2", "must be positive");
}

struct UpdateTally {
  std::size_t accepted = 0, rejected = 0, above95 = 0;
  double nis_sum = 0.0;
  InnovationStatistics statistics() const {
    InnovationStatistics s;
    s.accepted = accepted;
    s.rejected = rejected;
    s.mean_nis = accepted ? nis_sum / double(accepted) : 0.0;
    s.fraction_above_95 = accepted ? double(above95) / double(accepted) : 0.0;
    return s;
  }
};

// Kalman update with a 3-component measurement z = H x + noise(R); Joseph form. Returns false
// (and changes nothing) when the innovation fails the gate.
bool update(ErrorVector& x, ErrorMatrix& P, const Eigen::Vector3d& z, const Matrix3x15& H,
            const Eigen::Matrix3d& R, double gate, UpdateTally& tally) {
  const Eigen::Vector3d innovation = z - H * x;
  const Eigen::Matrix3d S = H * P * H.transpose() + R;
  const Eigen::LDLT<Eigen::Matrix3d> S_ldlt(S);
  const double nis = innovation.dot(S_ldlt.solve(innovation));
  if (!(nis <= gate)) {
    ++tally.rejected;
    return false;
  }
  ++tally.accepted;
  tally.nis_sum += nis;
  if (nis > kChi2Dof3Quantile95) ++tally.above95;
  const Eigen::Matrix<double, kSize, 3> K = S_ldlt.solve(H * P).transpose();  // P H^T S^-1
  x += K * innovation;
  const ErrorMatrix I_KH = ErrorMatrix::Identity() - K * H;
  P = I_KH * P * I_KH.transpose() + K * R * K.transpose();
  P = 0.5 * (P + P.transpose());
  return true;
}

NavState apply_error(const NavState& nominal, const ErrorVector& e) {
  NavState corrected = nominal;
  corrected.q_W_S =
      (quat_exp(Eigen::Vector3d(e.segment<3>(kAttitude))) * nominal.q_W_S).normalized();
  corrected.v_W += e.segment<3>(kVelocity);
  corrected.p_W += e.segment<3>(kPosition);
  return corrected;
}

// Smoother gain C = P_f Phi^T P_p^-1, solved on the equilibrated P_p (its diagonal spans ~20
// orders of magnitude between positions and gyro biases).
ErrorMatrix smoother_gain(const ErrorMatrix& filtered_cov, const ErrorMatrix& transition,
                          const ErrorMatrix& predicted_cov) {
  // States without uncertainty (e.g. a bias declared exactly known) keep the scale 1; the LDLT
  // then treats their zero pivots as such.
  const ErrorVector scale = predicted_cov.diagonal().unaryExpr(
      [](double variance) { return variance > 0.0 ? 1.0 / std::sqrt(variance) : 1.0; });
  const ErrorMatrix scaled_pred = scale.asDiagonal() * predicted_cov * scale.asDiagonal();
  const ErrorMatrix rhs = scale.asDiagonal() * (transition * filtered_cov);  // D Phi P_f
  // (D P_p D) y = D Phi P_f  =>  P_p^-1 Phi P_f = D y  =>  C = (D y)^T.
  const ErrorMatrix y = scaled_pred.ldlt().solve(rhs);
  return (scale.asDiagonal() * y).transpose();
}

RestDetectorOptions rest_options_of(const ZuptOptions& o) {
  RestDetectorOptions r = o.rest;
  if (r.gyro_noise_density_rad_per_sqrt_s == 0.0) {
    r.gyro_noise_density_rad_per_sqrt_s = o.gyro_noise_density_rad_per_sqrt_s;
    r.gyro_quantization_lsb_rad = o.gyro_quantization_lsb_rad;
  }
  if (r.acc_noise_density_m_s_per_sqrt_s == 0.0) {
    r.acc_noise_density_m_s_per_sqrt_s = o.acc_noise_density_m_s_per_sqrt_s;
    r.acc_quantization_lsb_m_s = o.acc_quantization_lsb_m_s;
  }
  // A bias of 3 sigma still passes the magnitude tests.
  if (r.gyro_bias_bound_rad_s == 0.0)
    r.gyro_bias_bound_rad_s = 3.0 * o.initial_gyro_bias_sigma_rad_s;
  if (r.acc_bias_bound_m_s2 == 0.0) r.acc_bias_bound_m_s2 = 3.0 * o.initial_acc_bias_sigma_m_s2;
  return r;
}

EpochCovariances initial_covariances(const Eigen::Matrix<double, 9, 1>& initial_sigma,
                                     const ZuptOptions& options) {
  EpochCovariances first;
  first.filtered_cov.setZero();
  first.filtered_cov.diagonal().head<9>() = initial_sigma.cwiseAbs2();
  first.filtered_cov.diagonal().segment<3>(kGyroBias).setConstant(
      options.initial_gyro_bias_sigma_rad_s * options.initial_gyro_bias_sigma_rad_s);
  first.filtered_cov.diagonal().segment<3>(kAccBias).setConstant(
      options.initial_acc_bias_sigma_m_s2 * options.initial_acc_bias_sigma_m_s2);
  first.predicted_cov = first.filtered_cov;
  first.transition.setIdentity();
  return first;
}

Epoch initial_epoch(const NavState& initial, const ZuptOptions& options) {
  Epoch first;
  first.t_s = initial.t_s;
  first.gyro_bias = options.initial_gyro_bias_rad_s;
  first.acc_bias = options.initial_acc_bias_m_s2;
  return first;
}

// Rauch-Tung-Striebel on the error state. With the estimates fed back, the filtered error is
// zero after every update and so is its prediction: x_s(k) = C_k x_s^before(k + 1). Appends
// each instant's smoothed errors to `out`, from the last instant to the first.
void rts_backward_pass(EpochFile& epochs, CovarianceFile& covariances, SmoothedErrorFile& out) {
  const std::size_t last = epochs.size() - 1;
  SmoothedError s;
  s.after.setZero();
  EpochCovariances next = covariances.read(last);
  ErrorMatrix smoothed_cov = next.filtered_cov;
  s.variance = smoothed_cov.diagonal();
  s.before = epochs.read(last).correction;
  out.append_before(s);
  for (std::size_t k = last; k-- > 0;) {
    EpochCovariances current = covariances.read(k);
    const ErrorMatrix C = smoother_gain(current.filtered_cov, next.transition, next.predicted_cov);
    const ErrorVector before_next = s.before;
    s.after = C * before_next;
    smoothed_cov = current.filtered_cov + C * (smoothed_cov - next.predicted_cov) * C.transpose();
    smoothed_cov = 0.5 * (smoothed_cov + smoothed_cov.transpose());
    s.variance = smoothed_cov.diagonal().cwiseMax(0.0);
    s.before = s.after + epochs.read(k).correction;
    out.append_before(s);
    next = std::move(current);
  }
}

// Sample i without the biases estimated at the instant before its interval.
ImuSample bias_corrected(const ImuSamples& imu, std::size_t i, const Epoch& previous) {
  const double dt = imu.interval_s(i);
  ImuSample corrected = imu.samples[i];
  corrected.gyro -= previous.gyro_bias * dt;
  corrected.acc -= previous.acc_bias * dt;
  return corrected;
}

// The feedback of the forward pass at instant k (the same step as there).
void feed_back(Strapdown& strapdown, const ErrorVector& correction) {
  if (!correction.isZero(0.0)) strapdown.reset(apply_error(strapdown.state(), correction));
}

// Keeps only the rest samples inside the still intervals (sorted) and redoes the runs.
void restrict_rests(const ImuSamples& imu, const std::vector<TimeInterval>& still,
                    RestDetection& rest) {
  std::size_t j = 0;
  for (std::size_t i = 0; i < imu.samples.size(); ++i) {
    const double t = imu.samples[i].t_s;
    while (j < still.size() && still[j].end_s < t) ++j;
    if (j >= still.size() || t < still[j].begin_s) rest.at_rest[i] = false;
  }
  rest.intervals.clear();
  for (std::size_t i = 0; i < rest.at_rest.size();) {
    if (!rest.at_rest[i]) {
      ++i;
      continue;
    }
    std::size_t last = i;
    while (last + 1 < rest.at_rest.size() && rest.at_rest[last + 1]) ++last;
    rest.intervals.push_back({i, last, imu.samples[i].t_s, imu.samples[last].t_s});
    i = last + 1;
  }
}

// The aid's velocity at t, linearly between the two samples around it (at most max_gap_s apart).
bool aid_velocity_at(const SmootherAids& aids, double t, std::size_t& cursor, Eigen::Vector3d& v,
                     double& sigma) {
  const std::vector<VelocitySample>& series = aids.velocity;
  while (cursor + 1 < series.size() && series[cursor + 1].t_s < t) ++cursor;
  if (cursor + 1 >= series.size() || series[cursor].t_s > t) return false;
  const VelocitySample& a = series[cursor];
  const VelocitySample& b = series[cursor + 1];
  if (b.t_s - a.t_s > aids.max_velocity_gap_s || !(b.t_s > a.t_s)) return false;
  const double f = (t - a.t_s) / (b.t_s - a.t_s);
  v = (1.0 - f) * a.v_W + f * b.v_W;
  sigma = std::max(a.sigma_m_s, b.sigma_m_s);
  return sigma > 0.0;
}

}  // namespace

struct SmoothedStateStream::Record {
  Strapdown initial;
  EpochFile epochs;
  SmoothedErrorFile smoothed;
};

// Where the stream stands: the strapdown after sample `sample` - 1, in the interval ending at
// instant `instant`, with what the record holds for the instants before and at its end.
struct SmoothedStateStream::Cursor {
  Strapdown strapdown;
  std::size_t instant = 1;
  std::size_t sample = 0;
  Epoch start, end;
  SmoothedError smoothed_start, smoothed_end;

  // Reads the instants around the interval `instant` ends, when the record has it.
  void load(Record& record) {
    if (instant >= record.epochs.size()) return;
    start = record.epochs.read(instant - 1);
    end = record.epochs.read(instant);
    smoothed_start = record.smoothed.read(instant - 1);
    smoothed_end = record.smoothed.read(instant);
  }
};

SmoothedStateStream::SmoothedStateStream() = default;
SmoothedStateStream::SmoothedStateStream(std::unique_ptr<Record> record, ImuSamples imu)
    : imu_(std::move(imu)), record_(std::move(record)) {
  rewind();
}
SmoothedStateStream::~SmoothedStateStream() = default;
SmoothedStateStream::SmoothedStateStream(SmoothedStateStream&&) noexcept = default;
SmoothedStateStream& SmoothedStateStream::operator=(SmoothedStateStream&&) noexcept = default;

std::size_t SmoothedStateStream::size() const {
  return imu_.samples.size();
}

bool SmoothedStateStream::done() const {
  return !record_ || cursor_->instant >= record_->epochs.size();
}
void SmoothedStateStream::rewind() {
  if (!record_) return;
  cursor_ = std::make_unique<Cursor>(Cursor{record_->initial, 1, 0, {}, {}, {}, {}});
  cursor_->load(*record_);
}

std::vector<SmoothedBias> SmoothedStateStream::biases() {
  std::vector<SmoothedBias> out;
  if (!record_) return out;
  out.resize(record_->epochs.size());
  for (std::size_t k = 0; k < out.size(); ++k) {
    const Epoch epoch = record_->epochs.read(k);
    const SmoothedError smoothed = record_->smoothed.read(k);
    SmoothedBias& b = out[k];
    b.t_s = epoch.t_s;
    b.gyro_rad_s = epoch.gyro_bias + smoothed.after.segment<3>(kGyroBias);
    b.acc_m_s2 = epoch.acc_bias + smoothed.after.segment<3>(kAccBias);
    b.gyro_sigma_rad_s = smoothed.variance.segment<3>(kGyroBias).cwiseSqrt();
    b.acc_sigma_m_s2 = smoothed.variance.segment<3>(kAccBias).cwiseSqrt();
  }
  return out;
}

// The nominal state of every sample corrected by the smoothed error, interpolated linearly in
// time between the propagation instants that enclose the sample. The nominal states are
// mechanised again (the same steps as the forward pass, so the same states), instead of being
// kept per sample or per instant.
std::size_t SmoothedStateStream::next(std::vector<SmoothedState>& out, std::size_t max_states) {
  if (!record_) return 0;
  Cursor& c = *cursor_;
  std::size_t given = 0;
  while (c.instant < record_->epochs.size() && given < max_states) {
    const double t0 = c.start.t_s, t1 = c.end.t_s;
    for (; c.sample <= c.end.last_sample && given < max_states; ++c.sample, ++given) {
      c.strapdown.step(bias_corrected(imu_, c.sample, c.start));
      const NavState& nominal = c.strapdown.state();
      const double alpha = (nominal.t_s - t0) / (t1 - t0);
      const ErrorVector e = (1.0 - alpha) * c.smoothed_start.after + alpha * c.smoothed_end.before;
      const ErrorVector var =
          (1.0 - alpha) * c.smoothed_start.variance + alpha * c.smoothed_end.variance;
      SmoothedState& state = out.emplace_back();
      state.state = apply_error(nominal, e);
      state.sigma = var.head<9>().cwiseSqrt();
    }
    if (c.sample > c.end.last_sample) {
      feed_back(c.strapdown, c.end.correction);
      ++c.instant;
      c.load(*record_);
    }
  }
  return given;
}

ZuptSmootherResult smooth_with_zupt(const ImuSamples& imu, const EarthModel& earth,
                                    const NavState& initial,
                                    const Eigen::Matrix<double, 9, 1>& initial_sigma,
                                    const ZuptOptions& options, const SmootherAids& aids) {
  ZuptSmoothing smoothing =
      smooth_with_zupt_streamed(imu, earth, initial, initial_sigma, options, aids);
  ZuptSmootherResult result;
  result.states.reserve(imu.samples.size() + 1);  // room for a caller's initial state
  smoothing.states.next(result.states, imu.samples.size());
  result.biases = smoothing.states.biases();
  result.summary = std::move(smoothing.summary);
  return result;
}

ZuptSmoothing smooth_with_zupt_streamed(const ImuSamples& imu, const EarthModel& earth,
                                        const NavState& initial,
                                        const Eigen::Matrix<double, 9, 1>& initial_sigma,
                                        const ZuptOptions& options, const SmootherAids& aids) {
  check_options(imu, options);
  const std::size_t n = imu.samples.size();
  ZuptSmoothing result;

  RestDetection rest = detect_rest(imu, earth, rest_options_of(options));
  if (aids.still) restrict_rests(imu, *aids.still, rest);
  result.summary.rest_intervals = rest.intervals;

  const ErrorProcessNoise noise = process_noise_of(options);
  const std::size_t samples_per_epoch = std::max<std::size_t>(
      1, std::size_t(std::lround(options.propagation_interval_s / imu.nominal_dt_s)));
  const std::size_t epoch_count = (n + samples_per_epoch - 1) / samples_per_epoch;
  // Epoch k (1-based) mechanises samples [(k-1) M, min(n, k M)); at rest if all of them are.
  std::vector<bool> epoch_at_rest(epoch_count + 2, false);
  for (std::size_t k = 1; k <= epoch_count; ++k) {
    const std::size_t begin = (k - 1) * samples_per_epoch;
    const std::size_t end = std::min(n, begin + samples_per_epoch);
    epoch_at_rest[k] =
        std::all_of(rest.at_rest.begin() + std::ptrdiff_t(begin),
                    rest.at_rest.begin() + std::ptrdiff_t(end), [](bool b) { return b; });
  }
  // Epochs at least `margin_s` inside a rest.
  const auto rest_interior = [&](double margin_s) {
    const std::size_t margin =
        std::size_t(std::ceil(margin_s / (double(samples_per_epoch) * imu.nominal_dt_s)));
    std::vector<bool> interior(epoch_count + 2, false);
    for (std::size_t k = 1 + margin; k + margin <= epoch_count; ++k) {
      bool inside = true;
      for (std::size_t j = k - margin; j <= k + margin && inside; ++j) inside = epoch_at_rest[j];
      interior[k] = inside;
    }
    return interior;
  };
  const std::vector<bool> epoch_in_rest_interior = rest_interior(options.zero_rate_edge_margin_s);
  const std::vector<bool> epoch_zero_velocity = rest_interior(options.zero_velocity_edge_margin_s);

  // ---- forward pass ----
  EpochFile epochs;
  CovarianceFile covariances;
  Epoch previous = initial_epoch(initial, options);
  epochs.append(previous);
  const EpochCovariances first_covariances = initial_covariances(initial_sigma, options);
  covariances.append(first_covariances);
  ErrorMatrix previous_filtered_cov = first_covariances.filtered_cov;
  const Strapdown initial_strapdown(earth, initial);
  Strapdown strapdown = initial_strapdown;
  ErrorLinearisation point;
  point.earth_rate_W = earth.earth_rate_W();
  point.gravity_gradient_W = earth.gravity_gradient_W();
  UpdateTally zupt_tally, zaru_tally, aid_tally;
  std::size_t aid_cursor = 0;
  // Zero angular rate over a whole rest: sums of the raw gyro increments, time and attitude.
  Eigen::Vector3d rest_raw_dtheta = Eigen::Vector3d::Zero();
  Eigen::Matrix3d rest_sum_R = Eigen::Matrix3d::Zero();
  double rest_time = 0.0;
  // The nominal velocity carries the quantisation residual of the summed increments.
  const double velocity_quantisation_variance =
      options.acc_quantization_lsb_m_s * options.acc_quantization_lsb_m_s / 12.0;
  const double zero_velocity_variance =
      options.zero_velocity_sigma_m_s * options.zero_velocity_sigma_m_s +
      velocity_quantisation_variance;

  for (std::size_t k = 1; k <= epoch_count; ++k) {
    const std::size_t begin = (k - 1) * samples_per_epoch;
    const std::size_t end = std::min(n, begin + samples_per_epoch);
    Eigen::Matrix3d sum_R = Eigen::Matrix3d::Zero();
    Eigen::Vector3d sum_dv_W = Eigen::Vector3d::Zero();
    Eigen::Vector3d sum_raw_dtheta = Eigen::Vector3d::Zero();
    const double t_begin = strapdown.state().t_s;
    for (std::size_t i = begin; i < end; ++i) {
      const ImuSample& raw = imu.samples[i];
      const double dt = imu.interval_s(i);
      const ImuSample corrected = bias_corrected(imu, i, previous);
      const Eigen::Matrix3d R_before = strapdown.state().q_W_S.toRotationMatrix();
      strapdown.step(corrected);
      const Eigen::Matrix3d R_mid = 0.5 * (R_before + strapdown.state().q_W_S.toRotationMatrix());
      sum_R += R_mid * dt;
      sum_dv_W += R_mid * corrected.acc;
      sum_raw_dtheta += raw.gyro;
    }
    const double interval = strapdown.state().t_s - t_begin;
    point.mean_R_W_S = sum_R / interval;
    point.mean_specific_force_W = sum_dv_W / interval;
    const DiscreteErrorModel model = discretize_error_model(
        continuous_error_dynamics(point, noise), continuous_error_noise(point, noise), interval);

    Epoch epoch;
    epoch.last_sample = end - 1;
    epoch.t_s = strapdown.state().t_s;
    EpochCovariances cov;
    cov.transition = model.transition;
    cov.predicted_cov = model.transition * previous_filtered_cov * model.transition.transpose() +
                        model.noise_covariance;
    cov.predicted_cov = 0.5 * (cov.predicted_cov + cov.predicted_cov.transpose());
    epoch.gyro_bias = previous.gyro_bias;
    epoch.acc_bias = previous.acc_bias;
    ErrorMatrix P = cov.predicted_cov;
    ErrorVector x = ErrorVector::Zero();
    if (epoch_zero_velocity[k]) {
      const NavState& state = strapdown.state();
      // Zero velocity: z = -v_estimate = dv + noise.
      Matrix3x15 H = Matrix3x15::Zero();
      H.block<3, 3>(0, kVelocity).setIdentity();
      const double gate = state.v_W.norm() > options.gate_min_speed_m_s
                              ? options.innovation_gate_chi2
                              : std::numeric_limits<double>::infinity();
      update(x, P, -state.v_W, H, zero_velocity_variance * Eigen::Matrix3d::Identity(), gate,
             zupt_tally);
    }
    Eigen::Vector3d aid_v;
    double aid_sigma = 0.0;
    if (!epoch_zero_velocity[k] &&
        aid_velocity_at(aids, strapdown.state().t_s, aid_cursor, aid_v, aid_sigma)) {
      // An outside velocity: z = v_aid - v_estimate = dv + noise.
      Matrix3x15 H = Matrix3x15::Zero();
      H.block<3, 3>(0, kVelocity).setIdentity();
      update(x, P, aid_v - strapdown.state().v_W, H,
             (aid_sigma * aid_sigma + velocity_quantisation_variance) * Eigen::Matrix3d::Identity(),
             options.innovation_gate_chi2, aid_tally);
    }
    if (epoch_in_rest_interior[k]) {
      rest_raw_dtheta += sum_raw_dtheta;
      rest_sum_R += sum_R;
      rest_time += interval;
      if (!epoch_in_rest_interior[k + 1]) {
        // Zero angular rate, once per rest over its whole length (the quantisation residuals
        // of the summed gyro increments then enter only once):
        //   z = mean gyro - b_g - R_S_W omega_ie = dbg + R_S_W [omega_ie]x phi + noise.
        const Eigen::Matrix3d R_S_W = (rest_sum_R / rest_time).transpose();
        const Eigen::Vector3d z =
            rest_raw_dtheta / rest_time - epoch.gyro_bias - R_S_W * point.earth_rate_W;
        Matrix3x15 H = Matrix3x15::Zero();
        H.block<3, 3>(0, kAttitude) = R_S_W * skew(point.earth_rate_W);
        H.block<3, 3>(0, kGyroBias).setIdentity();
        const double lsb = options.gyro_quantization_lsb_rad;
        const double rate_variance =
            options.gyro_noise_density_rad_per_sqrt_s * options.gyro_noise_density_rad_per_sqrt_s /
                rest_time +
            lsb * lsb / (6.0 * rest_time * rest_time) +
            options.zero_angular_rate_sigma_rad_s * options.zero_angular_rate_sigma_rad_s;
        update(x, P, z, H, rate_variance * Eigen::Matrix3d::Identity(),
               options.innovation_gate_chi2, zaru_tally);
      }
    }
    if (!x.isZero(0.0)) {
      feed_back(strapdown, x);
      epoch.gyro_bias += x.segment<3>(kGyroBias);
      epoch.acc_bias += x.segment<3>(kAccBias);
    }
    if (!epoch_in_rest_interior[k] || !epoch_in_rest_interior[k + 1]) {
      rest_raw_dtheta.setZero();
      rest_sum_R.setZero();
      rest_time = 0.0;
    }
    cov.filtered_cov = P;
    previous_filtered_cov = P;
    epoch.correction = x;
    epochs.append(epoch);
    covariances.append(cov);
    previous = epoch;
  }
  result.summary.zero_velocity = zupt_tally.statistics();
  result.summary.zero_angular_rate = zaru_tally.statistics();
  result.summary.velocity_aid = aid_tally.statistics();
  result.summary.propagation_steps = epoch_count;

  SmoothedErrorFile smoothed;
  rts_backward_pass(epochs, covariances, smoothed);
  result.states =
      SmoothedStateStream(std::make_unique<SmoothedStateStream::Record>(SmoothedStateStream::Record{
                              initial_strapdown, std::move(epochs), std::move(smoothed)}),
                          imu);
  return result;
}

}  // namespace imscal::ims
