#include "ident/parameter_table_io.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <sstream>
#include <string_view>

#include "core/input_error.hpp"
#include "core/input_file.hpp"
#include "core/json_input.hpp"
#include "core/json_output.hpp"
#include "ident/model_stability.hpp"

namespace imscal::ident {

const char* to_string(CellStatus status) {
  switch (status) {
    case CellStatus::kIdentified:
      return "identified";
    case CellStatus::kFilled:
      return "filled";
    case CellStatus::kNeutral:
      return "neutral";
  }
  return "?";
}

const char* to_string(TableForm form) {
  return form == TableForm::kInverse ? "inverse" : "forward";
}

ArxModel CellParameters::model(double sample_time_s) const {
  return ArxModel(structure, Eigen::Map<const Eigen::VectorXd>(a.data(), Eigen::Index(a.size())),
                  Eigen::Map<const Eigen::VectorXd>(b.data(), Eigen::Index(b.size())),
                  Eigen::Map<const Eigen::VectorXd>(c.data(), Eigen::Index(c.size())),
                  sample_time_s);
}

namespace {

using nlohmann::json;
constexpr std::string_view kSchemaName = "imscal-parameter-table";
// Loaded models must be stable with at least this margin; the identification uses its own
// (configurable, normally larger) margin, this only refuses tables that are plainly unusable.
constexpr double kLoadStabilityMargin = 0.0;

json units() {
  return {{"angle", "rad"},  {"time", "s"},       {"speed", "rad/s"},
          {"payload", "kg"}, {"position", "rad"}, {"acceleration", "rad/s^2"}};
}

json cell_json(const CellParameters& c) {
  json j = {{"bands", c.bands},
            {"status", to_string(c.status)},
            {"na", c.structure.na},
            {"nb", c.structure.nb},
            {"dead_time", c.structure.dead_time},
            {"nx", std::vector<int>(c.structure.nx.begin(),
                                    c.structure.nx.begin() + c.structure.extra_inputs)},
            {"a", c.a},
            {"b", c.b},
            {"c", c.c},
            {"fit",
             {{"estimation_rows", c.figures.estimation_rows},
              {"validation_rows", c.figures.validation_rows},
              {"one_step_fit_percent", json_number_or_null(c.figures.one_step_fit_percent)},
              {"simulation_fit_percent", json_number_or_null(c.figures.simulation_fit_percent)},
              {"joint_error_fit_percent", json_number_or_null(c.figures.joint_error_fit_percent)},
              {"residual_rms_rad", json_number_or_null(c.figures.residual_rms_rad)},
              {"whiteness_passed", c.figures.whiteness_passed},
              {"input_residual_passed", c.figures.input_residual_passed},
              {"spectral_radius", json_number_or_null(c.figures.spectral_radius)}}}};
  if (c.status == CellStatus::kFilled) j["filled_from"] = c.filled_from;
  if (c.status != CellStatus::kIdentified) j["reason"] = c.reason;
  return j;
}

// ---------------------------------------------------------------------------------------------
// Reading: a JSON value with its path, every error an InputError naming the file and the path.

class Node {
 public:
  Node(const json& value, std::string path, const std::string& file)
      : value_(value), path_(std::move(path)), file_(file) {}

  [[noreturn]] void fail(const std::string& problem) const {
    throw InputError(file_, 0, path_.empty() ? "/" : path_, problem);
  }
  Node child(const std::string& key) const {
    if (!value_.is_object()) fail("expected an object");
    const auto it = value_.find(key);
    if (it == value_.end()) Node(value_, path_ + "/" + key, file_).fail("missing key");
    return Node(*it, path_ + "/" + key, file_);
  }
  bool has(const std::string& key) const { return value_.is_object() && value_.contains(key); }
  void only_keys(std::initializer_list<std::string_view> allowed) const {
    if (!value_.is_object()) fail("expected an object");
    for (const auto& [key, v] : value_.items()) {
      bool known = false;
      for (auto a : allowed) known = known || a == key;
      if (!known) Node(v, path_ + "/" + key, file_).fail("unknown key");
    }
  }
  std::vector<Node> items() const {
    if (!value_.is_array()) fail("expected an array");
    std::vector<Node> out;
    for (std::size_t i = 0; i < value_.size(); ++i)
      out.emplace_back(value_[i], path_ + "/" + std::to_string(i), file_);
    return out;
  }
  double number() const {
    if (!value_.is_number())
      fail(value_.is_null() ? "not a finite number (null/NaN)" : "expected a number");
    const double v = value_.get<double>();
    if (!std::isfinite(v)) fail("not a finite number");
    return v;
  }
  // A figure: null stands for "not available" (NaN).
  double number_or_nan() const {
    return value_.is_null() ? std::numeric_limits<double>::quiet_NaN() : number();
  }
  long integer() const {
    if (!value_.is_number_integer()) fail("expected an integer");
    return value_.get<long>();
  }
  std::size_t count() const {
    const long v = integer();
    if (v < 0) fail("expected a count >= 0");
    return std::size_t(v);
  }
  bool boolean() const {
    if (!value_.is_boolean()) fail("expected true or false");
    return value_.get<bool>();
  }
  std::string string() const {
    if (!value_.is_string()) fail("expected a string");
    return value_.get<std::string>();
  }
  std::vector<double> numbers() const {
    std::vector<double> out;
    for (const Node& n : items()) out.push_back(n.number());
    return out;
  }
  const std::string& path() const { return path_; }

 private:
  const json& value_;
  std::string path_;
  const std::string& file_;
};

CellDimension read_dimension(const Node& n) {
  n.only_keys({"quantity", "unit", "bounds"});
  CellDimension d;
  try {
    d.quantity = operating_quantity_from_string(n.child("quantity").string());
  } catch (const std::invalid_argument& e) {
    n.child("quantity").fail(e.what());
  }
  const std::string unit = n.child("unit").string();
  if (unit != si_unit(d.quantity))
    n.child("unit").fail(fmt::format("unit '{}' for {}; expected '{}'", unit, to_string(d.quantity),
                                     si_unit(d.quantity)));
  d.bounds = n.child("bounds").numbers();
  if (d.bounds.size() < 2) n.child("bounds").fail("at least 2 bounds needed");
  for (std::size_t i = 1; i < d.bounds.size(); ++i)
    if (!(d.bounds[i] > d.bounds[i - 1]))
      n.child("bounds").fail("bounds must be strictly increasing");
  return d;
}

CellFitFigures read_figures(const Node& n) {
  n.only_keys({"estimation_rows", "validation_rows", "one_step_fit_percent",
               "simulation_fit_percent", "joint_error_fit_percent", "residual_rms_rad",
               "whiteness_passed", "input_residual_passed", "spectral_radius"});
  CellFitFigures f;
  f.estimation_rows = n.child("estimation_rows").count();
  f.validation_rows = n.child("validation_rows").count();
  f.one_step_fit_percent = n.child("one_step_fit_percent").number_or_nan();
  f.simulation_fit_percent = n.child("simulation_fit_percent").number_or_nan();
  f.joint_error_fit_percent = n.child("joint_error_fit_percent").number_or_nan();
  f.residual_rms_rad = n.child("residual_rms_rad").number_or_nan();
  f.whiteness_passed = n.child("whiteness_passed").boolean();
  f.input_residual_passed = n.child("input_residual_passed").boolean();
  f.spectral_radius = n.child("spectral_radius").number_or_nan();
  return f;
}

CellParameters read_cell(const Node& n, const CellGrid& grid, double sample_time_s,
                         int extra_inputs) {
  if (extra_inputs < 0)  // schema version 1: single-input cells
    n.only_keys(
        {"bands", "status", "filled_from", "reason", "na", "nb", "dead_time", "a", "b", "fit"});
  else
    n.only_keys({"bands", "status", "filled_from", "reason", "na", "nb", "dead_time", "nx", "a",
                 "b", "c", "fit"});
  CellParameters c;
  const Node bands = n.child("bands");
  for (const Node& b : bands.items()) c.bands.push_back(int(b.integer()));
  if (c.bands.size() != grid.dimensions().size())
    bands.fail(
        fmt::format("{} band indices for {} dimensions", c.bands.size(), grid.dimensions().size()));
  for (std::size_t d = 0; d < c.bands.size(); ++d)
    if (c.bands[d] < 0 || c.bands[d] >= grid.dimensions()[d].cell_count())
      bands.fail(fmt::format("band {} of dimension {} is outside 0..{}", c.bands[d], d,
                             grid.dimensions()[d].cell_count() - 1));
  const std::string status = n.child("status").string();
  if (status == "identified") {
    c.status = CellStatus::kIdentified;
    if (n.has("filled_from")) n.child("filled_from").fail("only a filled cell has filled_from");
  } else if (status == "filled") {
    c.status = CellStatus::kFilled;
    c.filled_from = int(n.child("filled_from").integer());
    if (c.filled_from < 0 || c.filled_from >= grid.cell_count())
      n.child("filled_from").fail("not a cell of this joint");
    c.reason = n.child("reason").string();
  } else if (status == "neutral") {
    c.status = CellStatus::kNeutral;
    if (n.has("filled_from")) n.child("filled_from").fail("only a filled cell has filled_from");
    c.reason = n.child("reason").string();
  } else {
    n.child("status").fail("expected 'identified', 'filled' or 'neutral', got '" + status + "'");
  }
  if (c.status == CellStatus::kIdentified && n.has("reason")) c.reason = n.child("reason").string();
  c.structure.na = int(n.child("na").integer());
  c.structure.nb = int(n.child("nb").integer());
  c.structure.dead_time = int(n.child("dead_time").integer());
  if (extra_inputs >= 0) {  // schema 2: one coefficient count per further input of the table
    const Node nx = n.child("nx");
    const std::vector<Node> counts = nx.items();
    if (counts.size() != std::size_t(extra_inputs))
      nx.fail(
          fmt::format("{} counts for the table's {} further inputs", counts.size(), extra_inputs));
    c.structure.extra_inputs = extra_inputs;
    for (int e = 0; e < extra_inputs; ++e) {
      const long count = counts[std::size_t(e)].integer();
      if (count < 1 || count > 256) counts[std::size_t(e)].fail("expected 1..256 coefficients");
      c.structure.nx[std::size_t(e)] = int(count);
    }
  }
  try {
    c.structure.validate();
  } catch (const std::invalid_argument& e) {
    n.fail(e.what());
  }
  c.a = n.child("a").numbers();
  c.b = n.child("b").numbers();
  if (extra_inputs >= 0) c.c = n.child("c").numbers();
  if (c.c.size() != std::size_t(c.structure.extra_coefficient_count()))
    n.child("c").fail(fmt::format("{} coefficients, the further inputs' nx add up to {}",
                                  c.c.size(), c.structure.extra_coefficient_count()));
  if (c.a.size() != std::size_t(c.structure.na))
    n.child("a").fail(fmt::format("{} coefficients, na = {}", c.a.size(), c.structure.na));
  if (c.b.size() != std::size_t(c.structure.nb))
    n.child("b").fail(fmt::format("{} coefficients, nb = {}", c.b.size(), c.structure.nb));
  c.figures = read_figures(n.child("fit"));
  const StabilityCheck stability = check_stability(c.model(sample_time_s), kLoadStabilityMargin);
  if (!stability.stable) n.child("a").fail("model rejected: " + stability.reason);
  return c;
}

// A further input by its name (ident/exogenous_inputs.hpp).
TableInput read_input(const Node& n) {
  const std::string name = n.string();
  std::string expected;
  for (int k = 0; k < kExogenousInputKindCount; ++k) {
    const ExogenousInputKind& kind = kExogenousInputKinds[k];
    if (name == kind.name) return kind.input;
    expected += k == 0 ? "" : k + 1 < kExogenousInputKindCount ? ", " : " or ";
    expected += fmt::format("'{}'", kind.name);
  }
  n.fail("expected " + expected + ", got '" + name + "'");
}

// The gear mode of the gear-mode transmission-error pairs (version 6 on, optional): natural
// frequency > 0 and damping ratio > 0. gear_mode_inputs: whether the table has inputs it acts on
// (version 6: the plain pairs, read as the gear-mode kinds; version 7: the gear-mode kinds).
void read_gear_mode_key(const Node& n, JointParameters& j, bool gear_mode_inputs) {
  if (!n.has("transmission_error_gear_mode")) return;
  const Node mode = n.child("transmission_error_gear_mode");
  if (!gear_mode_inputs) mode.fail("the table has no gear-mode transmission-error input");
  mode.only_keys({"natural_frequency_rad_s", "damping_ratio"});
  j.transmission_error_mode_rad_s = mode.child("natural_frequency_rad_s").number();
  j.transmission_error_mode_damping = mode.child("damping_ratio").number();
  if (!(j.transmission_error_mode_rad_s > 0.0 && std::isfinite(j.transmission_error_mode_rad_s)))
    mode.child("natural_frequency_rad_s").fail("must be finite and > 0");
  if (!(j.transmission_error_mode_damping > 0.0 &&
        std::isfinite(j.transmission_error_mode_damping)))
    mode.child("damping_ratio").fail("must be finite and > 0");
}

// The transmission-error keys of a joint (version 3 on): the phase rates and the compliance.
void read_transmission_error_keys(const Node& n, JointParameters& j, bool transmission_error,
                                  bool second_transmission_error, bool gear_mode_inputs) {
  const Node te = n.child("transmission_error_rad_per_rad");
  j.transmission_error_rad_per_rad = te.number();
  if (transmission_error ? !(j.transmission_error_rad_per_rad > 0.0)
                         : j.transmission_error_rad_per_rad != 0.0)
    te.fail(transmission_error
                ? "the table has the transmission-error inputs: the phase rate must be > 0"
                : "the table has no transmission-error input: the phase rate must be 0");
  if (second_transmission_error) {
    const Node te2 = n.child("transmission_error_2_rad_per_rad");
    j.transmission_error_2_rad_per_rad = te2.number();
    if (!(j.transmission_error_2_rad_per_rad >= 0.0) ||
        j.transmission_error_2_rad_per_rad == j.transmission_error_rad_per_rad)
      te2.fail(
          "the table has the second transmission-error inputs: the phase rate must be "
          ">= 0 (0: no second order on this joint) and differ from the first's");
  } else if (n.has("transmission_error_2_rad_per_rad")) {
    n.child("transmission_error_2_rad_per_rad")
        .fail("the table has no second transmission-error input");
  }
  read_gear_mode_key(n, j, gear_mode_inputs);
  const Node compliance = n.child("transmission_error_compliance_rad_per_nm");
  j.transmission_error_compliance_rad_per_nm = compliance.number();
  if (!(j.transmission_error_compliance_rad_per_nm >= 0.0) ||
      (!transmission_error && j.transmission_error_compliance_rad_per_nm != 0.0))
    compliance.fail(transmission_error ? "must be >= 0 (0: the phase from the joint angle alone)"
                                       : "the table has no transmission-error input: must be 0");
}

// extra_inputs: the table's further inputs (-1: schema version 1); torque_sign: whether one of
// them is the torque's sign (the joint then needs its scale); transmission_error: whether the
// transmission-error pair is (the joint then needs its phase rate; the key from version 3 on);
// gear_mode_inputs: whether a joint may carry a gear mode (read_gear_mode_key).
JointParameters read_joint(const Node& n, double sample_time_s, int schema_version,
                           int extra_inputs, bool torque_sign, bool transmission_error,
                           bool second_transmission_error, bool gear_mode_inputs) {
  if (extra_inputs < 0)
    n.only_keys({"name", "backlash", "dimensions", "cells"});
  else if (schema_version < 3)
    n.only_keys({"name", "backlash", "torque_sign_scale_nm", "offset_envelope_rad",
                 "offset_rate_envelope_rad_s", "dimensions", "cells"});
  else if (schema_version < 4)
    n.only_keys({"name", "backlash", "torque_sign_scale_nm", "transmission_error_rad_per_rad",
                 "transmission_error_compliance_rad_per_nm", "offset_envelope_rad",
                 "offset_rate_envelope_rad_s", "dimensions", "cells"});
  else if (schema_version < 6)
    n.only_keys({"name", "backlash", "torque_sign_scale_nm", "transmission_error_rad_per_rad",
                 "transmission_error_2_rad_per_rad", "transmission_error_compliance_rad_per_nm",
                 "offset_envelope_rad", "offset_rate_envelope_rad_s", "dimensions", "cells"});
  else
    n.only_keys({"name", "backlash", "torque_sign_scale_nm", "transmission_error_rad_per_rad",
                 "transmission_error_2_rad_per_rad", "transmission_error_compliance_rad_per_nm",
                 "transmission_error_gear_mode", "offset_envelope_rad",
                 "offset_rate_envelope_rad_s", "dimensions", "cells"});
  JointParameters j;
  j.name = n.child("name").string();
  if (j.name.empty()) n.child("name").fail("empty joint name");
  if (extra_inputs >= 0) {
    j.torque_sign_scale_nm = n.child("torque_sign_scale_nm").number();
    if (torque_sign ? !(j.torque_sign_scale_nm > 0.0) : j.torque_sign_scale_nm != 0.0)
      n.child("torque_sign_scale_nm")
          .fail(torque_sign ? "the table has the torque-sign input: the scale must be > 0"
                            : "the table has no torque-sign input: the scale must be 0");
    if (schema_version >= 3)
      read_transmission_error_keys(n, j, transmission_error, second_transmission_error,
                                   gear_mode_inputs);
    for (const auto& [key, value] :
         {std::pair{"offset_envelope_rad", &j.offset_envelope_rad},
          std::pair{"offset_rate_envelope_rad_s", &j.offset_rate_envelope_rad_s}}) {
      *value = n.child(key).number();
      if (!(*value >= 0.0)) n.child(key).fail("must be >= 0 (0: not known)");
    }
  }
  const Node bl = n.child("backlash");
  bl.only_keys({"l_rad", "l_sigma_rad", "identified", "lag_samples"});
  j.backlash_l_rad = bl.child("l_rad").number();
  j.backlash_l_sigma_rad = bl.child("l_sigma_rad").number();
  if (j.backlash_l_rad < 0.0) bl.child("l_rad").fail("negative backlash");
  if (j.backlash_l_sigma_rad < 0.0) bl.child("l_sigma_rad").fail("negative standard deviation");
  j.backlash_identified = bl.child("identified").boolean();
  j.backlash_lag_samples = bl.child("lag_samples").count();
  const Node dims = n.child("dimensions");
  for (const Node& d : dims.items()) j.dimensions.push_back(read_dimension(d));
  CellGrid grid;
  try {
    grid = CellGrid(j.dimensions);
  } catch (const std::invalid_argument& e) {
    dims.fail(e.what());
  }
  const Node cells = n.child("cells");
  std::vector<std::optional<CellParameters>> by_flat(std::size_t(grid.cell_count()));
  for (const Node& c : cells.items()) {
    CellParameters cell = read_cell(c, grid, sample_time_s, extra_inputs);
    const int flat = grid.flat_index(cell.bands);
    if (by_flat[std::size_t(flat)]) c.child("bands").fail("cell given twice: " + grid.label(flat));
    by_flat[std::size_t(flat)] = std::move(cell);
  }
  for (int flat = 0; flat < grid.cell_count(); ++flat) {
    if (!by_flat[std::size_t(flat)])
      cells.fail(fmt::format("missing cell {} ({}) of the {} cells of the grid", flat,
                             grid.label(flat), grid.cell_count()));
    j.cells.push_back(std::move(*by_flat[std::size_t(flat)]));
  }
  return j;
}

std::array<double, 3> read_vector3(const Node& n, bool non_negative) {
  const std::vector<double> v = n.numbers();
  if (v.size() != 3) n.fail("expected 3 numbers [m]");
  for (const double x : v)
    if (non_negative && x < 0.0) n.fail("negative standard deviation");
  return {v[0], v[1], v[2]};
}

LinkMassParameters read_link_masses(const Node& n) {
  n.only_keys({"refined", "held_out_z", "nominal_mass_kg", "mass_kg", "mass_sigma_kg",
               "nominal_com_m", "com_m", "com_sigma_m"});
  LinkMassParameters l;
  l.refined = n.child("refined").boolean();
  l.held_out_z = n.child("held_out_z").number();
  for (const auto& [key, value] :
       {std::pair{"nominal_mass_kg", &l.nominal_mass_kg}, std::pair{"mass_kg", &l.mass_kg}}) {
    *value = n.child(key).number();
    if (!(*value > 0.0)) n.child(key).fail("a link's mass must be > 0 kg");
  }
  l.mass_sigma_kg = n.child("mass_sigma_kg").number();
  if (l.mass_sigma_kg < 0.0) n.child("mass_sigma_kg").fail("negative standard deviation");
  l.nominal_com_m = read_vector3(n.child("nominal_com_m"), false);
  l.com_m = read_vector3(n.child("com_m"), false);
  l.com_sigma_m = read_vector3(n.child("com_sigma_m"), true);
  return l;
}

// Version 5's optional model_torque_links: one per joint's link when given.
std::vector<LinkMassParameters> read_model_torque_links(const Node& r, int schema_version,
                                                        std::size_t joints) {
  if (!r.has("model_torque_links")) return {};
  const Node links = r.child("model_torque_links");
  if (schema_version < 5) links.fail("not a key before schema version 5");
  std::vector<LinkMassParameters> out;
  for (const Node& l : links.items()) out.push_back(read_link_masses(l));
  if (out.size() != joints)
    links.fail(fmt::format("{} links for the table's {} joints", out.size(), joints));
  return out;
}

// Version 6 filtered the plain pairs of the joints with a gear mode: such a table's pairs are
// the gear-mode kinds, which equal the plain pairs on joints without a mode (the values and
// coefficients unchanged); the table is then one of this version.
void read_version_6_gear_mode_pairs(ParameterTable& t) {
  const bool any_mode = std::ranges::any_of(
      t.joints, [](const JointParameters& j) { return j.transmission_error_mode_rad_s > 0.0; });
  if (!any_mode) return;
  for (TableInput& input : t.extra_inputs) {
    using enum TableInput;
    if (input == kTransmissionErrorSin) input = kTransmissionErrorModeSin;
    if (input == kTransmissionErrorCos) input = kTransmissionErrorModeCos;
    if (input == kTransmissionError2Sin) input = kTransmissionError2ModeSin;
    if (input == kTransmissionError2Cos) input = kTransmissionError2ModeCos;
  }
  t.schema_version = kParameterTableSchemaVersion;
}

// The joints of a table whose header (version, sample time, inputs) is read.
void read_joints(const Node& joints, ParameterTable& t) {
  std::set<std::string> names;
  const auto has = [&](TableInput input) { return has_input(t.extra_inputs, input); };
  using enum TableInput;
  const bool plain = has(kTransmissionErrorSin) || has(kTransmissionErrorCos);
  const bool filtered = has(kTransmissionErrorModeSin) || has(kTransmissionErrorModeCos);
  const bool second = has(kTransmissionError2Sin) || has(kTransmissionError2Cos) ||
                      has(kTransmissionError2ModeSin) || has(kTransmissionError2ModeCos);
  for (const Node& j : joints.items()) {
    t.joints.push_back(read_joint(j, t.sample_time_s, t.schema_version,
                                  t.schema_version >= 2 ? int(t.extra_inputs.size()) : -1,
                                  has(kTorqueSign), plain || filtered, second,
                                  t.schema_version < 7 ? plain : filtered));
    if (!names.insert(t.joints.back().name).second)
      j.child("name").fail("joint '" + t.joints.back().name + "' given twice");
  }
  if (t.joints.empty()) joints.fail("no joint");
  if (t.schema_version < 7) read_version_6_gear_mode_pairs(t);
}

}  // namespace

nlohmann::json model_torque_links_json(const std::vector<LinkMassParameters>& links) {
  json out = json::array();
  for (const LinkMassParameters& l : links)
    out.push_back({{"refined", l.refined},
                   {"held_out_z", l.held_out_z},
                   {"nominal_mass_kg", l.nominal_mass_kg},
                   {"mass_kg", l.mass_kg},
                   {"mass_sigma_kg", l.mass_sigma_kg},
                   {"nominal_com_m", l.nominal_com_m},
                   {"com_m", l.com_m},
                   {"com_sigma_m", l.com_sigma_m}});
  return out;
}

std::string parameters_json_text(const ParameterTable& t) {
  const bool second_transmission_error =
      has_pair(t.extra_inputs, TableInput::kTransmissionError2Sin,
               TableInput::kTransmissionError2Cos) ||
      has_pair(t.extra_inputs, TableInput::kTransmissionError2ModeSin,
               TableInput::kTransmissionError2ModeCos);
  json joints = json::array();
  for (const JointParameters& j : t.joints) {
    json dims = json::array();
    for (const auto& d : j.dimensions)
      dims.push_back({{"quantity", to_string(d.quantity)},
                      {"unit", si_unit(d.quantity)},
                      {"bounds", d.bounds}});
    json cells = json::array();
    for (const auto& c : j.cells) cells.push_back(cell_json(c));
    json joint = {{"name", j.name},
                  {"backlash",
                   {{"l_rad", j.backlash_l_rad},
                    {"l_sigma_rad", j.backlash_l_sigma_rad},
                    {"identified", j.backlash_identified},
                    {"lag_samples", j.backlash_lag_samples}}},
                  {"torque_sign_scale_nm", j.torque_sign_scale_nm},
                  {"offset_envelope_rad", j.offset_envelope_rad},
                  {"offset_rate_envelope_rad_s", j.offset_rate_envelope_rad_s},
                  {"dimensions", dims},
                  {"cells", cells}};
    // Version 3's key; a version 2 table read back is written as it was.
    if (t.schema_version >= 3) {
      joint["transmission_error_rad_per_rad"] = j.transmission_error_rad_per_rad;
      joint["transmission_error_compliance_rad_per_nm"] =
          j.transmission_error_compliance_rad_per_nm;
    }
    if (second_transmission_error)  // version 4, with the second pair only
      joint["transmission_error_2_rad_per_rad"] = j.transmission_error_2_rad_per_rad;
    if (j.transmission_error_mode_rad_s > 0.0)  // version 6 on, with a gear mode only
      joint["transmission_error_gear_mode"] = {
          {"natural_frequency_rad_s", j.transmission_error_mode_rad_s},
          {"damping_ratio", j.transmission_error_mode_damping}};
    joints.push_back(std::move(joint));
  }
  json extra_names = json::array();
  for (const TableInput input : t.extra_inputs) extra_names.push_back(to_string(input));
  json root = {{"schema", kSchemaName},
               {"schema_version", t.schema_version},
               {"robot", t.robot},
               {"sample_time_s", t.sample_time_s},
               {"created_by", t.created_by},
               {"model_form", to_string(t.model_form)},
               {"preview_cycles", t.preview_cycles},
               {"extra_inputs", extra_names},
               {"direction_speed_scale_rad_s", t.direction_speed_scale_rad_s},
               {"units", units()},
               {"source",
                {{"file", t.source.file},
                 {"sha256", t.source.sha256},
                 {"samples", t.source.samples},
                 {"description", t.source.description}}},
               {"joints", joints}};
  if (!t.model_torque_links.empty())
    root["model_torque_links"] = model_torque_links_json(t.model_torque_links);
  return json_text(root, 1, "parameters.json");
}

namespace {

// The further inputs' coefficient counts, space-separated (empty without further inputs).
std::string join_counts(const ArxStructure& s) {
  std::string out;
  for (int e = 0; e < s.extra_inputs; ++e)
    out += fmt::format("{}{}", out.empty() ? "" : " ", s.nx[std::size_t(e)]);
  return out;
}

}  // namespace

std::string parameters_csv_text(const ParameterTable& t) {
  std::ostringstream s;
  s << "joint,cell,bands,bounds_si,status,filled_from,na,nb,dead_time,nx,backlash_l_rad,"
       "backlash_l_sigma_rad,estimation_rows,validation_rows,one_step_fit_percent,"
       "simulation_fit_percent,joint_error_fit_percent,residual_rms_rad,whiteness_passed,input_"
       "residual_passed,"
       "spectral_radius,a,b,c\n";
  auto join = [](const std::vector<double>& v) {
    std::string out;
    for (double x : v) out += fmt::format("{}{:.17g}", out.empty() ? "" : " ", x);
    return out;
  };
  for (const JointParameters& j : t.joints) {
    const CellGrid grid = j.grid();
    for (std::size_t flat = 0; flat < j.cells.size(); ++flat) {
      const CellParameters& c = j.cells[flat];
      std::string bands;
      for (int b : c.bands) bands += fmt::format("{}{}", bands.empty() ? "" : " ", b);
      const auto& f = c.figures;
      s << fmt::format(
          "{},{},{},\"{}\",{},{},{},{},{},{},{:.17g},{:.17g},{},{},{},{},{},{},{},{},{},{},{},{}\n",
          j.name, flat, bands, grid.label(int(flat)), to_string(c.status), c.filled_from,
          c.structure.na, c.structure.nb, c.structure.dead_time, join_counts(c.structure),
          j.backlash_l_rad, j.backlash_l_sigma_rad, f.estimation_rows, f.validation_rows,
          f.one_step_fit_percent, f.simulation_fit_percent, f.joint_error_fit_percent,
          f.residual_rms_rad, f.whiteness_passed ? 1 : 0, f.input_residual_passed ? 1 : 0,
          f.spectral_radius, join(c.a), join(c.b), join(c.c));
    }
  }
  return s.str();
}

void write_parameters_json(const std::filesystem::path& file, const ParameterTable& table,
                           Overwrite overwrite) {
  write_file_atomically(file, parameters_json_text(table), overwrite);
}

void write_parameters_csv(const std::filesystem::path& file, const ParameterTable& table,
                          Overwrite overwrite) {
  write_file_atomically(file, parameters_csv_text(table), overwrite);
}

ParameterTable parse_parameters_json(const std::string& text, const std::string& origin) {
  const json root = parse_json_refusing_duplicate_keys(text, origin);
  const Node r(root, "", origin);
  r.only_keys({"schema", "schema_version", "robot", "sample_time_s", "created_by", "model_form",
               "preview_cycles", "extra_inputs", "direction_speed_scale_rad_s", "units", "source",
               "joints", "model_torque_links"});
  if (r.child("schema").string() != kSchemaName)
    r.child("schema").fail(
        fmt::format("not an imscal parameter table (expected '{}')", kSchemaName));
  ParameterTable t;
  t.schema_version = int(r.child("schema_version").integer());
  if (t.schema_version < 1 || t.schema_version > kParameterTableSchemaVersion)
    r.child("schema_version")
        .fail(fmt::format("unknown schema version {}; this imscal reads versions 1..{}",
                          t.schema_version, kParameterTableSchemaVersion));
  if (t.schema_version >= 2) {
    const std::string form = r.child("model_form").string();
    if (form == to_string(TableForm::kInverse))
      t.model_form = TableForm::kInverse;
    else if (form != to_string(TableForm::kForward))
      r.child("model_form").fail("expected 'forward' or 'inverse', got '" + form + "'");
    const long preview = r.child("preview_cycles").integer();
    if (preview < 0 || preview > 64) r.child("preview_cycles").fail("expected 0..64 cycles");
    if (preview > 0 && t.model_form != TableForm::kInverse)
      r.child("preview_cycles").fail("only an inverse-form table has a preview");
    t.preview_cycles = int(preview);
    const Node inputs = r.child("extra_inputs");
    for (const Node& i : inputs.items()) t.extra_inputs.push_back(read_input(i));
    for (const TableInput input : t.extra_inputs)
      if (t.schema_version < kind_of(input).since_schema_version)
        inputs.fail(fmt::format("the {} inputs need schema version {}", kind_of(input).family,
                                kind_of(input).since_schema_version));
    if (t.extra_inputs.size() > std::size_t(kMaxExtraInputs))
      inputs.fail(fmt::format("at most {} further inputs", kMaxExtraInputs));
    for (std::size_t a = 0; a < t.extra_inputs.size(); ++a)
      for (std::size_t b = a + 1; b < t.extra_inputs.size(); ++b)
        if (t.extra_inputs[a] == t.extra_inputs[b]) inputs.fail("an input given twice");
    t.direction_speed_scale_rad_s = r.child("direction_speed_scale_rad_s").number();
    if (!(t.direction_speed_scale_rad_s > 0.0))
      r.child("direction_speed_scale_rad_s").fail("must be > 0");
  } else {
    for (const char* key :
         {"model_form", "preview_cycles", "extra_inputs", "direction_speed_scale_rad_s"})
      if (r.has(key)) r.child(key).fail("not a key of schema version 1");
  }
  t.robot = r.child("robot").string();
  t.sample_time_s = r.child("sample_time_s").number();
  if (!(t.sample_time_s > 0.0)) r.child("sample_time_s").fail("sample time must be > 0");
  t.created_by = r.child("created_by").string();
  const Node u = r.child("units");
  const json expected = units();
  u.only_keys({"angle", "time", "speed", "payload", "position", "acceleration"});
  for (const auto& [key, value] : expected.items())
    if (u.child(key).string() != value.get<std::string>())
      u.child(key).fail(fmt::format("unit '{}', expected '{}' (SI)", u.child(key).string(),
                                    value.get<std::string>()));
  const Node src = r.child("source");
  src.only_keys({"file", "sha256", "samples", "description"});
  t.source.file = src.child("file").string();
  t.source.sha256 = src.child("sha256").string();
  t.source.samples = src.child("samples").count();
  t.source.description = src.child("description").string();
  read_joints(r.child("joints"), t);
  t.model_torque_links = read_model_torque_links(r, t.schema_version, t.joints.size());
  return t;
}

ParameterTable read_parameters_json(const std::filesystem::path& file) {
  return parse_parameters_json(read_input_file(file), file.string());
}

}  // namespace imscal::ident
