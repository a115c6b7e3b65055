#pragma once
// An identification config meets the record it identifies. A config holds counts of cycles
// (the preview, the further inputs' taps, the rows a cell needs) that mean other durations at
// another controller rate (20 preview cycles are 40 ms at 2 ms, 200 ms at 10 ms), and maximum
// speeds, gear data and a payload rating of one robot. Durations stated in seconds
// (ConfigDurations) are turned into counts of the record's cycle here; a config that names its
// robot or the cycle of its counts is checked against the record, so that a KR 16 config is not
// applied to a UR10e log, nor 2 ms counts to 10 ms data, without a word.
#include <string>
#include <vector>

#include "ident/identification_config.hpp"

namespace imscal::ident {

// The counts the config's durations give at cycle_s (rounded to whole cycles), into its options.
// InputError naming the config file, line and key when a count falls outside what the
// identification and the precontrol take (preview 0..32 cycles, taps 1..64 and with the largest
// dead time at most 64, at least 1 row). warnings: a duration that is not a whole number of
// cycles by more than 1 %.
void apply_durations(IdentificationConfig& config, double cycle_s,
                     std::vector<std::string>* warnings = nullptr);

// The config for a record of `record_robot` sampled every record_cycle_s [s] (record_file names
// it in messages): InputError (config file, line, key) when the config names another robot, or
// states its counts in another cycle; its durations turned into counts of the record's cycle.
// warnings: counts taken in the record's cycle where the config does not say which cycle they
// are in and the record's is not 2 ms; durations rounded to whole cycles.
IdentificationConfig resolve_for_record(IdentificationConfig config,
                                        const std::string& record_robot, double record_cycle_s,
                                        const std::string& record_file,
                                        std::vector<std::string>* warnings = nullptr);

}  // namespace imscal::ident
