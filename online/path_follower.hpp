#pragma once
// The robot program's desired path, loaded before the run and followed by the controller's IPOC:
// what a table with a preview (the precontrol fed q_d P model cycles ahead) and with the model
// torque needs, where the interface sends only the current set-point (docs/decisions/0024).
//
// Synchronisation: the path starts at rest at its first sample. Its clock starts either
//  - at the motion (default): while the controller's set-point stands at that pose (within
//    rest_tolerance_rad on every joint) the follower waits and feeds the first sample; when the
//    set-point leaves it, the path's time is set to its first moving sample; or
//  - with the stream (clock_from_first_datagram): the path's sample 0 is the first datagram's
//    cycle, for a path recorded from the moment the controller starts sending (RSI_ON); then the
//    preview sees the first motion coming, which at the motion it cannot;
// and advances with the IPOC from then on (rsi_cycle_s per cycle, lost cycles counted). Every
// set-point is checked against the path at its time: farther than track_tolerance_rad on a joint
// and the follower is lost (a fault for the caller) until the set-point stands at the path's
// first pose again. After the path's end its last sample is held; standing at the first pose
// again re-arms it (a program run again).
//
// Limits: the program's timing must be the path's (same override, no waits on inputs that the
// recording did not have); with the clock started at the motion the first preview of a motion
// from the start pose is missed, since when the robot will leave it is known only once it does
// (the precontrol's input steps from the rest pose to the path P cycles ahead: on seed-line's
// line, which starts from rest, the reduction fell from 96.9 to 92.5 %).
//
// No allocation in step(); the path is held in vectors filled at construction.
#include <array>
#include <cstdint>
#include <vector>

namespace imscal::online {

inline constexpr int kPathJoints = 6;

struct LoadedPath {
  double cycle_s = 0.002;                                  // sample spacing [s]
  std::vector<std::array<double, kPathJoints>> q_rad;      // desired joints
  std::vector<std::array<double, kPathJoints>> torque_nm;  // model torque along it (or empty)
  std::vector<double> payload_kg;                          // per sample (or empty: 0)
};

// n when x_s is n whole samples of spacing_s (within 1e-6 of a sample), else -1: a controller
// cycle or a preview that the path's samples must divide.
long whole_samples(double x_s, double spacing_s);

struct PathFollowerOptions {
  double rest_tolerance_rad = 1e-4;        // "at the start pose"
  double track_tolerance_rad = 0.02;       // a set-point farther from the path is off it
  bool clock_from_first_datagram = false;  // see above
};

enum class PathFollowerState : std::uint8_t { kWaiting, kFollowing, kLost };

struct PathSample {
  std::array<double, kPathJoints> q_rad{};
  std::array<double, kPathJoints> torque_nm{};
  double payload_kg = 0.0;
};

class PathFollower {
 public:
  // Throws std::invalid_argument for an empty path, a cycle that is not a whole number of path
  // samples, or a preview that is not.
  PathFollower(LoadedPath path, double rsi_cycle_s, double preview_s,
               const PathFollowerOptions& options = {});

  // One in-order datagram: its set-point and the cycles since the previous one (1 normally).
  // Writes the sample the precontrol is fed (preview_s ahead of the set-point's time); returns
  // false when the set-point is off the path (the caller fades out).
  bool step(const std::array<double, kPathJoints>& setpoint_rad, std::uint64_t cycles_advanced,
            PathSample* ahead) noexcept;

  PathFollowerState state() const noexcept { return state_; }
  // The path sample of the set-point's time (valid while following).
  std::size_t index() const noexcept { return index_; }

 private:
  bool near(const std::array<double, kPathJoints>& q, std::size_t i, double tolerance) const;
  void fill(std::size_t i, PathSample* out) const noexcept;

  LoadedPath path_;
  PathFollowerOptions options_;
  std::size_t samples_per_cycle_ = 1;
  std::size_t preview_samples_ = 0;
  std::size_t first_moving_ = 0;  // first sample away from the start pose
  PathFollowerState state_ = PathFollowerState::kWaiting;
  std::size_t index_ = 0;
  bool stream_started_ = false;
};

}  // namespace imscal::online
