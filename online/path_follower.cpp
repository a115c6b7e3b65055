#include "online/path_follower.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace imscal::online {
long whole_samples(double x_s, double spacing_s) {
  const double n = x_s / spacing_s;
  return std::abs(n - std::round(n)) < 1e-6 && n >= 0.0 ? std::lround(n) : -1;
}

PathFollower::PathFollower(LoadedPath path, double rsi_cycle_s, double preview_s,
                           const PathFollowerOptions& options)
    : path_(std::move(path)), options_(options) {
  if (path_.q_rad.empty()) throw std::invalid_argument("the loaded path has no samples");
  if (!path_.torque_nm.empty() && path_.torque_nm.size() != path_.q_rad.size())
    throw std::invalid_argument("the loaded path's torques are not one per sample");
  if (!path_.payload_kg.empty() && path_.payload_kg.size() != path_.q_rad.size())
    throw std::invalid_argument("the loaded path's payloads are not one per sample");
  const long per_cycle = whole_samples(rsi_cycle_s, path_.cycle_s);
  const long preview = whole_samples(preview_s, path_.cycle_s);
  if (per_cycle < 1 || preview < 0)
    throw std::invalid_argument(
        "the controller's cycle and the table's preview must be whole "
        "numbers of the path's sample spacing");
  samples_per_cycle_ = std::size_t(per_cycle);
  preview_samples_ = std::size_t(preview);
  first_moving_ = path_.q_rad.size() - 1;
  for (std::size_t i = 0; i < path_.q_rad.size(); ++i) {
    if (!near(path_.q_rad[i], 0, options_.rest_tolerance_rad)) {
      first_moving_ = i;
      break;
    }
  }
}

bool PathFollower::near(const std::array<double, kPathJoints>& q, std::size_t i,
                        double tolerance) const {
  for (int j = 0; j < kPathJoints; ++j)
    if (!(std::abs(q[std::size_t(j)] - path_.q_rad[i][std::size_t(j)]) <= tolerance)) return false;
  return true;
}

void PathFollower::fill(std::size_t i, PathSample* out) const noexcept {
  const std::size_t k = std::min(i, path_.q_rad.size() - 1);
  out->q_rad = path_.q_rad[k];
  if (!path_.torque_nm.empty()) out->torque_nm = path_.torque_nm[k];
  out->payload_kg = path_.payload_kg.empty() ? 0.0 : path_.payload_kg[k];
}

bool PathFollower::step(const std::array<double, kPathJoints>& setpoint_rad,
                        std::uint64_t cycles_advanced, PathSample* ahead) noexcept {
  const bool at_start = near(setpoint_rad, 0, options_.rest_tolerance_rad);
  const bool finished = index_ + 1 >= path_.q_rad.size();
  const bool first_datagram = !stream_started_;
  stream_started_ = true;
  if (first_datagram && options_.clock_from_first_datagram && at_start) {
    state_ = PathFollowerState::kFollowing;  // the path's clock starts with the stream
    index_ = 0;
    fill(preview_samples_, ahead);
    return true;
  }
  if (at_start && (state_ != PathFollowerState::kFollowing || finished)) {
    state_ = PathFollowerState::kWaiting;
    index_ = 0;
    fill(0, ahead);
    return true;
  }
  if (state_ == PathFollowerState::kLost) return false;
  if (state_ == PathFollowerState::kWaiting) {
    state_ = PathFollowerState::kFollowing;
    index_ = first_moving_;
  } else {
    const std::uint64_t advance = std::min<std::uint64_t>(cycles_advanced, path_.q_rad.size());
    index_ = std::min(path_.q_rad.size() - 1, index_ + std::size_t(advance) * samples_per_cycle_);
  }
  if (!near(setpoint_rad, index_, options_.track_tolerance_rad)) {
    state_ = PathFollowerState::kLost;
    return false;
  }
  fill(index_ + preview_samples_, ahead);
  return true;
}

}  // namespace imscal::online
