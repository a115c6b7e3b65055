#include "ims/strapdown.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

// On x86-64 with GCC, step() is also compiled for AVX2 (x86-64-v3) and the better version is
// chosen at load time: fused multiply-adds and three-operand instructions save time per sample.
// The two versions may differ in the last bit of a result (GCC contracts a * b + c into an FMA
// where the target has it). Left out under AddressSanitizer. Deliberately no AVX-512 version
// (x86-64-v4): GCC then merges the state stores into 512-bit ones, and that version measured
// ~25 % slower per sample than the AVX2 one.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && \
    !defined(__SANITIZE_ADDRESS__)
#define IMSCAL_STRAPDOWN_CLONES __attribute__((target_clones("arch=x86-64-v3", "default")))
#else
#define IMSCAL_STRAPDOWN_CLONES
#endif

namespace imscal::ims {
namespace {

// Three-vectors are held as (x, y, z, 0) in a GCC/Clang vector of four doubles: one AVX register
// and one instruction per vector operation in the AVX2 build (two SSE2 halves otherwise). The
// per-sample code is about a dozen cross products and 50 vector multiply-adds. The state the
// next sample needs is kept in such padded vectors (Strapdown::Vec3) and read back whole: a
// load of one double out of a wider store of the previous sample stalls store forwarding.
typedef double Lanes __attribute__((vector_size(32)));

#if defined(__GNUC__)
// Helpers taking and returning Lanes are always inlined, so no function boundary exists whose
// ABI would depend on AVX; GCC and clang warn about it regardless.
#pragma GCC diagnostic ignored "-Wpsabi"
#endif
#define IMSCAL_INLINE inline __attribute__((always_inline))

IMSCAL_INLINE Lanes yzx(const Lanes& a) {
  return __builtin_shufflevector(a, a, 1, 2, 0, 3);
}
// a x b = yzx(a * yzx(b) - yzx(a) * b): three lane permutations; the zero lane stays zero.
IMSCAL_INLINE Lanes cross(const Lanes& a, const Lanes& b) {
  return yzx(a * yzx(b) - yzx(a) * b);
}
IMSCAL_INLINE double dot(const Lanes& a, const Lanes& b) {
  const Lanes m = a * b;
  return m[0] + m[1] + m[2];
}
IMSCAL_INLINE Lanes load(const double* xyz) {
  return Lanes{xyz[0], xyz[1], xyz[2], 0.0};
}
// The padded, aligned vectors of the class (Strapdown::Vec3) are read and written whole.
template <class Vec3>
IMSCAL_INLINE Lanes get(const Vec3& vec3) {
  static_assert(sizeof(Vec3) == sizeof(Lanes) && alignof(Vec3) == 32);
  Lanes lanes;
  __builtin_memcpy(&lanes, &vec3, sizeof(Lanes));
  return lanes;
}
template <class Vec3>
IMSCAL_INLINE void put(Vec3& vec3, const Lanes& lanes) {
  __builtin_memcpy(static_cast<void*>(&vec3), &lanes, sizeof(Lanes));
}

// Below this squared angle [rad^2] (0.01 rad) rotations use Taylor series; their first
// neglected terms are x^8/8! ~ 2.5e-21 (Rodrigues) and x^8/(2^8 8!) ~ 1e-23 (quaternion).
constexpr double kSeriesAngleSq = 1e-4;

// sin(x)/x and (1 - cos x)/x^2 of x = sqrt(x2): Taylor series below kSeriesAngleSq, else the
// functions themselves (no cancellation there).
IMSCAL_INLINE void rodrigues_terms(double x2, double& sin_term, double& cos_term) {
  if (x2 < kSeriesAngleSq) [[likely]] {
    // Estrin's scheme: two multiply-adds deep instead of three.
    const double x4 = x2 * x2;
    sin_term = (1.0 - x2 * (1.0 / 6)) + x4 * (1.0 / 120 - x2 * (1.0 / 5040));
    cos_term = (0.5 - x2 * (1.0 / 24)) + x4 * (1.0 / 720 - x2 * (1.0 / 40320));
  } else {
    const double x = std::sqrt(x2);
    const double half_sin = std::sin(0.5 * x);
    sin_term = std::sin(x) / x;
    cos_term = 2.0 * half_sin * half_sin / x2;
  }
}

// exp(phi x) v by Rodrigues' formula: v + sin(x)/x phi x v + (1 - cos x)/x^2 phi x (phi x v).
IMSCAL_INLINE Lanes rotate_by_vector(const Lanes& phi, const Lanes& v) {
  double sin_term, cos_term;
  rodrigues_terms(dot(phi, phi), sin_term, cos_term);
  const Lanes cross1 = cross(phi, v);
  return v + sin_term * cross1 + cos_term * cross(phi, cross1);
}

// Scalar part and vector scale of the exact quaternion of the rotation vector phi:
// q = (cos(x/2), sin(x/2)/x phi).
IMSCAL_INLINE void rotation_quaternion_terms(double x2, double& real_part, double& imag_scale) {
  if (x2 < kSeriesAngleSq) [[likely]] {
    const double x4 = x2 * x2;
    real_part = (1.0 - x2 * (1.0 / 8)) + x4 * (1.0 / 384 - x2 * (1.0 / 46080));
    imag_scale = (0.5 - x2 * (1.0 / 48)) + x4 * (1.0 / 3840 - x2 * (1.0 / 645120));
  } else {
    const double x = std::sqrt(x2);
    real_part = std::cos(0.5 * x);
    imag_scale = std::sin(0.5 * x) / x;
  }
}

// Interval model. With u = (t - t_{k-1}) / h in [0, 1], the rate and specific force (times h)
// are the quadratics q(u) = a + b u + c u^2 whose integrals over the intervals [-2,-1],
// [-1,0], [0,1] are the increments oldest (o), previous (p) and current (g):
//   a = (2g + 5p - o)/6,  b = g - p,  c = (g - 2p + o)/2.
// Everything below is written directly in o, p, g (weights computed here at compile time), so
// that nothing waits for the fit. For the rate:
//   alpha(u) = int_0^u q = u a + u^2/2 b + u^3/3 c                 first-order rotation vector
//   beta(u)  = 1/2 int_0^u alpha x q = ab u^3/12 + ac u^4/12 + bc u^5/60   second order
// with ab = a x b = (7 X1 - X2 + X3)/6, ac = (3 X1 - X2 - X3)/4, bc = (X1 - X2 + X3)/2 in the
// cross products X1 = p x g, X2 = o x g, X3 = o x p.
struct IncrementWeights {
  double current, previous, oldest;
};
struct CrossWeights {
  double pg, og, op;  // of X1, X2, X3
};
constexpr CrossWeights kAb{7.0 / 6, -1.0 / 6, 1.0 / 6};
constexpr CrossWeights kAc{3.0 / 4, -1.0 / 4, -1.0 / 4};
constexpr CrossWeights kBc{1.0 / 2, -1.0 / 2, 1.0 / 2};
constexpr CrossWeights combine(double ab, double ac, double bc) {
  return {ab * kAb.pg + ac * kAc.pg + bc * kBc.pg, ab * kAb.og + ac * kAc.og + bc * kBc.og,
          ab * kAb.op + ac * kAc.op + bc * kBc.op};
}
// beta(1): the second-order part of the rotation over the whole interval.
constexpr CrossWeights kBodyBeta = combine(1.0 / 12, 1.0 / 12, 1.0 / 60);

// One node of the two-point Gauss-Legendre rule on [0, 1] (weights 1/2 each).
struct GaussNode {
  double u;
  IncrementWeights alpha;  // alpha(u)
  CrossWeights beta;       // beta(u) without the bc term (see rotated_force_at)
  IncrementWeights force;  // q(u) of the specific force
};

constexpr GaussNode make_node(double u) {
  const double u2 = u * u, u3 = u2 * u, u4 = u3 * u;
  return GaussNode{u,
                   {u / 3 + u2 / 2 + u3 / 6, 5 * u / 6 - u2 / 2 - u3 / 3, -u / 6 + u3 / 6},
                   combine(u3 / 12, u4 / 12, 0.0),
                   {1.0 / 3 + u + u2 / 2, 5.0 / 6 - u - u2, -1.0 / 6 + u2 / 2}};
}

constexpr double kSqrt3Over6 = 0.28867513459481288225;  // sqrt(3)/6
constexpr GaussNode kNodes[2] = {make_node(0.5 - kSqrt3Over6), make_node(0.5 + kSqrt3Over6)};

IMSCAL_INLINE Lanes weighted(const IncrementWeights& w, const Lanes& g, const Lanes& p,
                             const Lanes& o) {
  return w.current * g + w.previous * p + w.oldest * o;
}
IMSCAL_INLINE Lanes weighted(const CrossWeights& w, const Lanes& pg, const Lanes& og,
                             const Lanes& op) {
  return w.pg * pg + w.og * og + w.op * op;
}

// The specific force f(u) rotated into the body frame at t_{k-1} at the Gauss node `node`:
// exp(phi(u) x) f(u) = f + sin(x)/x phi x f + (1 - cos x)/x^2 (phi (phi . f) - x^2 f),
// phi = alpha + beta, x = |phi|. Left out, and why it is allowed:
//  - the bc term of beta: |b x c| u^5/60 * |f h| < 1e-15 m/s at 3 rad/s and 1 kHz;
//  - in x^2, the part of beta: alpha . beta is a triple product of a, b, c (alpha . (a x b) =
//    alpha3 c . (a x b), ...), below 1e-15 rad^2 for robot motions, and |beta|^2 < 1e-17
//    rad^2, so the factors change by < 1e-16 relative and the result by < 1e-20 m/s; in
//    exchange x^2 is ready before beta.
IMSCAL_INLINE Lanes rotated_force_at(const GaussNode& node, const Lanes (&gyro)[3],
                                     const Lanes (&gyro_cross)[3], const Lanes (&acc)[3]) {
  const Lanes alpha = weighted(node.alpha, gyro[0], gyro[1], gyro[2]);
  const Lanes phi = alpha + weighted(node.beta, gyro_cross[0], gyro_cross[1], gyro_cross[2]);
  const Lanes f = weighted(node.force, acc[0], acc[1], acc[2]);
  const double x2 = dot(alpha, alpha);
  double sin_term, cos_term;
  rodrigues_terms(x2, sin_term, cos_term);
  return (1.0 - cos_term * x2) * f + sin_term * cross(phi, f) + (cos_term * dot(phi, f)) * phi;
}

// map x for a 3x3 map given by its columns.
template <class Vec3>
IMSCAL_INLINE Lanes apply_map(const Vec3 (&map)[3], const Lanes& x) {
  return x[0] * get(map[0]) + x[1] * get(map[1]) + x[2] * get(map[2]);
}

[[noreturn]] void throw_non_finite(const ImuSample& s) {
  throw std::invalid_argument("Strapdown::step: sample at t = " + std::to_string(s.t_s) +
                              " s holds a non-finite value");
}

[[noreturn]] void throw_time_not_advancing(const ImuSample& s, const NavState& state) {
  throw std::invalid_argument("Strapdown::step: sample time " + std::to_string(s.t_s) +
                              " s does not follow the state time " + std::to_string(state.t_s) +
                              " s");
}

}  // namespace

Strapdown::Strapdown(const EarthModel& earth, const NavState& initial, StrapdownOptions options)
    : options_(options) {
  const Eigen::Vector3d& w = earth.earth_rate_W();
  if (options.earth_rate) earth_rate_W_ = {w.x(), w.y(), w.z()};
  if (options.coriolis) coriolis_rate_W_ = {w.x(), w.y(), w.z()};
  if (options.gravity) {
    const Eigen::Vector3d& g0 = earth.gravity_origin_W();
    const Eigen::Matrix3d& G = earth.gravity_gradient_W();
    gravity_origin_W_ = {g0.x(), g0.y(), g0.z()};
    for (int j = 0; j < 3; ++j) gravity_gradient_W_[j] = {G(0, j), G(1, j), G(2, j)};
  }
  reset(initial);
}

void Strapdown::sync_earth_rate() {
  const Eigen::Vector3d w_S =
      state_.q_W_S.conjugate() * Eigen::Vector3d(earth_rate_W_.x, earth_rate_W_.y, earth_rate_W_.z);
  earth_rate_S_ = {w_S.x(), w_S.y(), w_S.z()};
  steps_since_sync_ = 0;
}

void Strapdown::reset(const NavState& state) {
  state_ = state;
  state_.q_W_S.normalize();
  q_vec_ = {state_.q_W_S.x(), state_.q_W_S.y(), state_.q_W_S.z()};
  q_w_ = state_.q_W_S.w();
  v_W_ = {state_.v_W.x(), state_.v_W.y(), state_.v_W.z()};
  p_W_ = {state_.p_W.x(), state_.p_W.y(), state_.p_W.z()};
  sync_earth_rate();
  history_count_ = 0;
  newest_ = 0;
  previous_dt_s_ = 0.0;
  previous_dv_0_W_ = {};
  for (int i = 0; i < 2; ++i) {
    gyro_history_[i] = {};
    acc_history_[i] = {};
  }
}

void Strapdown::update_increment_maps(double h, double trapezoid_fraction) {
  const double trapezoid_weight = trapezoid_fraction * h;  // c1
  // With w = R_W_S (r_0 + r_1) (sum of the rotated specific force at the two Gauss nodes,
  // twice the body-frame velocity increment, taken to W), c1 = trapezoid_weight, c2 = h/12
  // (or 0 without history):
  //   dv_0 = E w / 2 + h g(p_mid)       E = I - (h/2) [omega_ie]x: the Earth turn of W at
  //                                     mid-interval, first order
  //   dp_0 = h v + c1 dv_0 + c2 dv_0,prev                  (trapezoid with end correction)
  //   v'   = v + dv_0 - 2 [omega_c]x dp_0                  (Coriolis)
  //   p'   = p + dp_0 - h [omega_c]x dp_0
  // so the parts proportional to w are  dv_0: E/2,  v': (I - 2 c1 K) E/2,  p': c1 (I - h K) E/2
  // with K = [omega_c]x. Precomputing them keeps the chain from w to the new state at one
  // matrix-vector product. The factor c1 of the position map is applied per step (with the
  // step's own h); the rest depends on h only through (h/2) omega_ie, 2 c1 K and h K (< 1e-7),
  // so the maps are kept while h stays within a relative 1e-6 of the h they were made for:
  // their entries then differ from exact ones by < 1e-13 relative, i.e. < 1e-15 m/s per step.
  const auto skew = [](const Vec3& a) {
    Eigen::Matrix3d m;
    m << 0.0, -a.z, a.y, a.z, 0.0, -a.x, -a.y, a.x, 0.0;
    return m;
  };
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d half_E = 0.5 * (I - (0.5 * h) * skew(earth_rate_W_));
  const Eigen::Matrix3d K = skew(coriolis_rate_W_);
  const Eigen::Matrix3d velocity_map = (I - (2.0 * trapezoid_weight) * K) * half_E;
  const Eigen::Matrix3d position_map = (I - h * K) * half_E;  // times c1 in step()
  for (int j = 0; j < 3; ++j) {
    dv_0_map_[j] = {half_E(0, j), half_E(1, j), half_E(2, j)};
    velocity_map_[j] = {velocity_map(0, j), velocity_map(1, j), velocity_map(2, j)};
    position_map_[j] = {position_map(0, j), position_map(1, j), position_map(2, j)};
  }
  maps_h_s_ = h;
  maps_trapezoid_fraction_ = trapezoid_fraction;
}

IMSCAL_STRAPDOWN_CLONES void Strapdown::step(const ImuSample& increment) {
  const Lanes gyro = load(increment.gyro.data());
  const Lanes acc = load(increment.acc.data());
  // Any inf or nan among the inputs makes the sum non-finite (physical values cannot overflow).
  const Lanes sum = gyro + acc;
  if (!std::isfinite(increment.t_s + sum[0] + sum[1] + sum[2])) throw_non_finite(increment);
  const double h = increment.t_s - state_.t_s;
  if (!(h > 0.0)) throw_time_not_advancing(increment, state_);
  // The interval fit assumes equal intervals: a change of more than 1 % (a gap, a new rate)
  // restarts it at low order.
  if (history_count_ > 0 && std::abs(h - previous_dt_s_) > 0.01 * previous_dt_s_) {
    history_count_ = 0;
  }
  // Position: trapezoid of the velocity, whose error -h^3/12 dv/dt'' is removed with the
  // difference of consecutive mean accelerations (h/12)(dv_k - dv_{k-1}), i.e.
  // dp = h v + (5h/12) dv_k + (h/12) dv_{k-1}; what is left is O(h^5) per step. Without
  // history (first step) the correction is left out: dp = h v + (h/2) dv_k.
  const double trapezoid_fraction = history_count_ > 0 ? 5.0 / 12 : 0.5;
  const double trapezoid_weight = trapezoid_fraction * h;
  const double previous_weight = history_count_ > 0 ? (1.0 / 12) * h : 0.0;
  if (std::abs(h - maps_h_s_) > 1e-6 * h || trapezoid_fraction != maps_trapezoid_fraction_)
      [[unlikely]] {
    update_increment_maps(h, trapezoid_fraction);
  }

  // --- Body frame: depends on the increments only, not on the state. ---
  // Increments of the two previous intervals; missing ones extrapolated so that the fit
  // degrades to a constant (no history) or a line (one previous interval).
  Lanes gyro_prev = gyro, gyro_old = gyro, acc_prev = acc, acc_old = acc;
  if (options_.coning_sculling && history_count_ > 0) [[likely]] {
    gyro_prev = get(gyro_history_[newest_]);
    acc_prev = get(acc_history_[newest_]);
    if (history_count_ == 2) [[likely]] {
      gyro_old = get(gyro_history_[1 - newest_]);
      acc_old = get(acc_history_[1 - newest_]);
    } else {
      gyro_old = 2.0 * gyro_prev - gyro;
      acc_old = 2.0 * acc_prev - acc;
    }
  }
  const Lanes gyros[3] = {gyro, gyro_prev, gyro_old};  // [rad]
  const Lanes accs[3] = {acc, acc_prev, acc_old};      // [m/s]
  const Lanes gyro_cross[3] = {cross(gyro_prev, gyro), cross(gyro_old, gyro),
                               cross(gyro_old, gyro_prev)};  // X1, X2, X3
  const Lanes body_rotation =
      gyro + weighted(kBodyBeta, gyro_cross[0], gyro_cross[1], gyro_cross[2]);

  // Velocity increment in the body frame at t_{k-1}: int R_S_{k-1}_S(t) f^S(t) dt by two-point
  // Gauss-Legendre quadrature (weights 1/2, applied in the maps).
  const Lanes force_sum = rotated_force_at(kNodes[0], gyros, gyro_cross, accs) +
                          rotated_force_at(kNodes[1], gyros, gyro_cross, accs);

  // --- Navigation in W. ---
  // The sum taken to W with the columns of R_W_S of the unit quaternion (w, x, y, z), which do
  // not wait for this sample.
  // (The components come from the register, not from the members: reading one double of a
  // 32-byte store of the previous step stalls store forwarding.)
  const double qw = q_w_;
  const Lanes q_vec = get(q_vec_);
  const double qx = q_vec[0], qy = q_vec[1], qz = q_vec[2];
  const double xx = qx * qx, yy = qy * qy, zz = qz * qz, xy = qx * qy, xz = qx * qz, yz = qy * qz,
               wx = qw * qx, wy = qw * qy, wz = qw * qz;
  const Lanes force_sum_W =
      force_sum[0] * Lanes{1.0 - 2.0 * (yy + zz), 2.0 * (xy + wz), 2.0 * (xz - wy), 0.0} +
      force_sum[1] * Lanes{2.0 * (xy - wz), 1.0 - 2.0 * (xx + zz), 2.0 * (yz + wx), 0.0} +
      force_sum[2] * Lanes{2.0 * (xz + wy), 2.0 * (yz - wx), 1.0 - 2.0 * (xx + yy), 0.0};
  // Parts of the new velocity and position that do not depend on this sample's specific force
  // (update_increment_maps): gravity at the mid-interval position, h v, the previous dv_0,
  // their Coriolis terms.
  const Lanes p = get(p_W_);
  const Lanes v = get(v_W_);
  const Lanes p_mid = p + (0.5 * h) * v;
  const Lanes gravity_increment =
      h * (get(gravity_origin_W_) +
           (p_mid[0] * get(gravity_gradient_W_[0]) + p_mid[1] * get(gravity_gradient_W_[1]) +
            p_mid[2] * get(gravity_gradient_W_[2])));
  const Lanes dp_known =
      h * v + previous_weight * get(previous_dv_0_W_) + trapezoid_weight * gravity_increment;
  const Lanes coriolis_known = cross(get(coriolis_rate_W_), dp_known);
  const Lanes v_known = v + gravity_increment - 2.0 * coriolis_known;
  const Lanes p_known = p + dp_known - h * coriolis_known;

  const Lanes v_new = v_known + apply_map(velocity_map_, force_sum_W);
  const Lanes p_new = p_known + trapezoid_weight * apply_map(position_map_, force_sum_W);
  put(v_W_, v_new);
  put(p_W_, p_new);
  put(previous_dv_0_W_, gravity_increment + apply_map(dv_0_map_, force_sum_W));

  // Attitude: q_W_S <- exp(-omega_ie h) q_W_S exp(body) = q_W_S exp(earth_turn) exp(body),
  // with earth_turn = -h omega_ie^S the turn of W in S_{k-1}, the two rotations joined by
  // Baker-Campbell-Hausdorff to third order (the next terms are below 1e-18 rad). Joining them
  // first keeps a sensor at rest exactly at rest: the two nearly cancel before the one
  // quaternion product, so no rounding repeats every step.
  const Lanes earth_turn = -h * get(earth_rate_S_);
  const Lanes first_order = body_rotation + earth_turn;
  const Lanes earth_body = cross(earth_turn, body_rotation);
  const Lanes joined =
      first_order + 0.5 * earth_body - (1.0 / 12) * cross(body_rotation, earth_body);
  // |joined|^2 = |first_order|^2 + |earth_body|^2 / 12 + O(|earth_body|^2 |body|^2) exactly
  // (earth_body is normal to both rotations); |earth_body| < 1e-10 rad even at 3 rad/s and
  // 1 kHz, so the first term alone is exact to 1e-21 rad^2 and is ready earlier.
  double dq_w, dq_scale;
  rotation_quaternion_terms(dot(first_order, first_order), dq_w, dq_scale);
  // One Newton step towards unit norm (no square root), from the norm before the product
  // (the product with a unit quaternion keeps it): off the step-to-step dependency chain.
  const double norm_correction = 0.5 * (3.0 - (qw * qw + (xx + yy + zz)));
  // Hamilton product q (x) dq with dq = (dq_w, dq_scale joined), scaled.
  const double q_w_new = norm_correction * (qw * dq_w - dq_scale * dot(q_vec, joined));
  const Lanes q_vec_new = (norm_correction * dq_scale) * (qw * joined + cross(q_vec, joined)) +
                          (norm_correction * dq_w) * q_vec;
  put(q_vec_, q_vec_new);
  q_w_ = q_w_new;

  // omega_ie in S follows the body rotation (the Earth turn leaves it unchanged). Carried
  // along rather than computed from q so that the attitude update does not wait for it;
  // recomputed from q now and then so that rounding cannot accumulate.
  const bool sync = ++steps_since_sync_ >= kEarthRateSyncSteps;
  if (!sync) [[likely]] {
    put(earth_rate_S_, rotate_by_vector(-1.0 * body_rotation, get(earth_rate_S_)));
  }
  // The output state, from the registers (see above).
  state_.q_W_S = Eigen::Quaterniond(q_w_new, q_vec_new[0], q_vec_new[1], q_vec_new[2]);
  state_.p_W = Eigen::Vector3d(p_new[0], p_new[1], p_new[2]);
  state_.v_W = Eigen::Vector3d(v_new[0], v_new[1], v_new[2]);
  state_.t_s = increment.t_s;
  if (sync) [[unlikely]] {
    sync_earth_rate();
  }

  // Keep the two latest increments: a ring of two, the oldest is overwritten (no copies).
  if (history_count_ < 2) ++history_count_;
  newest_ = 1 - newest_;
  put(gyro_history_[newest_], gyro);
  put(acc_history_[newest_], acc);
  previous_dt_s_ = h;
}

std::vector<NavState> mechanize(const ImuSeries& increments, const EarthModel& earth,
                                const NavState& initial, StrapdownOptions options) {
  if (increments.quantity != ImuQuantity::kIncrements) {
    throw std::invalid_argument(
        "mechanize: the series '" + increments.source +
        "' holds rates (rad/s, m/s^2); strapdown mechanization needs increments (rad, m/s)");
  }
  std::vector<NavState> states;
  states.reserve(increments.samples.size() + 1);
  states.push_back(initial);
  Strapdown strapdown(earth, initial, options);
  for (const ImuSample& sample : increments.samples) {
    strapdown.step(sample);
    states.push_back(strapdown.state());
  }
  return states;
}

}  // namespace imscal::ims
