#include "tools/run_config.hpp"

#include <fmt/format.h>

#include "core/input_error.hpp"

namespace imscal::tools {

namespace fs = std::filesystem;

namespace {
// A path value, resolved against the config's folder; the file must exist.
fs::path existing_file(const ConfigNode& node, const fs::path& base) {
  const std::string text = node.as_string();
  if (text.empty()) node.fail("an empty path");
  const fs::path path = fs::absolute(base / text).lexically_normal();
  if (!fs::is_regular_file(path)) node.fail(fmt::format("'{}' is not a file", path.string()));
  return path;
}

double positive(const ConfigNode& node) {
  const double value = node.as_double();
  if (!(value > 0.0)) node.fail("must be > 0");
  return value;
}
}  // namespace

RunConfig load_run_config(const fs::path& file) {
  const ConfigNode root = ConfigNode::load_file(file);
  if (!root.is_map()) root.fail("the run config must be a map of keys");
  root.require_only_keys(
      {"imscal-run-config", "title", "inputs", "validate", "identify", "report"});
  if (root.child("imscal-run-config").as_int() != 1)
    root.child("imscal-run-config").fail("only version 1 is known");
  RunConfig config;
  config.file = fs::absolute(file).lexically_normal();
  const fs::path base = config.file.parent_path();
  config.title = root.get_string("title", "imscal calibration run");

  const ConfigNode inputs = root.child("inputs");
  inputs.require_only_keys({"imu", "robot_log", "joint_errors"});
  if (auto n = inputs.optional_child("imu")) config.imu = existing_file(*n, base);
  if (auto n = inputs.optional_child("robot_log")) config.robot_log = existing_file(*n, base);
  if (auto n = inputs.optional_child("joint_errors")) config.joint_errors = existing_file(*n, base);
  if (!config.imu && !config.robot_log && !config.joint_errors)
    inputs.fail("names no input (imu, robot_log, joint_errors): nothing to run");

  if (auto v = root.optional_child("validate")) {
    v->require_only_keys({"robot", "min_overlap_s", "allow_imu_gaps"});
    config.validate.robot = v->get_string("robot", "");
    if (auto n = v->optional_child("min_overlap_s")) config.validate.min_overlap_s = positive(*n);
    config.validate.allow_imu_gaps = v->get_bool("allow_imu_gaps", false);
  }
  if (auto i = root.optional_child("identify")) {
    i->require_only_keys({"config", "timeout_s"});
    if (!config.joint_errors)
      i->fail("an identify section needs inputs.joint_errors (the data to identify from)");
    IdentifySettings settings;
    settings.config = existing_file(i->child("config"), base);
    if (auto n = i->optional_child("timeout_s")) settings.timeout_s = positive(*n);
    config.identify = settings;
  } else if (config.joint_errors) {
    inputs.child("joint_errors")
        .fail("joint errors are given but there is no identify section (identify.config)");
  }
  if (auto r = root.optional_child("report")) {
    r->require_only_keys({"gnuplot_timeout_s", "max_points_per_curve"});
    if (auto n = r->optional_child("gnuplot_timeout_s"))
      config.report.gnuplot_timeout_s = positive(*n);
    if (auto n = r->optional_child("max_points_per_curve")) {
      const long points = n->as_int();
      if (points < 10 || points > 1000000) n->fail("must be in [10, 1000000]");
      config.report.max_points_per_curve = static_cast<int>(points);
    }
  }
  return config;
}

}  // namespace imscal::tools
