#include "ident/identification_report.hpp"

#include <fmt/format.h>

#include <cmath>

#include "core/json_fields.hpp"
#include "core/json_output.hpp"

namespace imscal::ident {
namespace {

using nlohmann::json;

constexpr const char* kVersionKey = "imscal-identification-report";

json correlation_json(const CorrelationTest& t) {
  json c = json::array();
  for (double v : t.correlation) c.push_back(v);
  return {{"lags", t.lags},
          {"correlation", c},
          {"band", t.band},
          {"family_band", t.family_band},
          {"max_abs_correlation", t.max_abs_correlation},
          {"outside_count", t.outside_count},
          {"allowed_outside", t.allowed_outside},
          {"passed", t.passed}};
}

// Criterion curves through the chosen structure: over na (chosen nb, d), over nb (chosen na, d)
// and over d (chosen na, nb) — the whole grid would be thousands of points per cell.
json curves_json(const OrderSweepResult& sweep) {
  json curves = {{"over_na", json::array()}, {"over_nb", json::array()}, {"over_d", json::array()}};
  const auto& c = sweep.chosen;
  for (const auto& cand : sweep.candidates) {
    const auto& s = cand.structure;
    const json point = {{"na", s.na},
                        {"nb", s.nb},
                        {"dead_time", s.dead_time},
                        {"valid", cand.valid},
                        {"loss", json_number_or_null(cand.loss)},
                        {"aic", json_number_or_null(cand.aic)},
                        {"bic", json_number_or_null(cand.bic)},
                        {"validation_loss", json_number_or_null(cand.validation_loss)}};
    if (s.nb == c.nb && s.dead_time == c.dead_time) curves["over_na"].push_back(point);
    if (s.na == c.na && s.dead_time == c.dead_time) curves["over_nb"].push_back(point);
    if (s.na == c.na && s.nb == c.nb) curves["over_d"].push_back(point);
  }
  return curves;
}

json fit_json(const ArxFitResult& fit) {
  return {
      {"rows", fit.row_count},
      {"residual_variance_rad2", fit.residual_variance},
      {"scaled_condition", fit.scaled_condition},
      {"method", to_string(fit.method_used)},
      {"refinement_steps", fit.refinement_steps},
      {"parameter_std", std::vector<double>(fit.parameter_std.data(),
                                            fit.parameter_std.data() + fit.parameter_std.size())}};
}

json cell_json(const CellIdentification& c, const CellFitFigures& figures) {
  json cell = {{"cell", c.cell},
               {"label", c.label},
               {"status", to_string(c.status)},
               {"estimation_rows", c.estimation_rows},
               {"validation_rows", c.validation_rows},
               {"rms_desired_speed_rad_s", c.rms_speed_rad_s}};
  if (c.status == CellStatus::kFilled) {
    cell["filled_from"] = c.filled_from;
    cell["reason"] = c.reason;
  }
  if (c.sweep) {
    cell["criterion"] = to_string(c.sweep->criterion);
    cell["chosen"] = {{"na", c.sweep->chosen.na},
                      {"nb", c.sweep->chosen.nb},
                      {"dead_time", c.sweep->chosen.dead_time}};
    cell["criterion_curves"] = curves_json(*c.sweep);
  }
  if (c.fit) cell["fit"] = fit_json(*c.fit);
  if (c.stability) {
    cell["stability"] = {{"stable", c.stability->stable},
                         {"spectral_radius", c.stability->spectral_radius},
                         {"margin", c.stability->margin},
                         {"reason", c.stability->reason}};
  }
  if (c.validation) {
    const auto& v = *c.validation;
    cell["validation"] = {
        {"samples", v.sample_count},
        {"one_step_fit_percent", v.one_step_fit_percent},
        {"simulation_fit_percent", v.simulation_fit_percent},
        {"joint_error_fit_percent", json_number_or_null(figures.joint_error_fit_percent)},
        {"residual_rms_rad", v.residual_rms},
        {"residual_whiteness", correlation_json(v.residual_whiteness)},
        {"input_residual", correlation_json(v.input_residual)}};
  }
  return cell;
}

json estimate_json(const StructureEstimate& e) {
  return {{"value", json_number_or_null(e.value)}, {"sigma", json_number_or_null(e.sigma)}};
}

json structure_json(const IdentifiedStructure& s) {
  return {
      {"cells", s.cells},
      {"compliance_rad_per_nm", estimate_json(s.compliance_rad_per_nm)},
      {"nominal_compliance_rad_per_nm", json_number_or_null(s.nominal_compliance_rad_per_nm)},
      {"stiffness_nm_per_rad", estimate_json(s.stiffness_nm_per_rad)},
      {"direction_offset_rad", estimate_json(s.direction_offset_rad)},
      {"transmission_error_harmonic_per_motor_rev",
       json_number_or_null(s.transmission_error_harmonic_per_motor_rev)},
      {"transmission_error_amplitude_rad", estimate_json(s.transmission_error_amplitude_rad)},
      {"transmission_error_phase_rad", estimate_json(s.transmission_error_phase_rad)},
      {"transmission_error_joint_speed_rad_s",
       json_number_or_null(s.transmission_error_joint_speed_rad_s)},
      {"transmission_error_frequency_hz", json_number_or_null(s.transmission_error_frequency_hz)}};
}

json joint_json(const JointIdentification& r, double seconds, const IdentifiedStructure& s) {
  const auto& b = r.backlash;
  json cells = json::array();
  for (const auto& c : r.cells)
    cells.push_back(cell_json(c, r.parameters.cells.at(std::size_t(c.cell)).figures));
  return {
      {"joint", r.parameters.name},
      {"seconds", seconds},
      {"table_joint_error_fit_percent", json_number_or_null(r.table_fit.joint_error_fit_percent)},
      {"table_validation_rows", r.table_fit.rows},
      {"backlash",
       {{"identified", r.parameters.backlash_identified},
        {"l_rad", b.l_rad},
        {"l_sigma_rad", b.l_sigma_rad},
        {"full_play_rad", 2.0 * r.parameters.backlash_l_rad},
        {"reversals_found", b.reversals_found},
        {"reversals_used", b.reversals_used},
        {"lag_samples", b.lag_samples},
        {"per_reversal_l_rad", b.per_reversal_rad},
        {"reason", b.reason}}},
      {"structure", structure_json(s)},
      {"cells", cells}};
}

json order_tracking_json(const OrderSearchJoint& j) {
  json orders = json::array();
  for (const TrackedOrder& o : j.tracked_orders)
    orders.push_back({{"order_per_motor_rev", o.order_per_motor_rev},
                      {"amplitude_rad", o.amplitude_rad},
                      {"floor_rad", o.floor_rad},
                      {"significance_sigma", o.significance_sigma},
                      {"t_statistic", o.t_statistic}});
  return {{"windows", j.tracking_windows}, {"significant_orders", orders}};
}

json order_search_json(const OrderSearchReport& search) {
  json joints = json::array();
  for (const OrderSearchJoint& j : search.joints) {
    json fits = json::array();
    for (double fit : j.held_out_joint_error_fit_percent) fits.push_back(json_number_or_null(fit));
    joints.push_back(
        {{"name", j.name},
         {"config_harmonic_per_motor_rev", j.config_harmonic_per_motor_rev},
         {"best_harmonic_per_motor_rev", j.best_harmonic_per_motor_rev},
         {"gain_points", json_number_or_null(j.gain_points)},
         {"chosen_harmonic_per_motor_rev", j.chosen_harmonic_per_motor_rev},
         {"held_out_joint_error_fit_percent", fits},
         {"second_harmonic_per_motor_rev", json_number_or_null(j.second_harmonic_per_motor_rev)},
         {"second_bic", json_number_or_null(j.second_bic)}});
    if (j.tracking_windows > 0) joints.back()["order_tracking"] = order_tracking_json(j);
  }
  return {{"candidates_per_motor_rev", search.candidates_per_motor_rev}, {"joints", joints}};
}

CellStatus status_of(const JsonField& field) {
  const std::string text = field.text();
  for (const CellStatus s : {CellStatus::kIdentified, CellStatus::kFilled, CellStatus::kNeutral})
    if (text == to_string(s)) return s;
  field.refuse(fmt::format("'{}' is not a cell status (identified, filled, neutral)", text));
}

int int_of(const JsonField& field) {
  const long long v = field.integer();
  if (v < -1 || v > 1000000) field.refuse(fmt::format("{} is out of range", v));
  return static_cast<int>(v);
}

ReportedCell cell_of(const JsonField& f) {
  ReportedCell c;
  c.cell = int_of(f["cell"]);
  c.label = f["label"].text();
  c.status = status_of(f["status"]);
  c.estimation_rows = f["estimation_rows"].count();
  c.validation_rows = f["validation_rows"].count();
  c.rms_desired_speed_rad_s = f["rms_desired_speed_rad_s"].number_or_nan();
  if (c.status == CellStatus::kFilled) {
    c.filled_from = int_of(f["filled_from"]);
    c.reason = f["reason"].text();
  }
  if (const auto chosen = f.optional("chosen"))
    c.chosen = ReportedOrders{int_of((*chosen)["na"]), int_of((*chosen)["nb"]),
                              int_of((*chosen)["dead_time"])};
  if (const auto v = f.optional("validation")) {
    c.validation = ReportedValidation{
        (*v)["samples"].count(), (*v)["one_step_fit_percent"].number_or_nan(),
        (*v)["simulation_fit_percent"].number_or_nan(),
        (*v)["joint_error_fit_percent"].number_or_nan(), (*v)["residual_rms_rad"].number_or_nan()};
  }
  return c;
}

ReportedBacklash backlash_of(const JsonField& f) {
  ReportedBacklash b;
  b.identified = f["identified"].boolean();
  b.l_rad = f["l_rad"].number_or_nan();
  b.l_sigma_rad = f["l_sigma_rad"].number_or_nan();
  b.full_play_rad = f["full_play_rad"].number_or_nan();
  b.reversals_found = f["reversals_found"].count();
  b.reversals_used = f["reversals_used"].count();
  b.lag_samples = int_of(f["lag_samples"]);
  b.per_reversal_l_rad = f["per_reversal_l_rad"].numbers_or_nan();
  b.reason = f["reason"].text();
  return b;
}

StructureEstimate estimate_of(const JsonField& f) {
  return {f["value"].number_or_nan(), f["sigma"].number_or_nan()};
}

IdentifiedStructure structure_of(const JsonField& f) {
  IdentifiedStructure s;
  s.cells = f["cells"].count();
  s.compliance_rad_per_nm = estimate_of(f["compliance_rad_per_nm"]);
  s.nominal_compliance_rad_per_nm = f["nominal_compliance_rad_per_nm"].number_or_nan();
  s.stiffness_nm_per_rad = estimate_of(f["stiffness_nm_per_rad"]);
  s.direction_offset_rad = estimate_of(f["direction_offset_rad"]);
  s.transmission_error_harmonic_per_motor_rev =
      f["transmission_error_harmonic_per_motor_rev"].number_or_nan();
  s.transmission_error_amplitude_rad = estimate_of(f["transmission_error_amplitude_rad"]);
  s.transmission_error_phase_rad = estimate_of(f["transmission_error_phase_rad"]);
  // Reports without them gave the pair's static gains (no frequency): read as NaN.
  if (const auto speed = f.optional("transmission_error_joint_speed_rad_s"))
    s.transmission_error_joint_speed_rad_s = speed->number_or_nan();
  if (const auto frequency = f.optional("transmission_error_frequency_hz"))
    s.transmission_error_frequency_hz = frequency->number_or_nan();
  return s;
}

ReportedJoint joint_of(const JsonField& f) {
  ReportedJoint j;
  j.name = f["joint"].text();
  j.seconds = f["seconds"].number();
  j.table_joint_error_fit_percent = f["table_joint_error_fit_percent"].number_or_nan();
  j.table_validation_rows = f["table_validation_rows"].count();
  j.backlash = backlash_of(f["backlash"]);
  if (const auto structure = f.optional("structure")) j.structure = structure_of(*structure);
  const JsonField cells = f["cells"];
  for (std::size_t k = 0; k < cells.size(); ++k) j.cells.push_back(cell_of(cells[k]));
  return j;
}

void read_order_tracking(const JsonField& f, OrderSearchJoint& joint) {
  joint.tracking_windows = f["windows"].count();
  const JsonField orders = f["significant_orders"];
  for (std::size_t k = 0; k < orders.size(); ++k) {
    const JsonField o = orders[k];
    joint.tracked_orders.push_back({o["order_per_motor_rev"].number(), o["amplitude_rad"].number(),
                                    o["floor_rad"].number(), o["significance_sigma"].number(),
                                    o["t_statistic"].number()});
  }
}

OrderSearchReport order_search_of(const JsonField& f) {
  OrderSearchReport search;
  search.candidates_per_motor_rev = f["candidates_per_motor_rev"].numbers();
  const JsonField joints = f["joints"];
  for (std::size_t k = 0; k < joints.size(); ++k) {
    const JsonField j = joints[k];
    const JsonField fits = j["held_out_joint_error_fit_percent"];
    if (fits.size() != search.candidates_per_motor_rev.size())
      fits.refuse(fmt::format("{} figures for {} candidates", fits.size(),
                              search.candidates_per_motor_rev.size()));
    search.joints.push_back({j["name"].text(), j["config_harmonic_per_motor_rev"].number(),
                             j["best_harmonic_per_motor_rev"].number(),
                             j["gain_points"].number_or_nan(),
                             j["chosen_harmonic_per_motor_rev"].number(), fits.numbers_or_nan()});
    // Reports written before the second pass have neither key.
    if (const auto second = j.optional("second_harmonic_per_motor_rev"))
      search.joints.back().second_harmonic_per_motor_rev = second->number_or_nan();
    if (const auto bic = j.optional("second_bic"))
      search.joints.back().second_bic = bic->number_or_nan();
    if (const auto tracking = j.optional("order_tracking"))
      read_order_tracking(*tracking, search.joints.back());
  }
  return search;
}

std::array<double, 3> vector3_of(const JsonField& f) {
  const std::vector<double> v = f.numbers();
  if (v.size() != 3) f.refuse("expected 3 numbers");
  return {v[0], v[1], v[2]};
}

LinkMassParameters link_of(const JsonField& f) {
  LinkMassParameters l;
  l.refined = f["refined"].boolean();
  l.held_out_z = f["held_out_z"].number();
  l.nominal_mass_kg = f["nominal_mass_kg"].number();
  l.mass_kg = f["mass_kg"].number();
  l.mass_sigma_kg = f["mass_sigma_kg"].number();
  l.nominal_com_m = vector3_of(f["nominal_com_m"]);
  l.com_m = vector3_of(f["com_m"]);
  l.com_sigma_m = vector3_of(f["com_sigma_m"]);
  return l;
}

IdentificationReportHeader header_of(const JsonField& root) {
  IdentificationReportHeader h;
  h.created_by = root["created_by"].text();
  h.joint_errors = root["joint_errors"].text();
  h.joint_errors_sha256 = root["joint_errors_sha256"].text();
  h.config = root["config"].text();
  h.samples = root["samples"].count();
  h.segments = root["segments"].count();
  h.sample_time_s = root["sample_time_s"].number();
  h.seconds = root["seconds"].number();
  if (const auto search = root.optional("transmission_error_order_search"))
    h.order_search = order_search_of(*search);
  return h;
}

}  // namespace

json identification_report_json(const IdentificationReportHeader& header,
                                const std::vector<JointOutcome>& outcomes) {
  json joints = json::array();
  for (const JointOutcome& outcome : outcomes)
    joints.push_back(joint_json(outcome.result, outcome.seconds, outcome.structure));
  return {{kVersionKey, 1},
          {"created_by", header.created_by},
          {"joint_errors", header.joint_errors},
          {"joint_errors_sha256", header.joint_errors_sha256},
          {"config", header.config},
          {"samples", header.samples},
          {"segments", header.segments},
          {"sample_time_s", header.sample_time_s},
          {"seconds", header.seconds},
          {"transmission_error_order_search",
           header.order_search ? order_search_json(*header.order_search) : json(nullptr)},
          {"joints", joints}};
}

IdentificationReport read_identification_report(const std::filesystem::path& file) {
  const JsonDocument document = read_json_document(file);
  document.check_version(kVersionKey, 1, "an imscal identification_report.json");
  const JsonField root = document.root();
  IdentificationReport report;
  report.header = header_of(root);
  const JsonField joints = root["joints"];
  for (std::size_t k = 0; k < joints.size(); ++k) report.joints.push_back(joint_of(joints[k]));
  if (const auto links = root.optional("model_torque_links"))  // with the refinement only
    for (std::size_t k = 0; k < links->size(); ++k)
      report.model_torque_links.push_back(link_of((*links)[k]));
  if (const auto friction = root.optional("friction_levels"))
    report.friction_levels = friction_levels_of(*friction);
  return report;
}

}  // namespace imscal::ident
