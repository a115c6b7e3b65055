#pragma once
// identification_report.json's "friction_levels" (datasets/FORMAT.md): per joint the friction
// levels and reflected inertia estimated from the motor encoders (ident/friction_levels.hpp) with
// 1σ beside the nominal robot's values; written and read here.
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/json_fields.hpp"
#include "ident/friction_levels.hpp"

namespace imscal::ident {

struct ReportedFrictionLevels {
  std::string name;  // joint
  JointFrictionLevels levels;
};

// The document's value (value and sigma null where a joint was not estimated).
nlohmann::json friction_levels_json(const std::vector<JointFrictionLevels>& levels,
                                    const std::vector<std::string>& joint_names);

// Reads the value written above; InputError naming the file and the field's path otherwise.
std::vector<ReportedFrictionLevels> friction_levels_of(const JsonField& field);

}  // namespace imscal::ident
