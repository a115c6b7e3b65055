#include "core/joint_limit_plausibility.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <stdexcept>

#include "core/input_error.hpp"

namespace imscal {
namespace {

// How far `q_rad` lies beyond the limits (<= 0: within), and which limit.
double excess_rad(double q_rad, const JointLimit& limit, bool& upper) {
  upper = q_rad - limit.upper_rad > limit.lower_rad - q_rad;
  return upper ? q_rad - limit.upper_rad : limit.lower_rad - q_rad;
}

std::string describe(const JointAngleColumn& column, std::size_t k, const JointLimit& limit,
                     const JointAngleSource& source) {
  bool upper = false;
  const double q_rad = column.q_rad[k], excess = excess_rad(q_rad, limit, upper);
  return fmt::format(
      "{:.6g} rad ({:.4g} deg) is {:.3g} deg beyond joint {}'s {} limit of {:.4g} "
      "deg ({})",
      q_rad, q_rad * kDegPerRad, excess * kDegPerRad, limit.joint, upper ? "upper" : "lower",
      (upper ? limit.upper_rad : limit.lower_rad) * kDegPerRad, source.limits_of);
}

}  // namespace

std::size_t check_joint_limits(std::span<const JointAngleColumn> columns,
                               std::span<const JointLimit> limits, const JointAngleSource& source) {
  std::size_t beyond_total = 0;
  for (const JointAngleColumn& column : columns) {
    if (column.joint >= limits.size())
      throw std::invalid_argument("check_joint_limits: no limit for column " + column.field);
    const JointLimit& limit = limits[column.joint];
    std::size_t worst = 0, beyond = 0;
    double worst_excess = 0.0;
    for (std::size_t k = 0; k < column.q_rad.size(); ++k) {
      bool upper = false;
      const double excess = excess_rad(column.q_rad[k], limit, upper);
      if (!(excess > 0.0)) continue;
      ++beyond;
      if (excess > worst_excess) {
        worst_excess = excess;
        worst = k;
      }
    }
    if (beyond == 0) continue;
    beyond_total += beyond;
    const std::size_t line = source.line_of ? source.line_of(worst) : 0;
    if (worst_excess > kJointLimitRefuseMargin_rad)
      throw InputError(source.file, line, column.field,
                       fmt::format("{}: more than {} deg beyond, no angle this arm reaches; is the "
                                   "column in another unit, or the log of another robot?",
                                   describe(column, worst, limit, source),
                                   kJointLimitRefuseMargin_rad * kDegPerRad));
    spdlog::warn("{}{}: field '{}': {}, the worst of {} samples beyond the limit", source.file,
                 line > 0 ? fmt::format(":{}", line) : "", column.field,
                 describe(column, worst, limit, source), beyond);
  }
  return beyond_total;
}

}  // namespace imscal
