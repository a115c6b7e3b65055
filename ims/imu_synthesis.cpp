#include "ims/imu_synthesis.hpp"

#include <array>
#include <cmath>
#include <stdexcept>

namespace imscal::ims {

InertialSignals ideal_signals(const KinematicState& state, const EarthModel& earth) {
  const Eigen::Matrix3d R_S_W = state.q_W_S.conjugate().toRotationMatrix();
  const Eigen::Vector3d& omega_ie_W = earth.earth_rate_W();
  InertialSignals out;
  out.omega_is_S = state.omega_WS_S + R_S_W * omega_ie_W;
  out.f_S = R_S_W * (state.a_W + 2.0 * omega_ie_W.cross(state.v_W) - earth.gravity_W(state.p_W));
  return out;
}

namespace {
// 8-point Gauss-Legendre rule on [-1, 1] (Abramowitz & Stegun, table 25.4): nodes +-x_i, weights
// w_i.
constexpr std::array<double, 4> kNodes = {0.1834346424956498049, 0.5255324099163289858,
                                          0.7966664774136267396, 0.9602898564975362317};
constexpr std::array<double, 4> kWeights = {0.3626837833783619830, 0.3137066458778872873,
                                            0.2223810344533744706, 0.1012285362903762592};
static_assert(2 * kNodes.size() == kGaussLegendrePoints);

std::size_t interval_count(const Trajectory& trajectory, double rate_hz) {
  if (!(rate_hz > 0.0) || !std::isfinite(rate_hz)) {
    throw std::invalid_argument("IMS synthesis: rate_hz must be positive and finite");
  }
  // The 1e-9 guards against a duration that is a whole number of intervals up to rounding.
  const double intervals = (trajectory.end_s() - trajectory.begin_s()) * rate_hz;
  if (!(intervals >= 1.0 - 1e-9)) {
    throw std::invalid_argument("IMS synthesis: trajectory shorter than one sample interval");
  }
  return static_cast<std::size_t>(std::floor(intervals + 1e-9));
}

// Adds the integrals of the ideal signals over [a, b] to sample.gyro and sample.acc.
void integrate_piece(const Trajectory& trajectory, const EarthModel& earth, double a, double b,
                     ImuSample& sample) {
  const double half = 0.5 * (b - a);
  const double mid = 0.5 * (a + b);
  for (std::size_t i = 0; i < kNodes.size(); ++i) {
    for (double sign : {-1.0, 1.0}) {
      const InertialSignals s = ideal_signals(trajectory.at(mid + sign * half * kNodes[i]), earth);
      sample.gyro += (kWeights[i] * half) * s.omega_is_S;
      sample.acc += (kWeights[i] * half) * s.f_S;
    }
  }
}

ImuSeries empty_series(ImuQuantity quantity, const EarthModel& earth, double rate_hz) {
  ImuSeries series;
  series.quantity = quantity;
  series.nominal_dt_s = 1.0 / rate_hz;
  series.site = earth.site();
  return series;
}
}  // namespace

ImuSeries synthesize_ideal_increments(const Trajectory& trajectory, const EarthModel& earth,
                                      double rate_hz) {
  const std::size_t n = interval_count(trajectory, rate_hz);
  ImuSeries series = empty_series(ImuQuantity::kIncrements, earth, rate_hz);
  series.samples.reserve(n);
  static const std::vector<double> kNoJoints;
  const auto* pieces = dynamic_cast<const PiecewiseSmooth*>(&trajectory);
  const std::vector<double>& joints = pieces ? pieces->joints_s() : kNoJoints;
  auto next_joint = joints.begin();
  const double t0 = trajectory.begin_s();
  double t_prev = t0;
  for (std::size_t k = 1; k <= n; ++k) {
    // t_k from k (not by accumulation), so the grid has no drift; the last one is clamped
    // against rounding past end_s.
    const double t = std::min(t0 + static_cast<double>(k) / rate_hz, trajectory.end_s());
    ImuSample sample;
    sample.t_s = t;
    // Joints closer than 1e-9 of the interval to its ends coincide with them (spline knots on
    // the sample grid up to rounding): no split there.
    const double margin = 1e-9 * (t - t_prev);
    while (next_joint != joints.end() && *next_joint <= t_prev + margin) ++next_joint;
    double piece_begin = t_prev;
    while (true) {
      const bool split = next_joint != joints.end() && *next_joint < t - margin;
      const double piece_end = split ? *next_joint : t;
      integrate_piece(trajectory, earth, piece_begin, piece_end, sample);
      if (!split) break;
      piece_begin = piece_end;
      ++next_joint;
    }
    series.samples.push_back(sample);
    t_prev = t;
  }
  return series;
}

ImuSeries synthesize_ideal_rates(const Trajectory& trajectory, const EarthModel& earth,
                                 double rate_hz) {
  const std::size_t n = interval_count(trajectory, rate_hz);
  ImuSeries series = empty_series(ImuQuantity::kRates, earth, rate_hz);
  series.samples.reserve(n + 1);
  for (std::size_t k = 0; k <= n; ++k) {
    const double t =
        std::min(trajectory.begin_s() + static_cast<double>(k) / rate_hz, trajectory.end_s());
    const InertialSignals s = ideal_signals(trajectory.at(t), earth);
    series.samples.push_back({t, s.omega_is_S, s.f_S});
  }
  return series;
}

}  // namespace imscal::ims
