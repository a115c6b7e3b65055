#pragma once
// A payload against the robot's rated payload, in every command that takes one (a config's mass,
// a log's payload column, a motion program's payload). Above the rating the robot, its drives and
// the tables identified for it are used outside what they are made for: a warning. Above
// kPayloadRefuseFactor times the rating it is a wrong unit or column, not a load the robot can
// lift (5000 kg on a 16 kg robot took the precontrol's gain on the test path to -26 %): refused.
// A robot that states no rating (0) is not checked.
#include <cstddef>
#include <span>
#include <string>

namespace imscal {

inline constexpr double kPayloadRefuseFactor = 1.5;

struct PayloadSource {
  std::string file;       // where the payload was given
  std::size_t line = 0;   // 1-based, 0: not known
  std::string field;      // "payload.mass_kg", "payload_kg"
  std::string rating_of;  // whose rating it is checked against: "robot kr16 (kr16.yaml)"
};

// InputError (file, line, field, both masses, the reason) above kPayloadRefuseFactor x rated_kg;
// a warning with the same words above rated_kg. Returns true when within the rating.
bool check_payload_plausible(double payload_kg, double rated_kg, const PayloadSource& source,
                             const std::string& where = "");

// The same for a payload column: its largest value, named with its time stamp.
bool check_payload_series(std::span<const double> payload_kg, std::span<const double> t_s,
                          double rated_kg, const PayloadSource& source);

}  // namespace imscal
