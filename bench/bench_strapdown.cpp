// Throughput of the strapdown mechanization: one hour of 2 kHz increments (7.2 million samples),
// single-threaded. Goal: >= 20 million samples/s (50 ns per sample).
//   build-*/bench/bench_strapdown
//     BM_StrapdownHourAt2kHz<ims::Strapdown>  -> counters "samples_per_s", "ns_per_sample" (the
//        goal); the same for <reference::ReferenceStrapdown>, the previous implementation
//     BM_StrapdownAgainstReference   -> the same hour through ims::Strapdown and through the
//        previous implementation (ReferenceStrapdown below, kept verbatim), alternately in each
//        iteration, so that both see the same machine load: "new_ns_per_sample",
//        "reference_ns_per_sample", "speedup" (reference time / new time), and
//        "position_difference_m" between the two after the hour with "position_m", the distance
//        reached. Only a coarse sanity check: the synthetic data are not a consistent motion,
//        the position runs off to ~1e9 m, and there the vertical instability of the linear
//        gravity model (time constant ~10 min) amplifies rounding-level differences of the
//        reordered arithmetic by orders of magnitude (~1e-8 relative after the hour). The
//        accuracy is checked by tests/ims/test_strapdown*.cpp.
// Timings use the thread's CPU time, not wall time, as the machine may be shared.
// The data are robot-like increments (rates up to ~3 rad/s about a wandering axis, gravity and
// an oscillating acceleration in the specific force), made by a cheap closed form: only their
// magnitudes matter here, not their consistency.
#include <benchmark/benchmark.h>

#include <time.h>

#include <cmath>
#include <stdexcept>
#include <string>

#include "ims/earth_model.hpp"
#include "ims/imu_data.hpp"
#include "ims/nav_state.hpp"
#include "ims/strapdown.hpp"

namespace ims = imscal::ims;

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && \
    !defined(__SANITIZE_ADDRESS__)
#define IMSCAL_REFERENCE_CLONES __attribute__((target_clones("arch=x86-64-v3", "default")))
#else
#define IMSCAL_REFERENCE_CLONES
#endif

namespace reference {

using imscal::ims::EarthModel;
using imscal::ims::ImuSample;
using imscal::ims::NavState;
using imscal::ims::StrapdownOptions;

// The mechanization as it was before the scalar rewrite of ims/strapdown.cpp (Eigen vectors
// in the per-sample code), kept verbatim as the baseline that each run measures against.
class ReferenceStrapdown {
 public:
  ReferenceStrapdown(const EarthModel& earth, const NavState& initial,
                     StrapdownOptions options = {});
  void step(const ImuSample& increment);
  const NavState& state() const { return state_; }
  void reset(const NavState& state);

 private:
  static constexpr int kEarthRateSyncSteps = 1024;
  void sync_earth_rate();

  Eigen::Vector3d earth_rate_W_;
  Eigen::Vector3d earth_rate_S_;
  int steps_since_sync_ = 0;
  Eigen::Vector3d coriolis_rate_W_;
  Eigen::Vector3d gravity_origin_W_;
  Eigen::Matrix3d gravity_gradient_W_;
  StrapdownOptions options_;
  NavState state_;
  Eigen::Vector3d gyro_history_[2];
  Eigen::Vector3d acc_history_[2];
  int history_count_ = 0;
  Eigen::Vector3d previous_dv_0_W_ = Eigen::Vector3d::Zero();
  double previous_dt_s_ = 0.0;
};

namespace {

using Eigen::Quaterniond;
using Eigen::Vector3d;

// Below this squared angle [rad^2] (0.01 rad) rotations use Taylor series; their first
// neglected terms are x^8/8! ~ 2.5e-21 (Rodrigues) and x^8/(2^8 8!) ~ 1e-23 (quaternion).
constexpr double kSeriesAngleSq = 1e-4;

// Exact quaternion of the rotation vector phi.
inline Quaterniond rotation_quaternion(const Vector3d& phi) {
  const double x2 = phi.squaredNorm();
  double real_part, imag_scale;  // cos(x/2), sin(x/2)/x
  if (x2 < kSeriesAngleSq) {
    real_part = 1.0 + x2 * (-1.0 / 8 + x2 * (1.0 / 384 - x2 * (1.0 / 46080)));
    imag_scale = 0.5 + x2 * (-1.0 / 48 + x2 * (1.0 / 3840 - x2 * (1.0 / 645120)));
  } else {
    const double x = std::sqrt(x2);
    real_part = std::cos(0.5 * x);
    imag_scale = std::sin(0.5 * x) / x;
  }
  return Quaterniond(real_part, imag_scale * phi.x(), imag_scale * phi.y(), imag_scale * phi.z());
}

// sin(x)/x and (1 - cos x)/x^2 of x = sqrt(x2), for x2 >= kSeriesAngleSq (no cancellation).
void rodrigues_terms(double x2, double& sin_term, double& cos_term) {
  const double x = std::sqrt(x2);
  const double half_sin = std::sin(0.5 * x);
  sin_term = std::sin(x) / x;
  cos_term = 2.0 * half_sin * half_sin / x2;
}

// exp(phi x) v by Rodrigues' formula: v + sin(x)/x phi x v + (1 - cos x)/x^2 phi x (phi x v).
inline Vector3d rotate_by_vector(const Vector3d& phi, const Vector3d& v) {
  const double x2 = phi.squaredNorm();
  double sin_term, cos_term;
  if (x2 < kSeriesAngleSq) {
    sin_term = 1.0 + x2 * (-1.0 / 6 + x2 * (1.0 / 120 - x2 * (1.0 / 5040)));
    cos_term = 0.5 + x2 * (-1.0 / 24 + x2 * (1.0 / 720 - x2 * (1.0 / 40320)));
  } else {
    rodrigues_terms(x2, sin_term, cos_term);
  }
  const Vector3d cross1 = phi.cross(v);
  return v + sin_term * cross1 + cos_term * phi.cross(cross1);
}

// Two-point Gauss-Legendre nodes on [0, 1] (weights 1/2 each) and the powers used below.
struct GaussNode {
  double u;
  double alpha1, alpha2, alpha3;  // u, u^2/2, u^3/3: integral of 1, u, u^2 from 0 to u
  double beta1, beta2;            // u^3/12, u^4/12: second-order rotation vector
};

constexpr GaussNode make_node(double u) {
  return GaussNode{u, u, u * u / 2, u * u * u / 3, u * u * u / 12, u * u * u * u / 12};
}

constexpr double kSqrt3Over6 = 0.28867513459481288225;  // sqrt(3)/6
constexpr GaussNode kNodes[2] = {make_node(0.5 - kSqrt3Over6), make_node(0.5 + kSqrt3Over6)};
const Eigen::Array2d kU(kNodes[0].u, kNodes[1].u);
const Eigen::Array2d kAlpha1(kNodes[0].alpha1, kNodes[1].alpha1);
const Eigen::Array2d kAlpha2(kNodes[0].alpha2, kNodes[1].alpha2);
const Eigen::Array2d kAlpha3(kNodes[0].alpha3, kNodes[1].alpha3);
const Eigen::Array2d kBeta1(kNodes[0].beta1, kNodes[1].beta1);
const Eigen::Array2d kBeta2(kNodes[0].beta2, kNodes[1].beta2);

// Coefficients of a quadratic q(u) = a + b u + c u^2 on the current interval u in [0, 1]
// (time normalised by h, values multiplied by h) whose integrals over the intervals
// [-2,-1], [-1,0], [0,1] are the increments oldest, previous, current.
struct Quadratic {
  Vector3d a, b, c;
};

inline Quadratic fit_quadratic(const Vector3d& oldest, const Vector3d& previous,
                               const Vector3d& current) {
  return Quadratic{(2.0 * current + 5.0 * previous - oldest) * (1.0 / 6), current - previous,
                   0.5 * (current - 2.0 * previous + oldest)};
}

[[noreturn]] void throw_non_finite(const ImuSample& s) {
  throw std::invalid_argument("ReferenceStrapdown::step: sample at t = " + std::to_string(s.t_s) +
                              " s holds a non-finite value");
}

[[noreturn]] void throw_time_not_advancing(const ImuSample& s, const NavState& state) {
  throw std::invalid_argument("ReferenceStrapdown::step: sample time " + std::to_string(s.t_s) +
                              " s does not follow the state time " + std::to_string(state.t_s) +
                              " s");
}

}  // namespace

ReferenceStrapdown::ReferenceStrapdown(const EarthModel& earth, const NavState& initial,
                                       StrapdownOptions options)
    : earth_rate_W_(options.earth_rate ? earth.earth_rate_W() : Vector3d::Zero()),
      coriolis_rate_W_(options.coriolis ? earth.earth_rate_W() : Vector3d::Zero()),
      gravity_origin_W_(options.gravity ? earth.gravity_origin_W() : Vector3d::Zero()),
      gravity_gradient_W_(options.gravity ? earth.gravity_gradient_W() : Eigen::Matrix3d::Zero()),
      options_(options) {
  reset(initial);
}

void ReferenceStrapdown::sync_earth_rate() {
  earth_rate_S_ = state_.q_W_S.conjugate() * earth_rate_W_;
  steps_since_sync_ = 0;
}

void ReferenceStrapdown::reset(const NavState& state) {
  state_ = state;
  state_.q_W_S.normalize();
  sync_earth_rate();
  history_count_ = 0;
  previous_dt_s_ = 0.0;
  for (int i = 0; i < 2; ++i) {
    gyro_history_[i].setZero();
    acc_history_[i].setZero();
  }
}

IMSCAL_REFERENCE_CLONES void ReferenceStrapdown::step(const ImuSample& increment) {
  const Vector3d& gyro = increment.gyro;
  const Vector3d& acc = increment.acc;
  // Any inf or nan among the inputs makes the sum non-finite (physical values cannot overflow).
  if (!std::isfinite(increment.t_s + gyro.sum() + acc.sum())) throw_non_finite(increment);
  const double h = increment.t_s - state_.t_s;
  if (!(h > 0.0)) throw_time_not_advancing(increment, state_);
  // The interval fit assumes equal intervals: a change of more than 1 % (a gap, a new rate)
  // restarts it at low order.
  if (history_count_ > 0 && std::abs(h - previous_dt_s_) > 0.01 * previous_dt_s_) {
    history_count_ = 0;
  }

  // Increments of the two previous intervals; missing ones extrapolated so that the fit
  // degrades to a constant (no history) or a line (one previous interval).
  Vector3d gyro_prev = gyro, gyro_old = gyro, acc_prev = acc, acc_old = acc;
  if (options_.coning_sculling && history_count_ > 0) {
    gyro_prev = gyro_history_[1];
    acc_prev = acc_history_[1];
    if (history_count_ == 2) {
      gyro_old = gyro_history_[0];
      acc_old = acc_history_[0];
    } else {
      gyro_old = 2.0 * gyro_prev - gyro;
      acc_old = 2.0 * acc_prev - acc;
    }
  }
  const Quadratic rate = fit_quadratic(gyro_old, gyro_prev, gyro);  // omega_is^S * h [rad]
  const Quadratic force = fit_quadratic(acc_old, acc_prev, acc);    // f^S * h [m/s]

  // Second-order rotation vector beta(u) = 1/2 int_0^u alpha x omega du (alpha: integral of the
  // rate) = ab u^3/12 + ac u^4/12 + bc u^5/60.
  const Vector3d ab = rate.a.cross(rate.b);
  const Vector3d ac = rate.a.cross(rate.c);
  const Vector3d bc = rate.b.cross(rate.c);
  const Vector3d body_rotation = gyro + (ab + ac) * (1.0 / 12) + bc * (1.0 / 60);

  // Specific force rotated into the body frame at t_{k-1}, at the Gauss nodes. The bc term of
  // beta is left out here: |b x c| u^5/60 * |f h| < 1e-15 m/s at 3 rad/s and 1 kHz.
  // Both nodes at once, one per SIMD lane.
  using Lanes = Eigen::Array2d;
  const Lanes px = kAlpha1 * rate.a.x() + kAlpha2 * rate.b.x() + kAlpha3 * rate.c.x() +
                   kBeta1 * ab.x() + kBeta2 * ac.x();
  const Lanes py = kAlpha1 * rate.a.y() + kAlpha2 * rate.b.y() + kAlpha3 * rate.c.y() +
                   kBeta1 * ab.y() + kBeta2 * ac.y();
  const Lanes pz = kAlpha1 * rate.a.z() + kAlpha2 * rate.b.z() + kAlpha3 * rate.c.z() +
                   kBeta1 * ab.z() + kBeta2 * ac.z();
  const Lanes fx = force.a.x() + kU * (force.b.x() + kU * force.c.x());
  const Lanes fy = force.a.y() + kU * (force.b.y() + kU * force.c.y());
  const Lanes fz = force.a.z() + kU * (force.b.z() + kU * force.c.z());
  const Lanes x2 = px * px + py * py + pz * pz;
  Lanes sin_term, cos_term;
  if ((x2 < kSeriesAngleSq).all()) {
    sin_term = 1.0 + x2 * (-1.0 / 6 + x2 * (1.0 / 120 - x2 * (1.0 / 5040)));
    cos_term = 0.5 + x2 * (-1.0 / 24 + x2 * (1.0 / 720 - x2 * (1.0 / 40320)));
  } else {
    for (int i = 0; i < 2; ++i) rodrigues_terms(x2[i], sin_term[i], cos_term[i]);
  }
  const Lanes c1x = py * fz - pz * fy, c1y = pz * fx - px * fz, c1z = px * fy - py * fx;
  const Lanes c2x = py * c1z - pz * c1y, c2y = pz * c1x - px * c1z, c2z = px * c1y - py * c1x;
  const Lanes rx = fx + sin_term * c1x + cos_term * c2x;
  const Lanes ry = fy + sin_term * c1y + cos_term * c2y;
  const Lanes rz = fz + sin_term * c1z + cos_term * c2z;
  const Vector3d dv_body(0.5 * rx.sum(), 0.5 * ry.sum(), 0.5 * rz.sum());

  // W turns by -omega_ie h relative to inertial space during the interval; in S_{k-1} that is
  // the rotation vector earth_turn. It enters the velocity at first order (mid-interval) and
  // the attitude exactly (below).
  const Eigen::Matrix3d R_W_S = state_.q_W_S.toRotationMatrix();
  const Vector3d earth_turn = -h * earth_rate_S_;
  // Velocity increment without Coriolis: specific force and gravity at the mid-interval
  // position. Parts that do not depend on the previous p and v come first, so that the
  // step-to-step dependency chain through them stays short.
  const Vector3d dv_f_W =
      R_W_S * (dv_body + 0.5 * earth_turn.cross(dv_body)) + h * gravity_origin_W_;
  const Vector3d dv_0 = dv_f_W + h * (gravity_gradient_W_ * (state_.p_W + (0.5 * h) * state_.v_W));
  // Position: trapezoid of the velocity, whose error -h^3/12 dv/dt'' is removed with the
  // difference of consecutive mean accelerations (h/12)(dv_k - dv_{k-1}); what is left is
  // O(h^5) per step. Without history (first step) the correction is left out.
  const Vector3d trapezoid_correction =
      history_count_ > 0 ? Vector3d((1.0 / 12) * h * (dv_0 - previous_dv_0_W_)) : Vector3d::Zero();
  const Vector3d dp_0 = h * state_.v_W + (0.5 * h) * dv_0 - trapezoid_correction;
  // Coriolis: -2 omega x int v dt = -2 omega x dp; in position half of it, h times (the
  // trapezoid of a velocity change growing linearly over the interval).
  const Vector3d coriolis = coriolis_rate_W_.cross(dp_0);
  const Vector3d dv_W = dv_0 - 2.0 * coriolis;
  const Vector3d dp_W = dp_0 - h * coriolis;
  previous_dv_0_W_ = dv_0;

  // Attitude: q_W_S <- exp(-omega_ie h) q_W_S exp(body) = q_W_S exp(earth_turn) exp(body),
  // the two rotations joined by Baker-Campbell-Hausdorff to third order (the next terms are
  // below 1e-18 rad). Joining them first keeps a sensor at rest exactly at rest: the two
  // nearly cancel before the one quaternion product, so no rounding repeats every step.
  const Vector3d earth_body = earth_turn.cross(body_rotation);
  const Vector3d joined =
      body_rotation + earth_turn + 0.5 * earth_body - (1.0 / 12) * body_rotation.cross(earth_body);
  // One Newton step towards unit norm (no square root), from the norm before the product
  // (the product with a unit quaternion keeps it): off the step-to-step dependency chain.
  const double norm_correction = 0.5 * (3.0 - state_.q_W_S.squaredNorm());
  Quaterniond q = state_.q_W_S * rotation_quaternion(joined);
  q.coeffs() *= norm_correction;

  state_.q_W_S = q;
  // omega_ie in S follows the body rotation (the Earth turn leaves it unchanged). Carried
  // along rather than computed from q so that the attitude update does not wait for it;
  // recomputed from q now and then so that rounding cannot accumulate.
  if (++steps_since_sync_ < kEarthRateSyncSteps) {
    earth_rate_S_ = rotate_by_vector(-body_rotation, earth_rate_S_);
  } else {
    sync_earth_rate();
  }
  state_.p_W += dp_W;
  state_.v_W += dv_W;
  state_.t_s = increment.t_s;

  // Keep the two latest increments, oldest first.
  gyro_history_[0] = gyro_history_[1];
  acc_history_[0] = acc_history_[1];
  if (history_count_ < 2) ++history_count_;
  gyro_history_[1] = gyro;
  acc_history_[1] = acc;
  previous_dt_s_ = h;
}

}  // namespace reference

namespace {

constexpr double kRateHz = 2000.0;
constexpr std::size_t kSampleCount = 7'200'000;  // 1 h at 2 kHz

const ims::ImuSeries& hour_of_increments() {
  static const ims::ImuSeries series = [] {
    ims::ImuSeries s;
    s.quantity = ims::ImuQuantity::kIncrements;
    s.nominal_dt_s = 1.0 / kRateHz;
    s.samples.resize(kSampleCount);
    const double h = s.nominal_dt_s;
    for (std::size_t k = 0; k < kSampleCount; ++k) {
      const double t = static_cast<double>(k + 1) * h;
      ims::ImuSample& sample = s.samples[k];
      sample.t_s = t;
      sample.gyro = h * Eigen::Vector3d(2.0 * std::sin(0.7 * t), 1.5 * std::cos(0.3 * t),
                                        3.0 * std::sin(0.11 * t) * std::cos(1.3 * t));
      sample.acc = h * Eigen::Vector3d(9.81 * std::sin(0.05 * t) + 1.5 * std::sin(2.0 * t),
                                       0.8 * std::cos(1.7 * t), 9.81 * std::cos(0.05 * t));
    }
    return s;
  }();
  return series;
}

const ims::EarthModel& site() {
  static const ims::EarthModel earth(ims::Site{48.7, 9.1, 380.0});
  return earth;
}

void set_rate_counters(benchmark::State& state, double samples) {
  state.counters["samples_per_s"] = benchmark::Counter(samples, benchmark::Counter::kIsRate);
  state.counters["ns_per_sample"] =
      benchmark::Counter(samples, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

// The hour through the mechanization M: ims::Strapdown (the goal) or the reference.
template <class M>
void BM_StrapdownHourAt2kHz(benchmark::State& state) {
  const ims::ImuSeries& series = hour_of_increments();
  for (auto _ : state) {
    M strapdown(site(), ims::NavState{0.0});
    for (const ims::ImuSample& sample : series.samples) strapdown.step(sample);
    benchmark::DoNotOptimize(strapdown.state());
  }
  set_rate_counters(
      state, static_cast<double>(series.samples.size()) * static_cast<double>(state.iterations()));
}

// CPU time of this thread [s] (wall time would count the other processes of a shared machine).
double thread_cpu_time_s() {
  timespec now{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &now);
  return static_cast<double>(now.tv_sec) + 1e-9 * static_cast<double>(now.tv_nsec);
}

// Runs the hour through a mechanization of type M; returns the thread CPU time [s] and the end
// state.
template <class M>
double time_hour(const ims::ImuSeries& series, ims::NavState& end) {
  const double start_s = thread_cpu_time_s();
  M strapdown(site(), ims::NavState{0.0});
  for (const ims::ImuSample& sample : series.samples) strapdown.step(sample);
  benchmark::DoNotOptimize(strapdown.state());
  const double elapsed_s = thread_cpu_time_s() - start_s;
  end = strapdown.state();
  return elapsed_s;
}

void BM_StrapdownAgainstReference(benchmark::State& state) {
  const ims::ImuSeries& series = hour_of_increments();
  double new_s = 0.0, reference_s = 0.0, position_difference_m = 0.0, position_m = 0.0;
  for (auto _ : state) {
    ims::NavState end_new, end_reference;
    reference_s += time_hour<reference::ReferenceStrapdown>(series, end_reference);
    new_s += time_hour<ims::Strapdown>(series, end_new);
    position_difference_m = (end_new.p_W - end_reference.p_W).norm();
    position_m = end_reference.p_W.norm();
  }
  const double samples =
      static_cast<double>(series.samples.size()) * static_cast<double>(state.iterations());
  state.counters["new_ns_per_sample"] = 1e9 * new_s / samples;
  state.counters["reference_ns_per_sample"] = 1e9 * reference_s / samples;
  state.counters["speedup"] = reference_s / new_s;
  state.counters["position_difference_m"] = position_difference_m;
  state.counters["position_m"] = position_m;
}

}  // namespace

BENCHMARK(BM_StrapdownHourAt2kHz<ims::Strapdown>)->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK(BM_StrapdownHourAt2kHz<reference::ReferenceStrapdown>)
    ->Unit(benchmark::kMillisecond)
    ->MinTime(2.0);
BENCHMARK(BM_StrapdownAgainstReference)->Unit(benchmark::kMillisecond)->MinTime(4.0);

BENCHMARK_MAIN();
