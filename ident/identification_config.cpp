#include "ident/identification_config.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <numbers>
#include <stdexcept>
#include <string>
#include <tuple>

#include "core/units.hpp"
#include "ident/identification_config_record.hpp"
#include "ident/precontrol.hpp"

namespace imscal::ident {
namespace {

std::vector<double> scaled(const std::vector<double>& v, double factor) {
  std::vector<double> out;
  for (double x : v) out.push_back(x * factor);
  return out;
}

void check_increasing(const ConfigNode& node, const std::vector<double>& v) {
  if (v.size() < 2) node.fail("at least 2 bounds needed");
  for (std::size_t i = 1; i < v.size(); ++i)
    if (!(v[i] > v[i - 1])) node.fail("bounds must be strictly increasing");
}

// One positive value per joint (`what` names it in the messages): empty when the key is absent.
std::vector<double> per_joint_positive(const ConfigNode& joints, const char* key,
                                       std::size_t joint_count, const char* what) {
  const auto node = joints.optional_child(key);
  if (!node) return {};
  std::vector<double> v = node->as_doubles();
  if (v.size() != joint_count)
    node->fail(
        fmt::format("one {} per joint: {} given, {} maximum speeds", what, v.size(), joint_count));
  for (double x : v)
    if (!(x > 0.0)) node->fail(fmt::format("every {} must be > 0", what));
  return v;
}

// An order range [min, max] of integers in [lowest, highest]; the bounds are checked before the
// integer test so that 1e300 is refused, not converted.
std::pair<int, int> range(const ConfigNode& node, int lowest, int highest) {
  const std::vector<double> v = node.as_doubles();
  const auto in_bounds = [&](double x) { return x >= lowest && x <= highest; };
  if (v.size() != 2 || !in_bounds(v[0]) || !in_bounds(v[1]) || v[0] != double(long(v[0])) ||
      v[1] != double(long(v[1])) || v[1] < v[0])
    node.fail(
        fmt::format("expected [min, max], integers, {} <= min <= max <= {}", lowest, highest));
  return {int(v[0]), int(v[1])};
}

// `duration_key` [s] or `count_key`, not both: the duration (NaN when not given), its line kept.
double duration_instead_of_count(const ConfigNode& parent, const std::string& parent_key,
                                 const char* duration_key, const char* count_key,
                                 IdentificationConfig& c) {
  const auto node = parent.optional_child(duration_key);
  if (!node) return ConfigDurations::kNone;
  if (parent.has(count_key))
    node->fail(fmt::format("give {} or {}, not both", duration_key, count_key));
  const double seconds = node->as_double();
  if (!(seconds >= 0.0 && seconds <= 3600.0)) node->fail("must be in [0, 3600] s");
  c.key_lines[parent_key + "." + duration_key] = node->line();
  return seconds;
}

// Where the gear mode's pairs go (model.transmission_error_gear_mode_pairs, instead of the plain
// pairs by default) and their taps beside them.
void load_gear_mode_pairs(const ConfigNode& model, IdentificationConfig& c) {
  JointIdentificationOptions& o = c.options;
  GearModePairs pairs = GearModePairs::kInstead;
  if (const auto n = model.optional_child("transmission_error_gear_mode_pairs")) {
    if (n->as_string() == "beside")
      pairs = GearModePairs::kBeside;
    else if (n->as_string() != "instead")
      n->fail("expected 'instead' (of the plain pairs) or 'beside' (them)");
  }
  o.transmission_error_mode_pairs = c.transmission_error_gear_mode ? pairs : GearModePairs::kNone;
  o.transmission_error_mode_taps =
      int(model.get_int("transmission_error_gear_mode_taps", o.transmission_error_mode_taps));
  if (o.transmission_error_mode_taps < 1 || o.transmission_error_mode_taps > 64)
    model.child("transmission_error_gear_mode_taps").fail("must be in 1..64 coefficients");
}

// `robot:` and `cycle_s:`, the record the config is for.
void load_record_keys(const ConfigNode& root, IdentificationConfig& c) {
  c.file = root.file();
  if (const auto robot = root.optional_child("robot")) {
    c.robot = robot->as_string();
    c.key_lines["robot"] = robot->line();
  }
  if (const auto cycle = root.optional_child("cycle_s")) {
    c.counts_cycle_s = cycle->as_double();
    if (!(c.counts_cycle_s > 0.0 && c.counts_cycle_s <= 1.0)) cycle->fail("must be in (0, 1] s");
    c.key_lines["cycle_s"] = cycle->line();
    c.resolved_cycle_s = c.counts_cycle_s;
  }
}

}  // namespace

CellGrid IdentificationConfig::joint_grid(std::size_t joint) const {
  if (joint >= max_speed_rad_s.size())
    throw std::invalid_argument(fmt::format(
        "identification config: no maximum speed for joint {} (joints.max_speed_deg_s has {})",
        joint + 1, max_speed_rad_s.size()));
  std::vector<CellDimension> dims;
  dims.push_back(
      {OperatingQuantity::kSpeed, scaled(speed_fraction_bounds, max_speed_rad_s[joint])});
  dims.push_back(
      {OperatingQuantity::kPayload, scaled(payload_fraction_bounds, nominal_payload_kg)});
  for (const auto& e : extra_dimensions) dims.push_back({e.quantity, e.bounds_si});
  return CellGrid(std::move(dims));
}

double IdentificationConfig::transmission_error_harmonic(std::size_t joint) const {
  return joint < transmission_error_harmonic_per_joint.size()
             ? transmission_error_harmonic_per_joint[joint]
             : transmission_error_harmonic_per_motor_rev;
}

JointIdentificationOptions IdentificationConfig::joint_options(std::size_t joint) const {
  JointIdentificationOptions o = options;
  if (o.transmission_error_input) {
    if (joint >= gear_ratio.size())
      throw std::invalid_argument(fmt::format(
          "identification config: no gear ratio for joint {} (joints.gear_ratio has {})", joint + 1,
          gear_ratio.size()));
    o.transmission_error_rad_per_rad = transmission_error_harmonic(joint) * gear_ratio[joint];
    // A joint without a second harmonic (0, or none given) is identified without the pair; the
    // table then gives it zero coefficients for it (pad_absent_second_transmission_error).
    const double second = joint < transmission_error_second_harmonic_per_joint.size()
                              ? transmission_error_second_harmonic_per_joint[joint]
                              : 0.0;
    o.second_transmission_error_input = o.second_transmission_error_input && second > 0.0;
    o.transmission_error_2_rad_per_rad =
        o.second_transmission_error_input ? second * gear_ratio[joint] : 0.0;
    if (joint < gear_stiffness_nm_per_rad.size())
      o.transmission_error_compliance_rad_per_nm = 1.0 / gear_stiffness_nm_per_rad[joint];
    if (joint < transmission_error_mode_rad_s.size() &&
        joint < transmission_error_mode_damping.size()) {
      o.transmission_error_mode_rad_s = transmission_error_mode_rad_s[joint];
      o.transmission_error_mode_damping = transmission_error_mode_damping[joint];
    }
    // Beside the plain pairs, a joint without a mode would repeat them: it is identified without
    // the gear-mode pairs (zero coefficients in the table, as for an absent second order).
    if (o.transmission_error_mode_pairs == GearModePairs::kBeside &&
        !(o.transmission_error_mode_rad_s > 0.0))
      o.transmission_error_mode_pairs = GearModePairs::kNone;
  }
  return o;
}

IdentificationConfig load_identification_config(const ConfigNode& root) {
  root.require_only_keys({"imscal-identification-config", "robot", "cycle_s", "joints", "cells",
                          "model", "order", "validation", "stability_margin", "backlash"});
  if (root.child("imscal-identification-config").as_int() != 1)
    root.child("imscal-identification-config").fail("unknown config version; expected 1");
  IdentificationConfig c;
  auto& o = c.options;
  load_record_keys(root, c);

  const ConfigNode joints = root.child("joints");
  joints.require_only_keys(
      {"max_speed_deg_s", "nominal_payload_kg", "gear_ratio", "gear_stiffness_nm_per_rad"});
  c.max_speed_rad_s = scaled(joints.child("max_speed_deg_s").as_doubles(), kRadPerDeg);
  for (double v : c.max_speed_rad_s)
    if (!(v > 0.0)) joints.child("max_speed_deg_s").fail("every maximum speed must be > 0");
  c.gear_ratio = per_joint_positive(joints, "gear_ratio", c.max_speed_rad_s.size(), "gear ratio");
  c.gear_stiffness_nm_per_rad = per_joint_positive(joints, "gear_stiffness_nm_per_rad",
                                                   c.max_speed_rad_s.size(), "stiffness");
  c.nominal_payload_kg = joints.child("nominal_payload_kg").as_double();
  if (!(c.nominal_payload_kg > 0.0))
    joints.child("nominal_payload_kg").fail("nominal payload must be > 0");

  if (auto cells = root.optional_child("cells")) {
    cells->require_only_keys({"speed_fraction_bounds", "payload_fraction_bounds", "extra",
                              "min_rows", "min_estimation_s", "min_rms_speed_deg_s"});
    c.durations.min_estimation_s =
        duration_instead_of_count(*cells, "cells", "min_estimation_s", "min_rows", c);
    if (auto n = cells->optional_child("speed_fraction_bounds")) {
      c.speed_fraction_bounds = n->as_doubles();
      check_increasing(*n, c.speed_fraction_bounds);
    }
    if (auto n = cells->optional_child("payload_fraction_bounds")) {
      c.payload_fraction_bounds = n->as_doubles();
      check_increasing(*n, c.payload_fraction_bounds);
    }
    if (auto extra = cells->optional_child("extra")) {
      for (const ConfigNode& e : extra->as_sequence()) {
        e.require_only_keys({"quantity", "bounds_deg", "bounds_deg_s2"});
        const std::string q = e.child("quantity").as_string();
        ExtraDimension d;
        if (q == "position") {
          d.quantity = OperatingQuantity::kPosition;
          if (e.has("bounds_deg_s2")) e.child("bounds_deg_s2").fail("position bounds: bounds_deg");
          d.bounds_si = scaled(e.child("bounds_deg").as_doubles(), kRadPerDeg);
          check_increasing(e.child("bounds_deg"), d.bounds_si);
        } else if (q == "acceleration") {
          d.quantity = OperatingQuantity::kAcceleration;
          if (e.has("bounds_deg")) e.child("bounds_deg").fail("acceleration bounds: bounds_deg_s2");
          d.bounds_si = scaled(e.child("bounds_deg_s2").as_doubles(), kRadPerDeg);
          check_increasing(e.child("bounds_deg_s2"), d.bounds_si);
        } else {
          e.child("quantity").fail("extra dimension must be 'position' or 'acceleration'");
        }
        c.extra_dimensions.push_back(std::move(d));
      }
    }
    const long min_rows = cells->get_int("min_rows", long(o.min_rows_per_cell));
    if (min_rows < 1) cells->child("min_rows").fail("must be >= 1");
    o.min_rows_per_cell = std::size_t(min_rows);
    o.min_rms_speed_rad_s =
        cells->get_double("min_rms_speed_deg_s", o.min_rms_speed_rad_s / kRadPerDeg) * kRadPerDeg;
  }
  if (auto model = root.optional_child("model")) {
    model->require_only_keys({"form",
                              "preview_cycles",
                              "preview_s",
                              "model_torque",
                              "direction",
                              "direction_speed_scale_deg_s",
                              "torque_sign",
                              "torque_sign_scale_fraction",
                              "input_taps",
                              "input_history_s",
                              "torque_sign_taps",
                              "torque_sign_history_s",
                              "transmission_error",
                              "transmission_error_harmonic_per_motor_rev",
                              "transmission_error_taps",
                              "transmission_error_history_s",
                              "transmission_error_gear_mode",
                              "transmission_error_gear_mode_pairs",
                              "transmission_error_gear_mode_taps",
                              "transmission_error_gear_mode_history_s",
                              "refine_mass_parameters",
                              "refine_gravity"});
    ConfigDurations& d = c.durations;
    d.preview_s = duration_instead_of_count(*model, "model", "preview_s", "preview_cycles", c);
    d.input_history_s =
        duration_instead_of_count(*model, "model", "input_history_s", "input_taps", c);
    d.torque_sign_history_s =
        duration_instead_of_count(*model, "model", "torque_sign_history_s", "torque_sign_taps", c);
    d.transmission_error_history_s = duration_instead_of_count(
        *model, "model", "transmission_error_history_s", "transmission_error_taps", c);
    d.transmission_error_gear_mode_history_s =
        duration_instead_of_count(*model, "model", "transmission_error_gear_mode_history_s",
                                  "transmission_error_gear_mode_taps", c);
    if (auto n = model->optional_child("form")) {
      try {
        o.form = arx_model_form_from_string(n->as_string());
      } catch (const std::invalid_argument& e) {
        n->fail(e.what());
      }
    }
    o.preview_cycles = int(model->get_int("preview_cycles", o.preview_cycles));
    if (o.preview_cycles < 0 || o.preview_cycles > 32)
      model->child("preview_cycles").fail("must be in 0..32 cycles");
    if ((o.preview_cycles > 0 || d.preview_s > 0.0) && o.form != ArxModelForm::kInverse)
      model->child(model->has("preview_s") ? "preview_s" : "preview_cycles")
          .fail("a preview is used only by the inverse form");
    o.model_torque_input = model->get_bool("model_torque", o.model_torque_input);
    o.direction_input = model->get_bool("direction", o.direction_input);
    o.direction_speed_scale_rad_s = model->get_double("direction_speed_scale_deg_s",
                                                      o.direction_speed_scale_rad_s / kRadPerDeg) *
                                    kRadPerDeg;
    if (!(o.direction_speed_scale_rad_s > 0.0))
      model->child("direction_speed_scale_deg_s").fail("must be > 0");
    o.torque_sign_input = model->get_bool("torque_sign", o.torque_sign_input);
    o.torque_sign_scale_fraction =
        model->get_double("torque_sign_scale_fraction", o.torque_sign_scale_fraction);
    if (!(o.torque_sign_scale_fraction > 0.0 && o.torque_sign_scale_fraction <= 1.0))
      model->child("torque_sign_scale_fraction").fail("must be in (0, 1] of the RMS torque");
    if (o.torque_sign_input && !o.model_torque_input)
      model->child("torque_sign").fail("the torque-sign input needs model_torque: true");
    c.refine_mass_parameters = model->get_bool("refine_mass_parameters", false);
    if (c.refine_mass_parameters && !o.model_torque_input)
      model->child("refine_mass_parameters").fail("refines the model torque: needs model_torque");
    c.refine_gravity = model->get_bool("refine_gravity", false);
    if (c.refine_gravity && !o.model_torque_input)
      model->child("refine_gravity").fail("refines the model torque: needs model_torque");
    if (c.refine_gravity && c.refine_mass_parameters)
      model->child("refine_gravity").fail("refine_mass_parameters refines the gravity already");
    o.input_taps = int(model->get_int("input_taps", o.input_taps));
    if (o.input_taps < 1 || o.input_taps > 64)
      model->child("input_taps").fail("must be in 1..64 coefficients per further input");
    o.torque_sign_taps = int(model->get_int("torque_sign_taps", o.torque_sign_taps));
    if (o.torque_sign_taps < 1 || o.torque_sign_taps > 64)
      model->child("torque_sign_taps").fail("must be in 1..64 coefficients");
    o.transmission_error_input = model->get_bool("transmission_error", false);
    if (o.transmission_error_input && c.gear_ratio.empty())
      model->child("transmission_error")
          .fail(
              "the transmission-error inputs need joints.gear_ratio (their phase advances "
              "harmonic x gear ratio per rad of joint angle)");
    if (o.transmission_error_input && !c.gear_stiffness_nm_per_rad.empty() && !o.model_torque_input)
      model->child("transmission_error")
          .fail(
              "the transmission error's phase with the gear's deflection (joints."
              "gear_stiffness_nm_per_rad) needs model_torque: true");
    c.transmission_error_gear_mode = model->get_bool("transmission_error_gear_mode", false);
    if (c.transmission_error_gear_mode && !(o.transmission_error_input && o.model_torque_input))
      model->child("transmission_error_gear_mode")
          .fail(
              "the gear mode is the transmission error's, its inertia the rigid-body model's: "
              "needs transmission_error: true and model_torque: true");
    load_gear_mode_pairs(*model, c);
    // One harmonic for every joint, or a list with one per joint.
    if (const auto harmonic = model->optional_child("transmission_error_harmonic_per_motor_rev")) {
      if (harmonic->is_sequence()) {
        c.transmission_error_harmonic_per_joint = harmonic->as_doubles();
        if (c.transmission_error_harmonic_per_joint.size() != c.max_speed_rad_s.size())
          harmonic->fail(
              fmt::format("expected one harmonic per joint ({})", c.max_speed_rad_s.size()));
        for (double h : c.transmission_error_harmonic_per_joint)
          if (!(h > 0.0)) harmonic->fail("every harmonic must be > 0");
      } else {
        c.transmission_error_harmonic_per_motor_rev = harmonic->as_double();
        if (!(c.transmission_error_harmonic_per_motor_rev > 0.0)) harmonic->fail("must be > 0");
      }
    }
    o.transmission_error_taps =
        int(model->get_int("transmission_error_taps", o.transmission_error_taps));
    if (o.transmission_error_taps < 1 || o.transmission_error_taps > 64)
      model->child("transmission_error_taps").fail("must be in 1..64 coefficients");
    if (extra_input_count(o) > kMaxExtraInputs)
      model->fail(
          fmt::format("at most {} further inputs (each transmission-error pair counts twice)",
                      kMaxExtraInputs));
  }
  if (auto order = root.optional_child("order")) {
    order->require_only_keys({"na", "nb", "dead_time", "criterion"});
    if (auto n = order->optional_child("na"))
      std::tie(o.grid.na_min, o.grid.na_max) = range(*n, 0, kMaxPrecontrolOrder);
    if (auto n = order->optional_child("nb"))
      std::tie(o.grid.nb_min, o.grid.nb_max) = range(*n, 1, kMaxPrecontrolOrder);
    if (auto n = order->optional_child("dead_time"))
      std::tie(o.grid.dead_time_min, o.grid.dead_time_max) = range(*n, 0, kMaxPrecontrolOrder);
    if (auto n = order->optional_child("criterion")) {
      const std::string name = n->as_string();
      if (name == "aic")
        o.criterion = OrderCriterion::kAic;
      else if (name == "bic")
        o.criterion = OrderCriterion::kBic;
      else if (name == "validation")
        o.criterion = OrderCriterion::kValidation;
      else
        n->fail("criterion must be aic, bic or validation");
    }
  }
  // Durations in counts of the config's cycle (2 ms if it names none) until a record's is known.
  apply_durations(c, c.resolved_cycle_s);
  // The exported table must load into the precontrol (ident/precontrol.hpp): a further input's
  // coefficients move behind the dead time when the model is written in the angle form, so
  // taps + largest dead time must fit the runtime's kMaxPrecontrolOrder per input.
  if (o.model_torque_input || o.direction_input || o.transmission_error_input) {
    const int taps = longest_extra_input_taps(o);
    const int longest = taps + o.grid.dead_time_max;
    if (longest > kMaxPrecontrolOrder) {
      const ConfigNode at =
          root.optional_child("model") && root.child("model").optional_child("input_taps")
              ? root.child("model").child("input_taps")
              : root.child("order").child("dead_time");
      at.fail(fmt::format(
          "model.input_taps ({}) plus the largest dead time (order.dead_time max {}) is {} "
          "coefficients per further input; the precontrol holds at most {}",
          taps, o.grid.dead_time_max, longest, kMaxPrecontrolOrder));
    }
  }
  if (auto v = root.optional_child("validation")) {
    v->require_only_keys({"fraction", "block_s", "max_lag", "band_z"});
    o.validation_fraction = v->get_double("fraction", o.validation_fraction);
    if (!(o.validation_fraction > 0.0 && o.validation_fraction < 1.0))
      v->child("fraction").fail("held-out fraction must be in (0, 1)");
    o.validation_block_s = v->get_double("block_s", o.validation_block_s);
    if (!(o.validation_block_s >= 0.0)) v->child("block_s").fail("must be >= 0 (0: whole runs)");
    o.validation.max_lag = int(v->get_int("max_lag", o.validation.max_lag));
    if (o.validation.max_lag < 1) v->child("max_lag").fail("must be >= 1");
    o.validation.band_z = v->get_double("band_z", o.validation.band_z);
    if (!(o.validation.band_z > 0.0)) v->child("band_z").fail("must be > 0");
  }
  o.stability_margin = root.get_double("stability_margin", o.stability_margin);
  if (!(o.stability_margin >= 0.0 && o.stability_margin < 1.0))
    root.child("stability_margin").fail("must be in [0, 1)");
  if (auto b = root.optional_child("backlash")) {
    b->require_only_keys(
        {"enabled", "min_speed_deg_s", "max_lag_s", "settle_s", "window_s", "min_reversals"});
    o.identify_backlash = b->get_bool("enabled", o.identify_backlash);
    auto& bl = o.backlash;
    bl.min_speed_rad_s =
        b->get_double("min_speed_deg_s", bl.min_speed_rad_s / kRadPerDeg) * kRadPerDeg;
    bl.max_lag_s = b->get_double("max_lag_s", bl.max_lag_s);
    bl.settle_s = b->get_double("settle_s", bl.settle_s);
    bl.window_s = b->get_double("window_s", bl.window_s);
    bl.min_reversals = int(b->get_int("min_reversals", bl.min_reversals));
    if (!(bl.min_speed_rad_s >= 0.0)) b->child("min_speed_deg_s").fail("must be >= 0");
    if (!(bl.max_lag_s >= 0.0)) b->child("max_lag_s").fail("must be >= 0");
    if (!(bl.settle_s >= 0.0)) b->child("settle_s").fail("must be >= 0");
    if (!(bl.window_s > 0.0)) b->child("window_s").fail("must be > 0");
    if (bl.min_reversals < 2) b->child("min_reversals").fail("must be >= 2");
  }
  // The grid of every joint must be valid (bounds, dimension count).
  for (std::size_t j = 0; j < c.max_speed_rad_s.size(); ++j) {
    try {
      (void)c.joint_grid(j);
    } catch (const std::invalid_argument& e) {
      root.child("cells").fail(e.what());
    }
  }
  return c;
}

}  // namespace imscal::ident
