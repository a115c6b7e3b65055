#pragma once
// The report's table of the drive structure the identified models imply (compliance, stiffness,
// direction offset and friction level, transmission error) with 1σ beside the values the
// identification config gave (identification_report.json, ident/identified_structure.hpp), and
// the model torque's link masses refined from the data and the drives' friction levels beside the
// robot file's.
#include <string>

#include "ident/identification_report.hpp"

namespace imscal::tools {

// The HTML table, or an empty string when the report holds no structure.
std::string structure_table_html(const ident::IdentificationReport& report);

// The table of the friction levels estimated from the data beside the robot file's, or an empty
// string without them.
std::string friction_levels_html(const std::vector<ident::ReportedFrictionLevels>& levels);

// The table of the model torque's refined links, or an empty string without them.
std::string model_torque_links_html(const std::vector<ident::LinkMassParameters>& links);

}  // namespace imscal::tools
