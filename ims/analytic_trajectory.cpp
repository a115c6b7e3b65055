#include "ims/analytic_trajectory.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

#include "core/units.hpp"
#include "ims/so3.hpp"

namespace imscal::ims {

SmoothStep::Value SmoothStep::at(double t_s) const {
  const double duration = t_end_s - t_begin_s;
  if (t_s <= t_begin_s) return {0.0, 0.0, 0.0};
  if (t_s >= t_end_s) return {1.0, 0.0, 0.0};
  const double u = (t_s - t_begin_s) / duration;
  const double v = 1.0 - u;
  const double u2 = u * u;
  const double u3 = u2 * u;
  Value out;
  // Bernstein form: s = sum_{k=5..9} C(9,k) u^k v^(9-k). All terms are positive, so s is
  // accurate to a few ulp everywhere (the monomial form loses ~500 ulp near u = 1 by
  // cancellation, which would show as noise in the attitude).
  out.s = u2 * u3 *
          (126.0 * (v * v) * (v * v) + 84.0 * u * (v * v * v) + 36.0 * u2 * (v * v) + 9.0 * u3 * v +
           u2 * u2);
  out.ds_dt = 630.0 * u2 * u2 * (v * v) * (v * v) / duration;
  out.d2s_dt2 = 2520.0 * u3 * (v * v * v) * (1.0 - 2.0 * u) / (duration * duration);
  return out;
}

namespace {
void check_window(double t_begin_s, double t_end_s) {
  if (!(t_end_s > t_begin_s) || !std::isfinite(t_begin_s) || !std::isfinite(t_end_s)) {
    throw std::invalid_argument(
        fmt::format("motion step: window [{}, {}] s is empty or reversed", t_begin_s, t_end_s));
  }
}
}  // namespace

AnalyticTrajectory::AnalyticTrajectory(double begin_s, double end_s,
                                       const Eigen::Quaterniond& q_W_S_start,
                                       const Eigen::Vector3d& p_W_start)
    : begin_s_(begin_s),
      end_s_(end_s),
      q_W_S_start_(q_W_S_start.normalized()),
      p_W_start_(p_W_start) {
  check_window(begin_s, end_s);
}

void AnalyticTrajectory::add_rotation(double t_begin_s, double t_end_s,
                                      const Eigen::Vector3d& axis_S, double angle_rad) {
  check_window(t_begin_s, t_end_s);
  if (!(axis_S.norm() > 0.0) || !std::isfinite(angle_rad)) {
    throw std::invalid_argument("motion rotation: axis must be non-zero, angle finite");
  }
  rotations_.push_back({{t_begin_s, t_end_s}, axis_S.normalized(), angle_rad});
  add_joints(t_begin_s, t_end_s);
}

void AnalyticTrajectory::add_joints(double t_begin_s, double t_end_s) {
  for (double t : {t_begin_s, t_end_s}) {
    const auto where = std::lower_bound(joints_s_.begin(), joints_s_.end(), t);
    if (where == joints_s_.end() || *where != t) joints_s_.insert(where, t);
  }
}

void AnalyticTrajectory::add_translation(double t_begin_s, double t_end_s,
                                         const Eigen::Vector3d& displacement_W) {
  check_window(t_begin_s, t_end_s);
  if (!displacement_W.allFinite()) {
    throw std::invalid_argument("motion translation: displacement must be finite");
  }
  translations_.push_back({{t_begin_s, t_end_s}, displacement_W});
  add_joints(t_begin_s, t_end_s);
}

KinematicState AnalyticTrajectory::at(double t_s) const {
  KinematicState state;
  state.p_W = p_W_start_;
  for (const auto& tr : translations_) {
    const SmoothStep::Value s = tr.step.at(t_s);
    state.p_W += tr.displacement_W * s.s;
    state.v_W += tr.displacement_W * s.ds_dt;
    state.a_W += tr.displacement_W * s.d2s_dt2;
  }
  // Attitude: product in the order added. Rate: walk backwards, carrying the product of the
  // later factors R_{k+1..n} (as a quaternion) to map each u_k dtheta_k into the final S.
  Eigen::Quaterniond later = Eigen::Quaterniond::Identity();  // R_{k+1} ... R_n
  for (std::size_t k = rotations_.size(); k-- > 0;) {
    const RotationStep& r = rotations_[k];
    const SmoothStep::Value s = r.step.at(t_s);
    if (s.s == 0.0) continue;  // not started: identity factor, no rate
    if (s.ds_dt != 0.0)
      state.omega_WS_S += later.conjugate() * (r.axis_S * (r.angle_rad * s.ds_dt));
    later = quat_exp(Eigen::Vector3d(r.axis_S * (r.angle_rad * s.s))) * later;
  }
  state.q_W_S = (q_W_S_start_ * later).normalized();
  return state;
}

std::vector<std::pair<double, double>> AnalyticTrajectory::rest_intervals() const {
  std::vector<std::pair<double, double>> windows;
  for (const auto& r : rotations_) windows.emplace_back(r.step.t_begin_s, r.step.t_end_s);
  for (const auto& tr : translations_) windows.emplace_back(tr.step.t_begin_s, tr.step.t_end_s);
  std::sort(windows.begin(), windows.end());
  std::vector<std::pair<double, double>> rests;
  double rest_start = begin_s_;
  for (const auto& [b, e] : windows) {
    if (b > rest_start && rest_start < end_s_) rests.emplace_back(rest_start, std::min(b, end_s_));
    rest_start = std::max(rest_start, e);
  }
  if (rest_start < end_s_) rests.emplace_back(rest_start, end_s_);
  return rests;
}

std::unique_ptr<AnalyticTrajectory> make_roundtrip_test_motion() {
  auto motion = std::make_unique<AnalyticTrajectory>(0.0, 60.0);
  double t = 3.0;  // rest before
  // +-pi about each axis: peak rate 2.461 * pi / 2.6 s = 2.97 rad/s.
  const double rotation_s = 2.6;
  for (int axis = 0; axis < 3; ++axis) {
    const Eigen::Vector3d u = Eigen::Vector3d::Unit(axis);
    motion->add_rotation(t, t + rotation_s, u, M_PI);
    t += rotation_s + 0.9;
    motion->add_rotation(t, t + rotation_s, u, -M_PI);
    t += rotation_s + 0.9;
  }
  // +-1 m along each axis: peak acceleration 9.372 * 1 m / (2.2 s)^2 = 1.94 m/s^2.
  const double translation_s = 2.2;
  for (int axis = 0; axis < 3; ++axis) {
    const Eigen::Vector3d d = Eigen::Vector3d::Unit(axis);
    motion->add_translation(t, t + translation_s, d);
    t += translation_s + 0.4;
    motion->add_translation(t, t + translation_s, -d);
    t += translation_s + 0.4;
  }
  // t = 39.6 s: concurrent rotation (about a skew axis) and translation, then back.
  const Eigen::Vector3d skew_axis(1.0, 1.0, 1.0);
  const Eigen::Vector3d shift(0.5, -0.4, 0.3);
  motion->add_rotation(t, t + 3.0, skew_axis, 2.0);
  motion->add_translation(t + 0.5, t + 3.0, shift);
  t += 3.5;
  motion->add_rotation(t, t + 3.0, skew_axis, -2.0);
  motion->add_translation(t, t + 2.5, -shift);
  t += 3.5;
  // t = 46.6 s: a tilt about y of S overlapping a translation along x of W, then back.
  motion->add_rotation(t, t + 2.0, Eigen::Vector3d::UnitY(), 1.0);
  motion->add_translation(t + 1.0, t + 3.0, Eigen::Vector3d(0.6, 0.0, 0.0));
  t += 3.5;
  motion->add_rotation(t, t + 2.0, Eigen::Vector3d::UnitY(), -1.0);
  motion->add_translation(t + 0.5, t + 2.5, Eigen::Vector3d(-0.6, 0.0, 0.0));
  // Last step ends at 52.6 s: rest for the remaining 7.4 s.
  return motion;
}

namespace {
// Uniform in [0, 1) from the top 53 bits: specified exactly, unlike std::uniform_real_distribution.
double uniform01(std::mt19937_64& rng) {
  return static_cast<double>(rng() >> 11) * 0x1.0p-53;
}
double uniform(std::mt19937_64& rng, double lo, double hi) {
  return lo + (hi - lo) * uniform01(rng);
}
Eigen::Vector3d random_unit_vector(std::mt19937_64& rng) {
  const double z = uniform(rng, -1.0, 1.0);
  const double phi = uniform(rng, 0.0, 2.0 * M_PI);
  const double r = std::sqrt(1.0 - z * z);
  return {r * std::cos(phi), r * std::sin(phi), z};
}
}  // namespace

std::unique_ptr<AnalyticTrajectory> make_motion_with_pauses(double duration_s, double max_move_s,
                                                            unsigned seed) {
  if (!(duration_s >= 4.0) || !(max_move_s >= 2.0) || !std::isfinite(duration_s) ||
      !std::isfinite(max_move_s)) {
    throw std::invalid_argument(
        "make_motion_with_pauses: need duration_s >= 4 s and "
        "max_move_s >= 2 s");
  }
  auto motion = std::make_unique<AnalyticTrajectory>(0.0, duration_s);
  std::mt19937_64 rng(seed);
  const Eigen::Vector3d box_half_m(0.5, 0.5, 0.3);
  const double max_rate_rad_s = 3.0;
  const double max_accel_m_s2 = 2.0;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  double t = 2.0;  // initial rest
  while (true) {
    // A rest starts at most max_move_s - 0.5 s after the previous one started, so that every
    // window of max_move_s holds a whole rest of >= 0.5 s.
    const double pause_s = uniform(rng, 0.5, std::min(1.0, max_move_s - 1.5));
    const double longest_move_s = max_move_s - 0.5 - pause_s;
    const double move_s = uniform(rng, std::max(1.0, 0.5 * longest_move_s), longest_move_s);
    if (t + move_s + 1.0 > duration_s) break;  // keep >= 1 s of rest at the end
    // Rotation and translation windows: independent sub-windows of the move.
    const double rot_begin = t + uniform(rng, 0.0, 0.15) * move_s;
    const double rot_end = t + move_s - uniform(rng, 0.0, 0.15) * move_s;
    const double tr_begin = t + uniform(rng, 0.0, 0.15) * move_s;
    const double tr_end = t + move_s - uniform(rng, 0.0, 0.15) * move_s;
    // Peak rate = kPeakSlope * angle / window.
    const double max_angle =
        std::min(2.0, max_rate_rad_s * (rot_end - rot_begin) / SmoothStep::kPeakSlope);
    const double angle = uniform(rng, 0.2, 1.0) * max_angle * (uniform01(rng) < 0.5 ? -1 : 1);
    motion->add_rotation(rot_begin, rot_end, random_unit_vector(rng), angle);
    // Translation towards a random point of the box, limited by 1 m and the peak acceleration.
    Eigen::Vector3d target;
    for (int i = 0; i < 3; ++i) target[i] = uniform(rng, -box_half_m[i], box_half_m[i]);
    Eigen::Vector3d displacement = target - position;
    const double window = tr_end - tr_begin;
    const double max_length =
        std::min(1.0, max_accel_m_s2 * window * window / SmoothStep::kPeakCurvature);
    if (displacement.norm() > max_length) displacement *= max_length / displacement.norm();
    motion->add_translation(tr_begin, tr_end, displacement);
    position += displacement;
    t += move_s + pause_s;
  }
  return motion;
}

namespace {
std::unique_ptr<AnalyticTrajectory> load_segments(const ConfigNode& config) {
  config.require_only_keys({"kind", "start", "segments"});
  Eigen::Quaterniond q_start = Eigen::Quaterniond::Identity();
  Eigen::Vector3d p_start = Eigen::Vector3d::Zero();
  if (auto start = config.optional_child("start")) {
    start->require_only_keys({"position_m", "rotation_vector_deg"});
    if (auto p = start->optional_child("position_m")) p_start = p->as_vector3();
    if (auto r = start->optional_child("rotation_vector_deg")) {
      q_start = quat_exp(Eigen::Vector3d(r->as_vector3() * kRadPerDeg));
    }
  }
  const auto segments = config.child("segments").as_sequence();
  if (segments.empty()) config.child("segments").fail("expected at least one segment");
  double total_s = 0.0;
  for (const auto& seg : segments) {
    const double d = seg.child("duration_s").as_double();
    if (!(d > 0.0)) seg.child("duration_s").fail("expected a positive duration");
    total_s += d;
  }
  auto motion = std::make_unique<AnalyticTrajectory>(0.0, total_s, q_start, p_start);
  double t = 0.0;
  for (const auto& seg : segments) {
    seg.require_only_keys(
        {"duration_s", "rotation_axis_S", "rotation_angle_deg", "translation_W_m"});
    const double d = seg.child("duration_s").as_double();
    if (seg.has("rotation_axis_S") != seg.has("rotation_angle_deg")) {
      seg.fail("rotation_axis_S and rotation_angle_deg go together");
    }
    if (seg.has("rotation_axis_S")) {
      const Eigen::Vector3d axis = seg.child("rotation_axis_S").as_vector3();
      if (!(axis.norm() > 0.0)) seg.child("rotation_axis_S").fail("axis must be non-zero");
      motion->add_rotation(t, t + d, axis,
                           seg.child("rotation_angle_deg").as_double() * M_PI / 180.0);
    }
    if (auto tr = seg.optional_child("translation_W_m")) {
      motion->add_translation(t, t + d, tr->as_vector3());
    }
    t += d;
  }
  return motion;
}
}  // namespace

std::unique_ptr<AnalyticTrajectory> load_motion(const ConfigNode& config) {
  const std::string kind = config.child("kind").as_string();
  if (kind == "roundtrip_test") {
    config.require_only_keys({"kind"});
    return make_roundtrip_test_motion();
  }
  if (kind == "random_with_pauses") {
    config.require_only_keys({"kind", "duration_s", "max_move_s", "seed"});
    const double duration = config.child("duration_s").as_double();
    const double max_move = config.child("max_move_s").as_double();
    const long seed = config.child("seed").as_int();
    if (duration < 4.0) config.child("duration_s").fail("expected at least 4 s");
    if (max_move < 2.0) config.child("max_move_s").fail("expected at least 2 s");
    if (seed < 0 || seed > 4294967295L) config.child("seed").fail("expected 0 .. 2^32-1");
    return make_motion_with_pauses(duration, max_move, static_cast<unsigned>(seed));
  }
  if (kind == "segments") return load_segments(config);
  config.child("kind").fail("expected one of roundtrip_test, random_with_pauses, segments, got '" +
                            kind + "'");
}

std::unique_ptr<AnalyticTrajectory> load_motion_file(const std::filesystem::path& file) {
  return load_motion(ConfigNode::load_file(file));
}

}  // namespace imscal::ims
