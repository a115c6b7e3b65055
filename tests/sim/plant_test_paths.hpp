#pragma once
// Desired joint paths for the plant tests, built from smooth analytic profiles (independent of
// the motion planner): per move, each joint follows a trapezoid-like velocity profile whose ramps
// are half cosines (continuous acceleration at the ends of the ramps is not needed by the plant,
// but velocity and position are smooth and start/end at rest).
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <vector>

#include "core/units.hpp"
#include "robot/robot_description.hpp"
#include "sim/desired_path.hpp"

namespace imscal::sim::test {

// The default robot of the plant tests (datasets/robots/kr16.yaml), read once.
inline const calib::RobotDescription& kr16() {
  static const auto robot =
      calib::load_robot_description(IMSCAL_SOURCE_DIR "/datasets/robots/kr16.yaml");
  return robot;
}

// Upper arm vertical, forearm horizontal, hand tilted: gravity loads A2, A3, A5.
inline calib::JointVector home() {
  calib::JointVector q;
  q << 0.0, -90.0 * kRadPerDeg, 90.0 * kRadPerDeg, 0.0, 45.0 * kRadPerDeg, 0.0;
  return q;
}

// Position, velocity, acceleration at time t in [0, duration] of a rest-to-rest move of
// `distance` with cosine ramps of `ramp_s` (<= duration / 2) and constant velocity between.
struct ProfilePoint {
  double q = 0.0, qd = 0.0, qdd = 0.0;
};

inline ProfilePoint cosine_trapezoid(double distance, double duration, double ramp_s, double t) {
  const double v = distance / (duration - ramp_s);  // cruise velocity
  auto up = [&](double tau) {                       // ramp from rest, tau in [0, ramp_s]
    const double w = M_PI / ramp_s;
    return ProfilePoint{v * (0.5 * tau - std::sin(w * tau) / (2.0 * w)),
                        v * 0.5 * (1.0 - std::cos(w * tau)), v * 0.5 * w * std::sin(w * tau)};
  };
  t = std::clamp(t, 0.0, duration);
  if (t <= ramp_s) return up(t);
  if (t >= duration - ramp_s) {
    const ProfilePoint mirrored = up(duration - t);
    return {distance - mirrored.q, mirrored.qd, -mirrored.qdd};
  }
  const ProfilePoint end_of_ramp = up(ramp_s);
  return {end_of_ramp.q + v * (t - ramp_s), v, 0.0};
}

struct Move {
  calib::JointVector target_rad;
  double duration_s = 1.0;
  double ramp_s = 0.3;
  double rest_after_s = 0.5;
  int payload_index = 0;  // payload carried during the rest after the move
};

// A path from `start` (held for rest_before_s) through the moves; cycle 2 ms.
inline DesiredJointPath build_path(const calib::JointVector& start, double rest_before_s,
                                   const std::vector<Move>& moves, int first_payload_index = 0,
                                   double cycle_s = 0.002) {
  DesiredJointPath path;
  path.cycle_s = cycle_s;
  path.payloads.push_back(Payload{"none", calib::RigidBodyParameters{}});
  struct Piece {
    double begin_s, duration_s, ramp_s;
    calib::JointVector from, to;
    int payload;
  };
  std::vector<Piece> pieces;
  double t = 0.0;
  calib::JointVector at = start;
  int payload = first_payload_index;
  pieces.push_back({t, rest_before_s, 0.0, at, at, payload});
  t += rest_before_s;
  for (const Move& move : moves) {
    pieces.push_back({t, move.duration_s, move.ramp_s, at, move.target_rad, payload});
    t += move.duration_s;
    at = move.target_rad;
    payload = move.payload_index;
    pieces.push_back({t, move.rest_after_s, 0.0, at, at, payload});
    t += move.rest_after_s;
  }
  const long count = std::lround(t / cycle_s) + 1;
  for (long k = 0; k < count; ++k) {
    DesiredJointSample sample;
    sample.t_s = static_cast<double>(k) * cycle_s;
    const Piece* piece = &pieces.back();
    for (const Piece& p : pieces) {
      if (sample.t_s < p.begin_s + p.duration_s - 1e-9) {
        piece = &p;
        break;
      }
    }
    sample.payload_index = piece->payload;
    for (int i = 0; i < calib::kJointCount; ++i) {
      const double distance = piece->to(i) - piece->from(i);
      if (piece->ramp_s <= 0.0 || distance == 0.0) {
        sample.q_rad(i) = piece->to(i);
        continue;
      }
      const ProfilePoint p =
          cosine_trapezoid(distance, piece->duration_s, piece->ramp_s, sample.t_s - piece->begin_s);
      sample.q_rad(i) = piece->from(i) + p.q;
      sample.qd_rad_s(i) = p.qd;
      sample.qdd_rad_s2(i) = p.qdd;
    }
    path.samples.push_back(sample);
  }
  path.segments.push_back(
      PathSegment{SegmentKind::kPtp, "test path", 0.0, path.samples.back().t_s});
  return path;
}

inline bool sanitized() {
  return std::getenv("IMSCAL_SANITIZED") != nullptr;
}

}  // namespace imscal::sim::test
