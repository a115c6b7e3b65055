#include "sim/motion_planner.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/input_error.hpp"
#include "core/units.hpp"
#include "robot/forward_kinematics.hpp"
#include "robot/ik_solver.hpp"
#include "robot/jacobian.hpp"
#include "sim/cartesian_timing.hpp"
#include "sim/motion_profile.hpp"

namespace imscal::sim {
namespace {

using calib::JointVector;
using calib::kJointCount;
using Vector6d = Eigen::Matrix<double, 6, 1>;

// Relative slack on limit checks: the profile meets its limits up to rounding (~1e-15).
constexpr double kLimitSlack = 1e-9;

// A point on the geometric path and its derivatives with respect to the arc length s [m].
struct PathPoint {
  Eigen::Vector3d p, dp_ds, d2p_ds2;
};

// The flange pose and its first two time derivatives.
struct FlangeMotion {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  Vector6d twist = Vector6d::Zero();         // [v; w] in R
  Vector6d acceleration = Vector6d::Zero();  // [a; w_dot] in R
};

// A LIN/CIRC move without its timing: the flange origin's path p(s), s in [0, length] [m], and
// the orientation law R(s) = R0 exp(s / length theta [k]) (rotation_vector = theta k, in R0's
// axes).
struct CartesianPath {
  double length = 0.0;
  std::function<PathPoint(double)> geometry;
  Eigen::Matrix3d R0 = Eigen::Matrix3d::Identity();
  Eigen::Vector3d rotation_vector = Eigen::Vector3d::Zero();

  Eigen::Matrix3d rotation(double s) const;
};

// Joint angles and their planned rates in one cycle.
struct JointState {
  JointVector q, qd, qdd;
};

class Planner {
 public:
  Planner(const calib::RobotDescription& robot, const MotionProgram& program)
      : robot_(robot),
        program_(program),
        ik_(calib::make_inverse_kinematics(robot.kinematics)),
        cycle_(robot.controller_cycle_s) {}

  DesiredJointPath run();

 private:
  [[noreturn]] void fail(const ProgramStep& step, const std::string& problem) const {
    throw InputError(program_.source, step.line,
                     fmt::format("segments[{}] '{}'", step.index, step.label), problem);
  }
  void check_within_limits(const ProgramStep& step, const JointVector& q, const char* what) const;
  std::string describe_outside_limits(const JointVector& q) const;
  using SampleFn = std::function<void(double t, JointVector& q, JointVector& qd, JointVector& qdd)>;
  void emit(const ProgramStep& step, SegmentKind kind, long cycles, const SampleFn& fn);
  void plan_rest(const ProgramStep& step);
  void plan_ptp(const ProgramStep& step);
  void plan_cartesian(const ProgramStep& step);
  CartesianPath cartesian_path(const ProgramStep& step) const;
  std::vector<JointState> sample_cartesian(const ProgramStep& step, const CartesianPath& path,
                                           const MotionProfile& profile) const;
  JointLimits joint_limits(const ProgramStep& step) const;
  JointLimitUse limit_use(const JointLimits& limits, const std::vector<JointState>& samples) const;
  JointPathDerivatives joint_path_derivatives(const CartesianPath& path,
                                              const MotionProfile& profile,
                                              const std::vector<JointState>& samples) const;
  void log_slowed(const ProgramStep& step, const CartesianTiming& timing, double duration_s) const;
  std::string joint_name(int i) const {
    return i < 0 ? std::string("none") : robot_.joints[static_cast<std::size_t>(i)].name;
  }
  JointVector solve_pose(const ProgramStep& step, const Eigen::Isometry3d& pose) const;
  MotionProfile path_profile(ProfileKind kind, double length, const ProfileLimits& limits) const;
  long cycles_for(double duration) const {
    return static_cast<long>(std::ceil(duration / cycle_ - 1e-9));
  }

  const calib::RobotDescription& robot_;
  const MotionProgram& program_;
  std::unique_ptr<calib::IkSolver> ik_;  // of the arm's class
  double cycle_;
  DesiredJointPath path_;
  JointVector q_;  // current joints (end of the last segment)
  int payload_index_ = 0;
};

std::string Planner::describe_outside_limits(const JointVector& q) const {
  const auto& k = robot_.kinematics;
  std::string out;
  for (int i = 0; i < kJointCount; ++i) {
    if (q(i) < k.lower_limit_rad(i) || q(i) > k.upper_limit_rad(i)) {
      out += fmt::format(" joint {} would reach {:.3f} deg, outside [{:.1f}, {:.1f}] deg;",
                         robot_.joints[i].name, q(i) * kDegPerRad,
                         k.lower_limit_rad(i) * kDegPerRad, k.upper_limit_rad(i) * kDegPerRad);
    }
  }
  return out;
}

void Planner::check_within_limits(const ProgramStep& step, const JointVector& q,
                                  const char* what) const {
  const auto& k = robot_.kinematics;
  for (int i = 0; i < kJointCount; ++i) {
    if (q(i) < k.lower_limit_rad(i) || q(i) > k.upper_limit_rad(i)) {
      fail(step,
           fmt::format("{}: joint {} at {:.4f} deg is outside its limits [{:.1f}, {:.1f}] deg",
                       what, robot_.joints[i].name, q(i) * kDegPerRad,
                       k.lower_limit_rad(i) * kDegPerRad, k.upper_limit_rad(i) * kDegPerRad));
    }
  }
}

void Planner::emit(const ProgramStep& step, SegmentKind kind, long cycles, const SampleFn& fn) {
  PathSegment segment;
  segment.kind = kind;
  segment.label = step.label;
  segment.begin_s = path_.samples.back().t_s;
  const long first = static_cast<long>(path_.samples.size()) - 1;
  for (long k = 1; k <= cycles; ++k) {
    DesiredJointSample sample;
    sample.t_s = static_cast<double>(first + k) * cycle_;
    sample.payload_index = payload_index_;
    fn(static_cast<double>(k) * cycle_, sample.q_rad, sample.qd_rad_s, sample.qdd_rad_s2);
    path_.samples.push_back(sample);
  }
  segment.end_s = path_.samples.back().t_s;
  q_ = path_.samples.back().q_rad;
  path_.segments.push_back(segment);
}

void Planner::plan_rest(const ProgramStep& step) {
  const long cycles = std::max(1L, std::lround(step.duration_s / cycle_));
  const JointVector q = q_;
  emit(step, SegmentKind::kRest, cycles,
       [&](double, JointVector& qo, JointVector& qd, JointVector& qdd) {
         qo = q;
         qd.setZero();
         qdd.setZero();
       });
}

// IK of a PTP target: among the configurations that succeed, the one nearest to the current
// joints (largest single-joint change smallest).
JointVector Planner::solve_pose(const ProgramStep& step, const Eigen::Isometry3d& pose) const {
  calib::IkOptions options;
  options.q_near = q_;
  const std::vector<calib::IkResult> all = ik_->solve_all(pose, options);
  const calib::IkResult* best = nullptr;
  double best_change = std::numeric_limits<double>::infinity();
  for (const auto& r : all) {
    if (!r.ok()) continue;
    const double change = (r.q - q_).cwiseAbs().maxCoeff();
    if (change < best_change) {
      best_change = change;
      best = &r;
    }
  }
  if (best == nullptr) {
    const auto current = ik_->configuration_of(q_);
    std::string reason;
    for (std::size_t i = 0; i < all.size(); ++i) {
      if (calib::IkSolver::all_configurations()[i] == current) {
        reason = all[i].status == calib::IkStatus::kOutsideJointLimits
                     ? "outside joint limits:" + describe_outside_limits(all[i].q)
                     : std::string(calib::to_string(all[i].status)) + ": " + all[i].reason;
      }
    }
    fail(step, fmt::format("target pose ({:.1f}, {:.1f}, {:.1f}) mm has no IK solution within the "
                           "joint limits ({}: {})",
                           pose.translation().x() * 1e3, pose.translation().y() * 1e3,
                           pose.translation().z() * 1e3, calib::to_string(current), reason));
  }
  return best->q;
}

void Planner::plan_ptp(const ProgramStep& step) {
  const JointVector target =
      step.target_joints_rad ? *step.target_joints_rad : solve_pose(step, *step.target_pose);
  check_within_limits(step, target, "target");
  const JointVector q0 = q_;
  const JointVector delta = target - q0;
  // Normalised profile s: 0 -> 1; joint i needs s_dot <= v_i / |dq_i| etc.
  ProfileLimits limits{std::numeric_limits<double>::infinity(),
                       std::numeric_limits<double>::infinity(),
                       std::numeric_limits<double>::infinity()};
  for (int i = 0; i < kJointCount; ++i) {
    const double d = std::abs(delta(i));
    if (d == 0.0) continue;
    limits.velocity =
        std::min(limits.velocity, step.velocity_scale * robot_.joints[i].max_velocity_rad_s / d);
    limits.acceleration = std::min(
        limits.acceleration, step.acceleration_scale * program_.max_acceleration_rad_s2(i) / d);
    if (program_.max_jerk_rad_s3) {
      limits.jerk =
          std::min(limits.jerk, step.acceleration_scale * (*program_.max_jerk_rad_s3)(i) / d);
    }
  }
  if (delta.cwiseAbs().maxCoeff() == 0.0) {
    emit(step, SegmentKind::kPtp, 0, {});  // nothing to do: an empty segment
    return;
  }
  const MotionProfile raw = MotionProfile::plan(step.profile, 1.0, limits);
  const long cycles = cycles_for(raw.duration());
  const MotionProfile profile = raw.stretched_to(static_cast<double>(cycles) * cycle_);
  emit(step, SegmentKind::kPtp, cycles,
       [&](double t, JointVector& q, JointVector& qd, JointVector& qdd) {
         const ProfileState s = profile.at(t);
         q = q0 + delta * s.position;
         qd = delta * s.velocity;
         qdd = delta * s.acceleration;
       });
  q_ = target;  // exactly (s(T) = 1 exactly, but q0 + delta may round)
  path_.samples.back().q_rad = target;
}

MotionProfile Planner::path_profile(ProfileKind kind, double length,
                                    const ProfileLimits& limits) const {
  const MotionProfile raw = MotionProfile::plan(kind, length, limits);
  return raw.stretched_to(static_cast<double>(cycles_for(raw.duration())) * cycle_);
}

Eigen::Matrix3d CartesianPath::rotation(double s) const {
  const double sigma = s / length;
  return R0 * Eigen::AngleAxisd(sigma * rotation_vector.norm(),
                                rotation_vector.norm() > 0.0
                                    ? Eigen::Vector3d(rotation_vector.normalized())
                                    : Eigen::Vector3d::UnitZ())
                  .toRotationMatrix();
}

CartesianPath Planner::cartesian_path(const ProgramStep& step) const {
  const Eigen::Isometry3d start = calib::forward_kinematics<double>(robot_.kinematics, q_);
  const Eigen::Vector3d p0 = start.translation();
  CartesianPath path;
  path.R0 = start.linear();

  // The geometric path p(s), s in [0, length].
  if (step.kind == ProgramStepKind::kLinear) {
    const Eigen::Vector3d p1 =
        step.target_is_offset ? Eigen::Vector3d(p0 + step.target_m) : step.target_m;
    path.length = (p1 - p0).norm();
    if (path.length < 1e-9) fail(step, "a line of zero length (use ptp to only turn the flange)");
    const Eigen::Vector3d u = (p1 - p0) / path.length;
    path.geometry = [p0, u](double s) { return PathPoint{p0 + s * u, u, Eigen::Vector3d::Zero()}; };
  } else {
    Eigen::Vector3d centre, normal;
    double radius = 0.0, angle = 0.0;
    if (step.kind == ProgramStepKind::kCircleThroughVia) {
      // Circumcentre of p0, via, p1: c = p0 + ((|a|^2 b - |b|^2 a) x (a x b)) / (2 |a x b|^2).
      const Eigen::Vector3d a = step.via_m - p0;
      const Eigen::Vector3d b = step.target_m - p0;
      const Eigen::Vector3d axb = a.cross(b);
      if (axb.norm() < 1e-6 * a.norm() * b.norm() || a.norm() < 1e-6 || b.norm() < 1e-6) {
        fail(step, "start, via and target points are (nearly) collinear or coincide: no circle");
      }
      centre =
          p0 + (a.squaredNorm() * b - b.squaredNorm() * a).cross(axb) / (2.0 * axb.squaredNorm());
      normal = axb.normalized();  // p0 -> via -> p1 turns positively about this normal
      radius = (p0 - centre).norm();
      const Eigen::Vector3d e1 = (p0 - centre) / radius;
      const Eigen::Vector3d e2 = normal.cross(e1);
      const Eigen::Vector3d r1 = step.target_m - centre;
      angle = std::atan2(r1.dot(e2), r1.dot(e1));
      if (angle <= 0.0) angle += 2.0 * M_PI;
    } else {
      centre = step.centre_m;
      normal = step.angle_rad > 0.0 ? step.normal : Eigen::Vector3d(-step.normal);
      angle = std::abs(step.angle_rad);
      radius = step.radius_m;
      const Eigen::Vector3d r0 = p0 - centre;
      const double off_plane = r0.dot(normal);
      const double off_radius = (r0 - off_plane * normal).norm() - radius;
      if (std::abs(off_plane) > 1e-6 || std::abs(off_radius) > 1e-6) {
        fail(step,
             fmt::format("the start position ({:.3f}, {:.3f}, {:.3f}) mm is not on the circle "
                         "({:.3f} mm off its plane, {:.3f} mm off its radius; tolerance "
                         "0.001 mm)",
                         p0.x() * 1e3, p0.y() * 1e3, p0.z() * 1e3, off_plane * 1e3,
                         off_radius * 1e3));
      }
    }
    path.length = radius * angle;
    const Eigen::Vector3d e1 = (p0 - centre - (p0 - centre).dot(normal) * normal).normalized();
    const Eigen::Vector3d e2 = normal.cross(e1);
    path.geometry = [centre, e1, e2, radius](double s) {
      const double phi = s / radius;
      const Eigen::Vector3d radial = std::cos(phi) * e1 + std::sin(phi) * e2;
      const Eigen::Vector3d tangent = -std::sin(phi) * e1 + std::cos(phi) * e2;
      return PathPoint{centre + radius * radial, tangent, -radial / radius};
    };
  }

  // Orientation: R(sigma) = R0 exp(sigma theta [k]), sigma = s / length.
  if (step.orientation == OrientationMode::kSlerp) {
    const Eigen::AngleAxisd turn(path.R0.transpose() * (*step.target_rotation));
    path.rotation_vector = turn.angle() * turn.axis();
  }
  return path;
}

std::vector<JointState> Planner::sample_cartesian(const ProgramStep& step,
                                                  const CartesianPath& path,
                                                  const MotionProfile& profile) const {
  const long cycles = cycles_for(profile.duration() - 1e-12);
  const double length = path.length;
  calib::IkOptions options;
  options.singularity_tolerance = kSingularityTolerance;
  JointVector q_prev = q_;
  std::vector<JointState> out(static_cast<std::size_t>(cycles));
  for (long k = 1; k <= cycles; ++k) {
    const double t = static_cast<double>(k) * cycle_;
    JointState& j = out[static_cast<std::size_t>(k - 1)];
    const ProfileState s = profile.at(t);
    const PathPoint point = path.geometry(s.position);
    FlangeMotion m;
    m.pose.translation() = point.p;
    m.pose.linear() = path.rotation(s.position);
    m.twist.head<3>() = point.dp_ds * s.velocity;
    m.twist.tail<3>() = path.R0 * path.rotation_vector * (s.velocity / length);
    m.acceleration.head<3>() =
        point.d2p_ds2 * s.velocity * s.velocity + point.dp_ds * s.acceleration;
    m.acceleration.tail<3>() = path.R0 * path.rotation_vector * (s.acceleration / length);

    options.q_near = q_prev;
    const calib::IkResult ik = ik_->solve(m.pose, ik_->configuration_of(q_prev), options);
    if (ik.status == calib::IkStatus::kOutsideJointLimits) {
      fail(step, fmt::format("at {:.3f} s ({:.1f} mm along the path):{}", t, s.position * 1e3,
                             describe_outside_limits(ik.q)));
    }
    if (!ik.ok()) {
      fail(step, fmt::format("at {:.3f} s ({:.1f} mm along the path, flange at ({:.1f}, {:.1f}, "
                             "{:.1f}) mm): {}: {}",
                             t, s.position * 1e3, point.p.x() * 1e3, point.p.y() * 1e3,
                             point.p.z() * 1e3, calib::to_string(ik.status), ik.reason));
    }
    j.q = ik.q;
    const calib::Jacobian J = calib::geometric_jacobian(robot_.kinematics, j.q);
    const Eigen::PartialPivLU<calib::Jacobian> lu(J);
    j.qd = lu.solve(m.twist);
    j.qdd = lu.solve(m.acceleration - jacobian_rate_times_joint_rate(robot_.kinematics, j.q, j.qd));
    for (int i = 0; i < kJointCount; ++i) {
      const double v_max = robot_.joints[i].max_velocity_rad_s;
      if (std::abs(j.qd(i)) > v_max * (1.0 + kLimitSlack)) {
        fail(step, fmt::format("at {:.3f} s ({:.1f} mm along the path): joint {} would turn at "
                               "{:.1f} deg/s, above its max velocity {:.1f} deg/s",
                               t, s.position * 1e3, robot_.joints[i].name, j.qd(i) * kDegPerRad,
                               v_max * kDegPerRad));
      }
      // Between two samples a joint moves at most v_max * cycle; far more means IK jumped.
      if (std::abs(j.q(i) - q_prev(i)) > 2.0 * v_max * cycle_ + 1e-9) {
        fail(step, fmt::format("at {:.3f} s: joint {} jumps by {:.3f} deg in one cycle (IK "
                               "branch change)",
                               t, robot_.joints[i].name, (j.q(i) - q_prev(i)) * kDegPerRad));
      }
    }
    q_prev = j.q;
  }
  // The segment ends at rest: the profile's end state has zero rates.
  return out;
}

JointLimits Planner::joint_limits(const ProgramStep& step) const {
  JointLimits limits;
  limits.acceleration_rad_s2 = program_.max_acceleration_rad_s2;
  if (step.profile == ProfileKind::kJerkLimited) limits.jerk_rad_s3 = program_.max_jerk_rad_s3;
  return limits;
}

JointLimitUse Planner::limit_use(const JointLimits& limits,
                                 const std::vector<JointState>& samples) const {
  JointLimitMeter meter(limits, cycle_, path_.samples.back().qdd_rad_s2);
  for (const JointState& j : samples) meter.add(j.qdd);
  return meter.use();
}

// q'(s) = J^-1 [dp/ds; R0 theta k / length] and q''(s) = J^-1 ([d2p/ds2; 0] - J_dot(q, q') q') at
// the start and at every sample of a timing (q_ddot = q'' s_dot^2 + q' s_ddot,
// sim/cartesian_timing.hpp).
JointPathDerivatives Planner::joint_path_derivatives(const CartesianPath& path,
                                                     const MotionProfile& profile,
                                                     const std::vector<JointState>& samples) const {
  const Eigen::Vector3d w_per_s = path.R0 * path.rotation_vector / path.length;
  JointPathDerivatives out;
  auto add = [&](double s, const JointVector& q) {
    const PathPoint point = path.geometry(s);
    const Eigen::PartialPivLU<calib::Jacobian> lu(calib::geometric_jacobian(robot_.kinematics, q));
    Vector6d twist, curvature = Vector6d::Zero();
    twist << point.dp_ds, w_per_s;
    const JointVector dq = lu.solve(twist);
    curvature.head<3>() = point.d2p_ds2;
    out.add(s, dq, lu.solve(curvature - jacobian_rate_times_joint_rate(robot_.kinematics, q, dq)));
  };
  add(0.0, q_);
  for (std::size_t k = 0; k < samples.size(); ++k) {
    add(profile.at(static_cast<double>(k + 1) * cycle_).position, samples[k].q);
  }
  return out;
}

void Planner::plan_cartesian(const ProgramStep& step) {
  const CartesianPath path = cartesian_path(step);
  // The target first: a clear refusal if it is out of reach, before any sampling.
  Eigen::Isometry3d end_pose = Eigen::Isometry3d::Identity();
  end_pose.translation() = path.geometry(path.length).p;
  end_pose.linear() = path.rotation(path.length);
  solve_pose(step, end_pose);

  CartesianTiming timing;
  timing.programmed = {step.path.velocity_m_s, step.path.acceleration_m_s2, step.path.jerk_m_s3};
  MotionProfile profile = path_profile(step.profile, path.length, timing.programmed);
  std::vector<JointState> samples = sample_cartesian(step, path, profile);
  const JointLimits limits = joint_limits(step);
  timing.programmed_use = limit_use(limits, samples);
  timing.programmed_peak_velocity_m_s = profile.peak_velocity();
  timing.programmed_duration_s = static_cast<double>(samples.size()) * cycle_;
  timing.planned = timing.programmed;
  timing.planned_use = timing.programmed_use;
  timing.planned_peak_velocity_m_s = timing.programmed_peak_velocity_m_s;
  if (timing.programmed_use.ratio() > 1.0 + kJointLimitTolerance) {
    // Judge candidate timings without IK, on the joint path of the programmed samples.
    const JointPathDerivatives derivatives = joint_path_derivatives(path, profile, samples);
    TimingJudge judge;
    judge.duration = [&](const ProfileLimits& l) {
      return path_profile(step.profile, path.length, l).duration();
    };
    judge.within = [&](const ProfileLimits& l) {
      const MotionProfile candidate = path_profile(step.profile, path.length, l);
      JointLimitMeter meter(limits, cycle_, path_.samples.back().qdd_rad_s2);
      const long cycles = cycles_for(candidate.duration() - 1e-12);
      std::size_t cursor = 0;
      for (long k = 1; k <= cycles; ++k) {
        const ProfileState state = candidate.at(static_cast<double>(k) * cycle_);
        meter.add(derivatives.acceleration(state, cursor));
        if (meter.use().ratio() > 1.0) return false;
      }
      return true;
    };
    TimingChoice choice = choose_timing(timing.programmed, timing.programmed_use, judge);
    // The chosen timing sampled by IK and checked exactly; a remaining excess (interpolation
    // error) removed by a further uniform slow-down, exact for the continuous motion.
    int round = 0;
    for (;; ++round) {
      profile = path_profile(step.profile, path.length, choice.limits);
      samples = sample_cartesian(step, path, profile);
      timing.planned_use = limit_use(limits, samples);
      if (timing.planned_use.ratio() <= 1.0 + kJointLimitTolerance) break;
      if (round == 10) {
        throw std::logic_error(fmt::format("planner: '{}' stays above the joint limits ({:.9f})",
                                           step.label, timing.planned_use.ratio()));
      }
      choice.speed_factor *= std::max(std::sqrt(timing.planned_use.acceleration_ratio),
                                      std::cbrt(timing.planned_use.jerk_ratio));
      choice.limits = slowed_limits(timing.programmed, choice.speed_factor, choice.ramp_factor);
    }
    timing.planned = choice.limits;
    timing.planned_peak_velocity_m_s = profile.peak_velocity();
    timing.slowed = true;
    spdlog::debug(
        "planner: '{}': timing chosen after {} trials, {} corrections: k {:.6f}, m {:.6f}",
        step.label, choice.trials, round, choice.speed_factor, choice.ramp_factor);
    log_slowed(step, timing, static_cast<double>(samples.size()) * cycle_);
  }
  const long cycles = static_cast<long>(samples.size());
  emit(step, step.kind == ProgramStepKind::kLinear ? SegmentKind::kLinear : SegmentKind::kCircular,
       cycles, [&](double t, JointVector& q, JointVector& qd, JointVector& qdd) {
         const JointState& j = samples[static_cast<std::size_t>(std::lround(t / cycle_) - 1)];
         q = j.q;
         qd = j.qd;
         qdd = j.qdd;
       });
  path_.segments.back().timing = timing;
}

void Planner::log_slowed(const ProgramStep& step, const CartesianTiming& timing,
                         double duration_s) const {
  const JointLimitUse& before = timing.programmed_use;
  const JointLimitUse& after = timing.planned_use;
  spdlog::info(
      "planner: segments[{}] '{}' slowed to {:.0f} % of its programmed speed by {}'s {} limit: "
      "peak path speed {:.3f} -> {:.3f} m/s, duration {:.3f} -> {:.3f} s; profile limits {:.3f} -> "
      "{:.3f} m/s, {:.2f} -> {:.2f} m/s^2, {:.1f} -> {:.1f} m/s^3; largest joint acceleration "
      "{:.2f} ({}) -> {:.2f} ({}) of its limit, jerk {:.2f} ({}) -> {:.2f} ({})",
      step.index, step.label,
      100.0 * timing.planned_peak_velocity_m_s / timing.programmed_peak_velocity_m_s,
      joint_name(after.joint()), after.jerk_binds() ? "jerk" : "acceleration",
      timing.programmed_peak_velocity_m_s, timing.planned_peak_velocity_m_s,
      timing.programmed_duration_s, duration_s, timing.programmed.velocity, timing.planned.velocity,
      timing.programmed.acceleration, timing.planned.acceleration, timing.programmed.jerk,
      timing.planned.jerk, before.acceleration_ratio, joint_name(before.acceleration_joint),
      after.acceleration_ratio, joint_name(after.acceleration_joint), before.jerk_ratio,
      joint_name(before.jerk_joint), after.jerk_ratio, joint_name(after.jerk_joint));
}

DesiredJointPath Planner::run() {
  path_.cycle_s = cycle_;
  path_.payloads.push_back(program_.initial_payload);
  q_ = program_.start_joints_rad;
  const auto& k = robot_.kinematics;
  for (int i = 0; i < kJointCount; ++i) {
    if (q_(i) < k.lower_limit_rad(i) || q_(i) > k.upper_limit_rad(i)) {
      throw InputError(
          program_.source, 0, "start_joints_deg",
          fmt::format("joint {} at {:.4f} deg is outside its limits [{:.1f}, {:.1f}] deg",
                      robot_.joints[i].name, q_(i) * kDegPerRad, k.lower_limit_rad(i) * kDegPerRad,
                      k.upper_limit_rad(i) * kDegPerRad));
    }
  }
  DesiredJointSample first;
  first.q_rad = q_;
  path_.samples.push_back(first);
  for (const ProgramStep& step : program_.steps) {
    switch (step.kind) {
      case ProgramStepKind::kRest:
        plan_rest(step);
        break;
      case ProgramStepKind::kPtp:
        plan_ptp(step);
        break;
      case ProgramStepKind::kLinear:
      case ProgramStepKind::kCircleThroughVia:
      case ProgramStepKind::kCircleAboutCentre:
        plan_cartesian(step);
        break;
      case ProgramStepKind::kPayload:
        path_.payloads.push_back(step.payload);
        payload_index_ = static_cast<int>(path_.payloads.size()) - 1;
        // The last sample (at rest) already carries the new load from the next cycle on.
        break;
    }
  }
  return path_;
}

}  // namespace

Vector6d jacobian_rate_times_joint_rate(const calib::KinematicModel& model, const JointVector& q,
                                        const JointVector& q_dot) {
  const calib::ChainPoses<double> chain = calib::chain_poses<double>(model, q);
  const Eigen::Vector3d p_e = chain.T_R_H.translation();
  std::array<Eigen::Vector3d, kJointCount> z, p;
  for (int i = 0; i < kJointCount; ++i) {
    z[i] = chain.T_R_axis[i].linear().col(2);
    p[i] = chain.T_R_axis[i].translation();
  }
  // Velocity of the flange origin.
  Eigen::Vector3d v_e = Eigen::Vector3d::Zero();
  for (int k = 0; k < kJointCount; ++k) v_e += z[k].cross(p_e - p[k]) * q_dot(k);
  // Column i: J_i = [z_i x (p_e - p_i); z_i], with z_i and p_i fixed to the body before joint i,
  // which turns at w_i = sum_{k<i} z_k q_dot_k; so z_i_dot = w_i x z_i and
  // p_i_dot = sum_{k<i} z_k x (p_i - p_k) q_dot_k.
  Vector6d out = Vector6d::Zero();
  Eigen::Vector3d w = Eigen::Vector3d::Zero();
  for (int i = 0; i < kJointCount; ++i) {
    Eigen::Vector3d p_i_dot = Eigen::Vector3d::Zero();
    for (int k = 0; k < i; ++k) p_i_dot += z[k].cross(p[i] - p[k]) * q_dot(k);
    const Eigen::Vector3d z_dot = w.cross(z[i]);
    out.head<3>() += (z_dot.cross(p_e - p[i]) + z[i].cross(v_e - p_i_dot)) * q_dot(i);
    out.tail<3>() += z_dot * q_dot(i);
    w += z[i] * q_dot(i);
  }
  return out;
}

DesiredJointPath plan_motion(const calib::RobotDescription& robot, const MotionProgram& program) {
  Planner planner(robot, program);
  return planner.run();
}

}  // namespace imscal::sim
