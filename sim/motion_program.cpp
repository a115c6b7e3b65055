#include "sim/motion_program.hpp"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <cmath>

#include "core/config_node.hpp"
#include "core/units.hpp"

namespace imscal::sim {
namespace {

constexpr double kMmToM = 1e-3;

calib::JointVector read_joints(const ConfigNode& node, double scale, bool positive) {
  const std::vector<double> v = node.as_doubles();
  if (v.size() != calib::kJointCount) {
    node.fail(
        fmt::format("expected {} numbers (one per joint), got {}", calib::kJointCount, v.size()));
  }
  calib::JointVector out;
  for (int i = 0; i < calib::kJointCount; ++i) {
    if (positive && !(v[i] > 0.0)) {
      node.fail(fmt::format("joint A{}: {} must be positive", i + 1, v[i]));
    }
    out(i) = v[i] * scale;
  }
  return out;
}

double positive(const ConfigNode& node) {
  const double v = node.as_double();
  if (!(v > 0.0)) node.fail(fmt::format("must be positive, got {}", v));
  return v;
}

double fraction(const ConfigNode& parent, std::string_view key) {
  const auto node = parent.optional_child(key);
  if (!node) return 1.0;
  const double v = node->as_double();
  if (!(v > 0.0 && v <= 1.0)) node->fail(fmt::format("must lie in (0, 1], got {}", v));
  return v;
}

ProfileKind read_profile(const ConfigNode& node) {
  const std::string s = node.as_string();
  if (s == "trapezoidal") return ProfileKind::kTrapezoidal;
  if (s == "jerk_limited") return ProfileKind::kJerkLimited;
  node.fail(fmt::format("unknown profile '{}' (trapezoidal or jerk_limited)", s));
}

Payload read_payload(const ConfigNode& node) {
  node.require_only_keys({"name", "mass_kg", "com_m", "inertia_kg_m2"});
  Payload p;
  p.name = node.child("name").as_string();
  p.body.mass_kg = node.child("mass_kg").as_double();
  if (p.body.mass_kg < 0.0) node.child("mass_kg").fail("mass must not be negative");
  if (auto c = node.optional_child("com_m")) p.body.com_m = c->as_vector3();
  if (auto c = node.optional_child("inertia_kg_m2")) {
    const std::vector<double> v = c->as_doubles();
    if (v.size() != 6) c->fail("expected [ixx, iyy, izz, ixy, ixz, iyz]");
    p.body.inertia_kg_m2 << v[0], v[3], v[4], v[3], v[1], v[5], v[4], v[5], v[2];
    const Eigen::Vector3d principal =
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(p.body.inertia_kg_m2).eigenvalues();
    if (principal.minCoeff() < 0.0) c->fail("inertia tensor is not positive semi-definite");
  }
  return p;
}

// {xyz_mm, rpy_deg?} -> position [m] and optional rotation.
void read_cartesian(const ConfigNode& node, Eigen::Vector3d& xyz_m,
                    std::optional<Eigen::Matrix3d>& rotation) {
  node.require_only_keys({"xyz_mm", "rpy_deg"});
  xyz_m = node.child("xyz_mm").as_vector3() * kMmToM;
  if (auto r = node.optional_child("rpy_deg")) {
    rotation =
        calib::pose_from_xyz_rpy(Eigen::Vector3d::Zero(), r->as_vector3() * kRadPerDeg).linear();
  }
}

void read_path_limits(const ConfigNode& node, ProgramStep& step) {
  step.path.velocity_m_s = positive(node.child("velocity_m_s"));
  step.path.acceleration_m_s2 = positive(node.child("acceleration_m_s2"));
  if (auto j = node.optional_child("jerk_m_s3")) step.path.jerk_m_s3 = positive(*j);
  if (step.profile == ProfileKind::kJerkLimited && step.path.jerk_m_s3 == 0.0) {
    node.fail("jerk_m_s3 is required for a jerk_limited profile");
  }
  if (auto o = node.optional_child("orientation")) {
    const std::string s = o->as_string();
    if (s == "constant") {
      step.orientation = OrientationMode::kConstant;
    } else if (s == "slerp") {
      step.orientation = OrientationMode::kSlerp;
    } else {
      o->fail(fmt::format("unknown orientation '{}' (constant or slerp)", s));
    }
  }
}

ProgramStep read_step(const ConfigNode& item, ProfileKind default_profile, std::size_t index) {
  const std::vector<std::string> keys = item.keys();
  if (keys.size() != 1) {
    item.fail("a segment is a map with exactly one key: rest, ptp, lin, circ, circle or payload");
  }
  const std::string kind = keys.front();
  const ConfigNode body = item.child(kind);
  ProgramStep step;
  step.index = index;
  step.line = body.line();
  step.profile = default_profile;
  if (kind != "payload") {
    if (auto p = body.optional_child("profile")) step.profile = read_profile(*p);
    if (auto l = body.optional_child("label")) step.label = l->as_string();
  }
  if (kind == "rest") {
    body.require_only_keys({"duration_s", "label"});
    step.kind = ProgramStepKind::kRest;
    step.duration_s = positive(body.child("duration_s"));
  } else if (kind == "ptp") {
    body.require_only_keys(
        {"joints_deg", "pose", "velocity_scale", "acceleration_scale", "profile", "label"});
    step.kind = ProgramStepKind::kPtp;
    if (body.has("joints_deg") == body.has("pose")) {
      body.fail("give exactly one target: joints_deg or pose");
    }
    if (auto j = body.optional_child("joints_deg")) {
      step.target_joints_rad = read_joints(*j, kRadPerDeg, false);
    } else {
      const ConfigNode pose = body.child("pose");
      pose.require_only_keys({"xyz_mm", "rpy_deg"});
      Eigen::Isometry3d T =
          calib::pose_from_xyz_rpy(pose.child("xyz_mm").as_vector3() * kMmToM,
                                   pose.child("rpy_deg").as_vector3() * kRadPerDeg);
      step.target_pose = T;
    }
    step.velocity_scale = fraction(body, "velocity_scale");
    step.acceleration_scale = fraction(body, "acceleration_scale");
  } else if (kind == "lin") {
    body.require_only_keys({"to", "by", "velocity_m_s", "acceleration_m_s2", "jerk_m_s3",
                            "orientation", "profile", "label"});
    step.kind = ProgramStepKind::kLinear;
    if (body.has("to") == body.has("by")) body.fail("give exactly one target: to or by");
    if (auto to = body.optional_child("to")) {
      read_cartesian(*to, step.target_m, step.target_rotation);
    } else {
      const ConfigNode by = body.child("by");
      by.require_only_keys({"xyz_mm"});
      step.target_m = by.child("xyz_mm").as_vector3() * kMmToM;
      step.target_is_offset = true;
    }
    read_path_limits(body, step);
  } else if (kind == "circ") {
    body.require_only_keys({"via_mm", "to", "velocity_m_s", "acceleration_m_s2", "jerk_m_s3",
                            "orientation", "profile", "label"});
    step.kind = ProgramStepKind::kCircleThroughVia;
    step.via_m = body.child("via_mm").as_vector3() * kMmToM;
    read_cartesian(body.child("to"), step.target_m, step.target_rotation);
    read_path_limits(body, step);
  } else if (kind == "circle") {
    body.require_only_keys({"centre_mm", "normal", "radius_mm", "angle_deg", "velocity_m_s",
                            "acceleration_m_s2", "jerk_m_s3", "profile", "label"});
    step.kind = ProgramStepKind::kCircleAboutCentre;
    step.centre_m = body.child("centre_mm").as_vector3() * kMmToM;
    const ConfigNode normal = body.child("normal");
    step.normal = normal.as_vector3();
    if (!(step.normal.norm() > 1e-12)) normal.fail("normal must not be zero");
    step.normal.normalize();
    step.radius_m = positive(body.child("radius_mm")) * kMmToM;
    if (auto a = body.optional_child("angle_deg")) {
      step.angle_rad = a->as_double() * kRadPerDeg;
      if (step.angle_rad == 0.0) a->fail("angle must not be zero");
    }
    read_path_limits(body, step);
  } else if (kind == "payload") {
    step.kind = ProgramStepKind::kPayload;
    step.payload = read_payload(body);
    step.label = "payload " + step.payload.name;
  } else {
    item.fail(
        fmt::format("unknown segment kind '{}' (rest, ptp, lin, circ, circle, payload)", kind));
  }
  if (step.label.empty()) step.label = fmt::format("{} {}", kind, index);
  if (step.kind == ProgramStepKind::kLinear || step.kind == ProgramStepKind::kCircleThroughVia) {
    if (step.orientation == OrientationMode::kSlerp && !step.target_rotation) {
      body.fail("orientation: slerp needs the target orientation (to.rpy_deg)");
    }
  }
  return step;
}

}  // namespace

const char* to_string(ProgramStepKind kind) {
  switch (kind) {
    case ProgramStepKind::kRest:
      return "rest";
    case ProgramStepKind::kPtp:
      return "ptp";
    case ProgramStepKind::kLinear:
      return "lin";
    case ProgramStepKind::kCircleThroughVia:
      return "circ";
    case ProgramStepKind::kCircleAboutCentre:
      return "circle";
    case ProgramStepKind::kPayload:
      return "payload";
  }
  return "?";
}

MotionProgram load_motion_program(const std::filesystem::path& file) {
  return parse_motion_program(ConfigNode::load_file(file));
}

MotionProgram parse_motion_program(const ConfigNode& root) {
  root.require_only_keys({"name", "start_joints_deg", "profile", "joint_acceleration_deg_s2",
                          "joint_jerk_deg_s3", "payload", "segments"});
  MotionProgram program;
  program.source = root.file();
  program.name = root.child("name").as_string();
  program.start_joints_rad = read_joints(root.child("start_joints_deg"), kRadPerDeg, false);
  if (auto p = root.optional_child("profile")) program.default_profile = read_profile(*p);
  program.max_acceleration_rad_s2 =
      read_joints(root.child("joint_acceleration_deg_s2"), kRadPerDeg, true);
  if (auto j = root.optional_child("joint_jerk_deg_s3")) {
    program.max_jerk_rad_s3 = read_joints(*j, kRadPerDeg, true);
  }
  program.initial_payload.name = "none";
  if (auto p = root.optional_child("payload")) program.initial_payload = read_payload(*p);
  const std::vector<ConfigNode> items = root.child("segments").as_sequence();
  if (items.empty()) root.child("segments").fail("the program has no segments");
  for (std::size_t i = 0; i < items.size(); ++i) {
    ProgramStep step = read_step(items[i], program.default_profile, i);
    if (step.kind == ProgramStepKind::kPtp && step.profile == ProfileKind::kJerkLimited &&
        !program.max_jerk_rad_s3) {
      items[i].fail("a jerk_limited ptp move needs joint_jerk_deg_s3 at the top of the program");
    }
    if (step.kind == ProgramStepKind::kPayload && i > 0 &&
        program.steps.back().kind != ProgramStepKind::kRest &&
        program.steps.back().kind != ProgramStepKind::kPayload) {
      items[i].fail(
          "a payload change is allowed only at rest: put it at the start or after a rest segment");
    }
    program.steps.push_back(std::move(step));
  }
  return program;
}

}  // namespace imscal::sim
