#pragma once
// Joint angles read from a file (a robot log's desired and internal angles, a joint_errors.csv, a
// tracker pose's joints) against the robot's joint limits. The controller stops the arm at its
// software limits, so an angle beyond one is not a pose the arm took: within
// kJointLimitRefuseMargin_rad of the limit (limits in a robot file a little tighter than the
// controller's) a warning; further out a wrong unit (degrees in a `_rad` column), the log of
// another robot or a corrupted sample: refused. Each warning or refusal names the file, the line
// of the worst sample, the column, the value and the limit.
#include <cstddef>
#include <functional>
#include <span>
#include <string>

#include "core/units.hpp"

namespace imscal {

// 5 deg: wider than the distance of a robot file's data-sheet limits from the controller's
// software limit switches, far narrower than a unit mistake (1 rad read as 1 deg or 57 deg).
inline constexpr double kJointLimitRefuseMargin_rad = 5.0 * kRadPerDeg;

struct JointLimit {
  std::string joint;  // "A1"
  double lower_rad = 0.0, upper_rad = 0.0;
};

struct JointAngleColumn {
  std::string field;  // the column's name: "q_desired_A1_rad"
  std::size_t joint;  // index into the limits
  std::span<const double> q_rad;
};

struct JointAngleSource {
  std::string file;
  std::function<std::size_t(std::size_t)> line_of;  // sample index -> 1-based line (0: unknown)
  std::string limits_of;                            // "robot kr16 (kr16.yaml)"
};

// InputError for a column whose worst sample lies more than kJointLimitRefuseMargin_rad beyond a
// limit; one warning per column with samples beyond a limit. Returns how many samples (over all
// columns) lie beyond a limit.
std::size_t check_joint_limits(std::span<const JointAngleColumn> columns,
                               std::span<const JointLimit> limits, const JointAngleSource& source);

}  // namespace imscal
