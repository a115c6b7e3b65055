#include "tools/run_config.hpp"

#include "core/input_error.hpp"

namespace imscal::tools {

namespace fs = std::filesystem;

namespace {
double positive(const ConfigNode& node) {
  const double value = node.as_double();
  if (!(value > 0.0)) node.fail("must be > 0");
  return value;
}

// A scenario as a stage names it: a shipped scenario's name (datasets/scenarios/NAME.yaml) as
// given, or a .yaml file (must exist; appended to `files`, checksummed as an input).
std::string scenario_reference(const ConfigNode& item, std::vector<fs::path>& files) {
  const std::string name = item.as_string();
  if (name.ends_with(".yaml")) {
    files.push_back(item.as_existing_file());
    return files.back().string();
  }
  if (name.empty() || name.find('/') != std::string::npos)
    item.fail("a shipped scenario name (datasets/scenarios/NAME.yaml) or a .yaml file");
  return name;
}

}  // namespace

RunConfig load_run_config(const fs::path& file) {
  const ConfigNode root = ConfigNode::load_file(file);
  if (!root.is_map()) root.fail("the run config must be a map of keys");
  root.require_only_keys({"imscal-run-config", "title", "inputs", "validate", "calibrate",
                          "identify", "verify", "diagnose", "report"});
  if (root.child("imscal-run-config").as_int() != 1)
    root.child("imscal-run-config").fail("only version 1 is known");
  RunConfig config;
  config.file = fs::absolute(file).lexically_normal();
  config.title = root.get_string("title", "imscal calibration run");

  const ConfigNode inputs = root.child("inputs");
  inputs.require_only_keys({"imu", "robot_log", "joint_errors"});
  if (auto n = inputs.optional_child("imu")) config.imu = n->as_existing_file();
  if (auto n = inputs.optional_child("robot_log")) config.robot_log = n->as_existing_file();
  if (auto n = inputs.optional_child("joint_errors")) config.joint_errors = n->as_existing_file();
  if (!config.imu && !config.robot_log && !config.joint_errors)
    inputs.fail("names no input (imu, robot_log, joint_errors): nothing to run");

  if (auto v = root.optional_child("validate")) {
    v->require_only_keys({"robot", "min_overlap_s", "allow_imu_gaps"});
    config.validate.robot = v->get_string("robot", "");
    if (auto n = v->optional_child("min_overlap_s")) config.validate.min_overlap_s = positive(*n);
    config.validate.allow_imu_gaps = v->get_bool("allow_imu_gaps", false);
  }
  if (auto c = root.optional_child("calibrate")) {
    c->require_only_keys({"config", "timeout_s"});
    if (!config.imu || !config.robot_log)
      c->fail("a calibrate section needs inputs.imu and inputs.robot_log");
    CalibrateSettings settings;
    settings.config = c->child("config").as_existing_file();
    if (auto n = c->optional_child("timeout_s")) settings.timeout_s = positive(*n);
    config.calibrate = settings;
  }
  if (auto i = root.optional_child("identify")) {
    i->require_only_keys({"config", "robot", "timeout_s"});
    if (!config.joint_errors && !config.calibrate)
      i->fail("an identify section needs joint errors: inputs.joint_errors or a calibrate section");
    IdentifySettings settings;
    settings.config = i->child("config").as_existing_file();
    if (auto n = i->optional_child("robot")) settings.robot = n->as_existing_file();
    if (auto n = i->optional_child("timeout_s")) settings.timeout_s = positive(*n);
    config.identify = settings;
  } else if (config.joint_errors) {
    inputs.child("joint_errors")
        .fail("joint errors are given but there is no identify section (identify.config)");
  }
  if (auto v = root.optional_child("verify")) {
    v->require_only_keys({"scenarios", "cycles", "timeout_s"});
    if (!config.identify) v->fail("a verify section needs an identify section (the table)");
    VerifySettings settings;
    if (auto list = v->optional_child("scenarios")) {
      settings.scenarios.clear();
      for (const ConfigNode& item : list->as_sequence())
        settings.scenarios.push_back(scenario_reference(item, settings.scenario_files));
      if (settings.scenarios.empty()) list->fail("names no scenario");
    }
    if (auto n = v->optional_child("cycles")) {
      const long cycles = n->as_int();
      if (cycles < 1 || cycles > 100) n->fail("must be in [1, 100]");
      settings.cycles = static_cast<int>(cycles);
    }
    if (auto n = v->optional_child("timeout_s")) settings.timeout_s = positive(*n);
    config.verify = settings;
  }
  if (auto d = root.optional_child("diagnose")) {
    d->require_only_keys({"robot", "scenario", "timeout_s"});
    if (!config.identify) d->fail("a diagnose section needs an identify section (the table)");
    DiagnoseSettings settings;
    settings.robot = d->child("robot").as_existing_file();
    if (auto n = d->optional_child("scenario")) {
      std::vector<fs::path> files;
      settings.scenario = scenario_reference(*n, files);
      if (!files.empty()) settings.scenario_file = files.front();
    }
    if (auto n = d->optional_child("timeout_s")) settings.timeout_s = positive(*n);
    config.diagnose = settings;
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
