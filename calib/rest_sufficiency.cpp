#include "calib/rest_sufficiency.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

namespace imscal::calib {

std::vector<std::pair<double, double>> commanded_standstills(const RobotLog& log, double min_s) {
  std::vector<std::pair<double, double>> out;
  const auto& s = log.samples;
  std::size_t begin = 0;
  for (std::size_t k = 1; k <= s.size(); ++k) {
    // A change of q_desired above 1e-12 rad (rounding of a logged constant) ends a standstill.
    const bool ends = k == s.size() ||
                      (s[k].q_desired_rad - s[k - 1].q_desired_rad).cwiseAbs().maxCoeff() > 1e-12;
    if (!ends) continue;
    if (k - 1 > begin && s[k - 1].t_s - s[begin].t_s >= min_s)
      out.emplace_back(s[begin].t_s, s[k - 1].t_s);
    begin = k;
  }
  return out;
}

std::optional<std::string> rest_shortage(const RestPoseResult& rests, const RobotLog& log,
                                         const RestPoseOptions& options) {
  std::vector<std::string> used, commanded;
  for (const RestObservation& r : rests.rests)
    used.push_back(fmt::format("{:.1f}", r.end_ims_s - r.begin_ims_s));
  const auto standstills = commanded_standstills(log, 0.5);
  for (const auto& [b, e] : standstills) commanded.push_back(fmt::format("{:.1f}", e - b));
  const double first_s =
      standstills.empty() ? 0.0 : standstills.front().second - standstills.front().first;
  // 5 % below the length needed still counts (a log that starts a little into the rest).
  const bool short_first = first_s < 0.95 * kFirstRestNeeded_s;
  if (rests.rests.size() >= 2 && !short_first) return std::nullopt;
  const double between_s = options.min_duration_s + kRingDown_s;
  return fmt::format(
      "the record lacks the rests the IMS chain needs: {} rest{} used ({} s after trimming {} s at "
      "both ends; {} standstill{} of the IMS not used), the robot log's commanded standstills "
      "last [{}] s. Needed: a first rest of at least {:.0f} s{} and at least 2 usable rests, each "
      "a commanded standstill of at least {:.1f} s (the IMS still for {:.1f} s once the gears "
      "stop ringing, ~{:.1f} s after a stop). With one rest the gear deflection of that pose "
      "cannot be split over the joints, and every joint error carries its error (about a tenth "
      "of the gear wind-up, ~2e-4 rad); the joint errors' diagnosis counts it as the "
      "measurement's own (diagnose --frames)",
      rests.rests.size(), rests.rests.size() == 1 ? "" : "s",
      used.empty() ? "none" : fmt::format("{}", fmt::join(used, ", ")), options.edge_trim_s,
      rests.rejected.size(), rests.rejected.size() == 1 ? "" : "s", fmt::join(commanded, ", "),
      kFirstRestNeeded_s, short_first ? fmt::format(" (here {:.1f} s)", first_s) : "", between_s,
      options.min_duration_s, kRingDown_s);
}

}  // namespace imscal::calib
