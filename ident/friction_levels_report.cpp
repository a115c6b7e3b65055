#include "ident/friction_levels_report.hpp"

#include "core/json_output.hpp"

namespace imscal::ident {
namespace {

nlohmann::json level_json(const FrictionLevel& level, bool estimated) {
  return {{"value", estimated ? json_number_or_null(level.value) : nlohmann::json()},
          {"sigma", estimated ? json_number_or_null(level.sigma) : nlohmann::json()},
          {"nominal", json_number_or_null(level.nominal)}};
}

FrictionLevel level_of(const JsonField& f) {
  return {f["value"].number_or_nan(), f["sigma"].number_or_nan(), f["nominal"].number_or_nan()};
}

}  // namespace

nlohmann::json friction_levels_json(const std::vector<JointFrictionLevels>& levels,
                                    const std::vector<std::string>& joint_names) {
  nlohmann::json joints = nlohmann::json::array();
  for (std::size_t j = 0; j < levels.size(); ++j) {
    const JointFrictionLevels& l = levels[j];
    nlohmann::json joint = {{"name", joint_names.at(j)}, {"estimated", l.estimated}};
    joint["not_estimated"] = l.estimated ? nlohmann::json() : nlohmann::json(l.not_estimated);
    joint["coulomb_nm"] = level_json(l.coulomb_nm, l.estimated);
    joint["viscous_nm_s_per_rad"] = level_json(l.viscous_nm_s_per_rad, l.estimated);
    joint["reflected_inertia_kg_m2"] = level_json(l.reflected_inertia_kg_m2, l.estimated);
    joint["rows"] = l.rows;
    joint["dead_time_cycles"] = l.dead_time_cycles;
    joint["model_torque_rms_nm"] = json_number_or_null(l.torque_rms_nm);
    joint["balance_fit_percent"] = json_number_or_null(l.torque_fit_percent);
    joint["correlation_factor"] = json_number_or_null(l.correlation_factor);
    joints.push_back(std::move(joint));
  }
  return {{"source", "motor encoders' following error (q_desired - q_internal)"},
          {"joints", std::move(joints)}};
}

std::vector<ReportedFrictionLevels> friction_levels_of(const JsonField& field) {
  std::vector<ReportedFrictionLevels> out;
  const JsonField joints = field["joints"];
  for (std::size_t j = 0; j < joints.size(); ++j) {
    const JsonField f = joints[j];
    ReportedFrictionLevels r;
    r.name = f["name"].text();
    r.levels.estimated = f["estimated"].boolean();
    if (const auto why = f.optional("not_estimated")) r.levels.not_estimated = why->text();
    r.levels.coulomb_nm = level_of(f["coulomb_nm"]);
    r.levels.viscous_nm_s_per_rad = level_of(f["viscous_nm_s_per_rad"]);
    r.levels.reflected_inertia_kg_m2 = level_of(f["reflected_inertia_kg_m2"]);
    r.levels.rows = f["rows"].count();
    r.levels.dead_time_cycles = int(f["dead_time_cycles"].count());
    r.levels.torque_rms_nm = f["model_torque_rms_nm"].number_or_nan();
    r.levels.torque_fit_percent = f["balance_fit_percent"].number_or_nan();
    r.levels.correlation_factor = f["correlation_factor"].number_or_nan();
    out.push_back(std::move(r));
  }
  return out;
}

}  // namespace imscal::ident
