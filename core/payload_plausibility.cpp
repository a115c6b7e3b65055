#include "core/payload_plausibility.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>

#include "core/input_error.hpp"

namespace imscal {

bool check_payload_plausible(double payload_kg, double rated_kg, const PayloadSource& source,
                             const std::string& where) {
  if (!(rated_kg > 0.0) || payload_kg <= rated_kg) return true;
  const std::string what =
      fmt::format("payload {} kg{} is above the rated payload of {} kg of {}", payload_kg,
                  where.empty() ? "" : " " + where, rated_kg, source.rating_of);
  if (payload_kg > kPayloadRefuseFactor * rated_kg)
    throw InputError(source.file, source.line, source.field,
                     fmt::format("{}, more than {} x: no load this robot can carry; is it in "
                                 "another unit (g, lb) or another column?",
                                 what, kPayloadRefuseFactor));
  spdlog::warn(
      "{}{}: field '{}': {}: the robot and the tables identified for it are used "
      "outside their rating",
      source.file, source.line > 0 ? fmt::format(":{}", source.line) : "", source.field, what);
  return false;
}

bool check_payload_series(std::span<const double> payload_kg, std::span<const double> t_s,
                          double rated_kg, const PayloadSource& source) {
  if (payload_kg.empty()) return true;
  const auto largest = std::max_element(payload_kg.begin(), payload_kg.end());
  const auto k = std::size_t(largest - payload_kg.begin());
  return check_payload_plausible(
      *largest, rated_kg, source,
      k < t_s.size() ? fmt::format("at t = {} s", t_s[k]) : std::string());
}

}  // namespace imscal
