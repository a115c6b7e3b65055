#pragma once
// Whether a record holds the rests the IMS chain needs, in words for the user. The chain needs:
//   - a first rest of at least kFirstRestNeeded_s: the smoother starts there (alignment, biases);
//   - at least two rests the bundle can use: one rest sees only its tilt, so the gear deflection
//     it corrects for cannot be split over the pitch joints (A2, A3, A5 on an elbow arm); the
//     deflection scales keep their prior there, and every later joint error carries the first
//     rest's error (a tenth of the gear wind-up: ~2e-4 rad on A3 of a KR 16 with 16 kg);
//   - for a standstill to count as such a rest, the IMS must be still for min_duration_s, which
//     begins only once the gears have stopped ringing (3-3.5 s after a stop on the KR 16: on the
//     wide harness's ISO set, standstills of 3 s gave 0.5 s of IMS stillness, of 5 s about 2 s): a
//     commanded standstill of min_duration_s + kRingDown_s or longer.
// The commanded standstills are the robot log's spans of constant q_desired.
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "calib/rest_poses.hpp"
#include "robot/robot_log.hpp"

namespace imscal::calib {

inline constexpr double kFirstRestNeeded_s = 10.0;
inline constexpr double kRingDown_s = 3.5;

// Spans [begin, end) of the log [robot clock, s] where no joint's q_desired changes, at least
// min_s long.
std::vector<std::pair<double, double>> commanded_standstills(const RobotLog& log, double min_s);

// The warning when the record lacks those rests (none when it has them): the rests found and
// used with their durations, the commanded standstills, and the lengths needed.
std::optional<std::string> rest_shortage(const RestPoseResult& rests, const RobotLog& log,
                                         const RestPoseOptions& options);

}  // namespace imscal::calib
