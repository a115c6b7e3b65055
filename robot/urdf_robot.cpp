#include "robot/urdf_robot.hpp"

#include <fmt/format.h>

#include <console_bridge/console.h>
#include <urdf_parser/urdf_parser.h>
#include <algorithm>
#include <fstream>
#include <optional>
#include <sstream>
#include <vector>

#include "core/config_node.hpp"
#include "core/input_error.hpp"

namespace imscal::calib {
namespace {

// Two axes closer to parallel than this (sine of their angle) are treated as parallel, and two
// lines closer than kTouchM [m] as intersecting: far below any machined length, far above the
// rounding of a URDF's printed numbers.
constexpr double kParallelSine = 1e-9;
constexpr double kTouchM = 1e-9;

// The 1-based line of `name="<name>"` in the URDF text (0 if not found): urdfdom gives no lines.
std::size_t line_of_name(const std::string& text, const std::string& name) {
  const std::size_t at = text.find("name=\"" + name + "\"");
  if (at == std::string::npos) return 0;
  return 1 + static_cast<std::size_t>(std::count(text.begin(), text.begin() + at, '\n'));
}

std::string read_text(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw InputError(file.string(), 0, "", "cannot open the URDF file");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

Eigen::Isometry3d to_isometry(const urdf::Pose& pose) {
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.linear() =
      Eigen::Quaterniond(pose.rotation.w, pose.rotation.x, pose.rotation.y, pose.rotation.z)
          .normalized()
          .toRotationMatrix();
  out.translation() << pose.position.x, pose.position.y, pose.position.z;
  return out;
}

// A link's inertial with the pose of its link frame in the base at q = 0.
struct BodyPiece {
  Eigen::Isometry3d T_R_link0;
  urdf::InertialSharedPtr inertial;
};

// What the URDF gives besides the chain's geometry.
struct ChainWalk {
  UrdfChain chain;
  std::array<std::vector<BodyPiece>, kJointCount> pieces;  // per moving body 1..6
  std::array<urdf::JointLimitsSharedPtr, kJointCount> limits;
  std::array<bool, kJointCount> continuous{};
};

// urdfdom reports through console_bridge; its errors are collected for the InputError instead of
// going to stderr, its warnings and notes are dropped.
class CollectErrors : public console_bridge::OutputHandler {
 public:
  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (level < console_bridge::CONSOLE_BRIDGE_LOG_ERROR) return;
    if (!errors.empty()) errors += "; ";
    errors += text;
  }
  std::string errors;
};

urdf::ModelInterfaceSharedPtr parse_collecting_errors(const std::string& text,
                                                      std::string& errors) {
  CollectErrors collect;
  console_bridge::useOutputHandler(&collect);
  urdf::ModelInterfaceSharedPtr model = urdf::parseURDF(text);
  console_bridge::restorePreviousOutputHandler();
  errors = collect.errors;
  return model;
}

class UrdfReader {
 public:
  explicit UrdfReader(const std::filesystem::path& file) : file_(file), text_(read_text(file)) {
    std::string errors;
    model_ = parse_collecting_errors(text_, errors);
    if (!model_) fail(0, "", "urdfdom could not parse it as a URDF: " + errors);
  }
  [[noreturn]] void fail(std::size_t line, const std::string& field, const std::string& why) const {
    throw InputError(file_.string(), line, field, why);
  }
  [[noreturn]] void fail_at(const std::string& name, const std::string& why) const {
    fail(line_of_name(text_, name), name, why);
  }
  const urdf::ModelInterface& model() const { return *model_; }

 private:
  std::filesystem::path file_;
  std::string text_;
  urdf::ModelInterfaceSharedPtr model_;
};

// The joints from base_link down to tip_link, base first.
std::vector<urdf::JointConstSharedPtr> joints_between(const UrdfReader& reader,
                                                      const std::string& base_link,
                                                      const std::string& tip_link) {
  urdf::LinkConstSharedPtr link = reader.model().getLink(tip_link);
  if (!link) reader.fail(0, tip_link, "the chain's tip link is not in the URDF");
  if (!reader.model().getLink(base_link)) {
    reader.fail(0, base_link, "the chain's base link is not in the URDF");
  }
  std::vector<urdf::JointConstSharedPtr> joints;
  while (link->name != base_link) {
    if (!link->parent_joint) {
      reader.fail_at(tip_link,
                     fmt::format("link '{}' does not hang below '{}'", tip_link, base_link));
    }
    joints.push_back(link->parent_joint);
    link = reader.model().getLink(link->parent_joint->parent_link_name);
  }
  std::reverse(joints.begin(), joints.end());
  return joints;
}

// Adds one moving joint to the walk; `origin` is its origin after the preceding fixed joints.
void add_moving_joint(const UrdfReader& reader, const urdf::Joint& joint, int index,
                      const Eigen::Isometry3d& origin, ChainWalk& walk) {
  if (index >= kJointCount) {
    reader.fail_at(joint.name,
                   fmt::format("the chain has more than {} moving joints", kJointCount));
  }
  const Eigen::Vector3d axis(joint.axis.x, joint.axis.y, joint.axis.z);
  if (!(axis.norm() > 0.5)) reader.fail_at(joint.name, "the joint axis is not a unit vector");
  walk.chain.joint_names[index] = joint.name;
  walk.chain.fixed[index] = origin;
  walk.chain.axis[index] = axis.normalized();
  walk.limits[index] = joint.limits;
  walk.continuous[index] = joint.type == urdf::Joint::CONTINUOUS;
}

ChainWalk walk_chain(const UrdfReader& reader, const std::string& base_link,
                     const std::string& tip_link) {
  ChainWalk walk;
  walk.chain.robot_name = reader.model().getName();
  walk.chain.base_link = base_link;
  walk.chain.tip_link = tip_link;
  Eigen::Isometry3d since_moving = Eigen::Isometry3d::Identity();  // fixed part so far
  Eigen::Isometry3d T_R_link0 = Eigen::Isometry3d::Identity();     // link pose at q = 0
  int moving = 0;
  for (const urdf::JointConstSharedPtr& joint : joints_between(reader, base_link, tip_link)) {
    const Eigen::Isometry3d origin = to_isometry(joint->parent_to_joint_origin_transform);
    since_moving = since_moving * origin;
    T_R_link0 = T_R_link0 * origin;
    if (joint->type == urdf::Joint::REVOLUTE || joint->type == urdf::Joint::CONTINUOUS) {
      add_moving_joint(reader, *joint, moving, since_moving, walk);
      since_moving.setIdentity();
      ++moving;
    } else if (joint->type != urdf::Joint::FIXED) {
      reader.fail_at(joint->name, "only revolute, continuous and fixed joints are supported");
    }
    const urdf::LinkConstSharedPtr child = reader.model().getLink(joint->child_link_name);
    if (moving > 0 && child->inertial) {
      walk.pieces[moving - 1].push_back({T_R_link0, child->inertial});
    }
  }
  if (moving != kJointCount) {
    reader.fail_at(tip_link, fmt::format("the chain {} -> {} has {} moving joints, expected {}",
                                         base_link, tip_link, moving, kJointCount));
  }
  walk.chain.fixed[kJointCount] = since_moving;
  return walk;
}

// --- DH conversion -------------------------------------------------------------------------

struct AxisLine {
  Eigen::Vector3d point;
  Eigen::Vector3d direction;  // unit
};

// A DH frame in the base: origin, x and z (y = z x x).
struct DhFrame {
  Eigen::Vector3d origin;
  Eigen::Vector3d x;
  Eigen::Vector3d z;
  Eigen::Isometry3d pose() const {
    Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
    out.linear().col(0) = x;
    out.linear().col(1) = z.cross(x);
    out.linear().col(2) = z;
    out.translation() = origin;
    return out;
  }
};

// The joint axes in the base at q = 0.
std::array<AxisLine, kJointCount> axis_lines(const UrdfChain& chain) {
  std::array<AxisLine, kJointCount> lines;
  Eigen::Isometry3d joint_frame = Eigen::Isometry3d::Identity();
  for (int i = 0; i < kJointCount; ++i) {
    joint_frame = joint_frame * chain.fixed[i];
    lines[i] = {joint_frame.translation(), (joint_frame.linear() * chain.axis[i]).normalized()};
  }
  return lines;
}

// Frame 0: z along axis 1, origin at the foot of the base origin on it, x as close to the
// base's x as possible (its y if x is along the axis).
DhFrame first_dh_frame(const AxisLine& axis) {
  DhFrame frame;
  frame.z = axis.direction;
  frame.origin = axis.point - frame.z * frame.z.dot(axis.point);
  Eigen::Vector3d x = Eigen::Vector3d::UnitX() - frame.z * frame.z.x();
  if (x.norm() < 1e-6) x = Eigen::Vector3d::UnitY() - frame.z * frame.z.y();
  frame.x = x.normalized();
  return frame;
}

// Frame i from frame i-1 and the axis of joint i+1 (standard DH), with the row A_i.
DhFrame next_dh_frame(const DhFrame& prev, const AxisLine& axis, DhParameters& row) {
  const Eigen::Vector3d& z0 = prev.z;
  const Eigen::Vector3d& z1 = axis.direction;
  const Eigen::Vector3d w = prev.origin - axis.point;
  const Eigen::Vector3d normal = z0.cross(z1);
  const double cosine = z0.dot(z1);
  const bool parallel = normal.norm() < kParallelSine;
  // Closest points of the two lines (for parallel lines: the foot of prev.origin).
  const double t = parallel ? 0.0 : (cosine * z1.dot(w) - z0.dot(w)) / (1.0 - cosine * cosine);
  const double u =
      parallel ? z1.dot(w) : (z1.dot(w) - cosine * z0.dot(w)) / (1.0 - cosine * cosine);
  const Eigen::Vector3d on_prev = prev.origin + t * z0;
  const Eigen::Vector3d on_next = axis.point + u * z1;
  const Eigen::Vector3d gap = on_next - on_prev;
  DhFrame next;
  next.z = z1;
  next.origin = on_next;
  if (gap.norm() > kTouchM) {
    next.x = gap.normalized();
  } else if (!parallel) {
    next.x = normal.normalized();
    if (next.x.dot(prev.x) < 0.0) next.x = -next.x;  // keeps offsets small; either is valid
  } else {
    next.x = prev.x;  // coincident axes
  }
  row.d_m = t;
  row.offset_rad = std::atan2(z0.dot(prev.x.cross(next.x)), prev.x.dot(next.x));
  row.a_m = gap.dot(next.x);
  row.alpha_rad = std::atan2(next.x.dot(normal), cosine);
  return next;
}

// T_R_0, the DH rows and T_6_H of the chain, and the DH frames 0..6 at q = 0. Joint 6 gets a
// zero row: frame 6 is frame 5 turned by q_6.
KinematicModel dh_model_of(const UrdfChain& chain, std::array<DhFrame, kJointCount + 1>& frames) {
  KinematicModel model;
  model.convention = DhConvention::kStandard;
  const std::array<AxisLine, kJointCount> lines = axis_lines(chain);
  frames[0] = first_dh_frame(lines[0]);
  model.T_R_0 = frames[0].pose();
  for (int i = 1; i < kJointCount; ++i) {
    frames[i] = next_dh_frame(frames[i - 1], lines[i], model.dh[i - 1]);
  }
  model.dh[kJointCount - 1] = DhParameters{};
  frames[kJointCount] = frames[kJointCount - 1];
  const Eigen::Isometry3d T_R_tip0 = urdf_chain_pose(chain, JointVector::Zero());
  model.T_6_H = frames[kJointCount].pose().inverse() * T_R_tip0;
  return model;
}

// --- inertials and limits -------------------------------------------------------------------

Eigen::Matrix3d inertia_tensor(const urdf::Inertial& inertial) {
  Eigen::Matrix3d out;
  out << inertial.ixx, inertial.ixy, inertial.ixz, inertial.ixy, inertial.iyy, inertial.iyz,
      inertial.ixz, inertial.iyz, inertial.izz;
  return out;
}

// The pieces of one body as one rigid body in the DH frame T_R_frame0 (all poses at q = 0):
// masses add, the centre of mass is their weighted mean, inertias move by Steiner's theorem.
RigidBodyParameters merged_body(const std::vector<BodyPiece>& pieces,
                                const Eigen::Isometry3d& T_R_frame0) {
  RigidBodyParameters body;
  std::vector<std::pair<Eigen::Vector3d, Eigen::Matrix3d>> in_frame;  // com, inertia
  for (const BodyPiece& piece : pieces) {
    const Eigen::Isometry3d T_frame_inertial =
        T_R_frame0.inverse() * piece.T_R_link0 * to_isometry(piece.inertial->origin);
    const Eigen::Matrix3d& rotation = T_frame_inertial.linear();
    in_frame.emplace_back(T_frame_inertial.translation(),
                          rotation * inertia_tensor(*piece.inertial) * rotation.transpose());
    body.mass_kg += piece.inertial->mass;
    body.com_m += piece.inertial->mass * T_frame_inertial.translation();
  }
  if (body.mass_kg > 0.0) body.com_m /= body.mass_kg;
  for (std::size_t i = 0; i < pieces.size(); ++i) {
    const Eigen::Vector3d r = in_frame[i].first - body.com_m;
    body.inertia_kg_m2 += in_frame[i].second +
                          pieces[i].inertial->mass *
                              (r.squaredNorm() * Eigen::Matrix3d::Identity() - r * r.transpose());
  }
  return body;
}

void fill_limits(const ChainWalk& walk, RobotDescription& robot) {
  for (int i = 0; i < kJointCount; ++i) {
    robot.joints[i].name = walk.chain.joint_names[i];
    const urdf::JointLimitsSharedPtr& limits = walk.limits[i];
    if (limits && !walk.continuous[i]) {
      robot.kinematics.lower_limit_rad(i) = limits->lower;
      robot.kinematics.upper_limit_rad(i) = limits->upper;
    }
    if (limits) robot.joints[i].max_velocity_rad_s = limits->velocity;
  }
}

// An upper bound of the reach: the lengths of the links after joint 1 laid end to end.
double stretched_reach(const KinematicModel& model) {
  double reach = 0.0;
  for (int i = 1; i < kJointCount; ++i) reach += std::hypot(model.dh[i].a_m, model.dh[i].d_m);
  return reach + model.T_6_H.translation().norm();
}

// --- side file ------------------------------------------------------------------------------

void read_side_joints(const ConfigNode& node, RobotDescription& robot) {
  const std::vector<ConfigNode> joints = node.as_sequence();
  if (joints.size() != kJointCount) {
    node.fail(fmt::format("expected {} joints, got {}", kJointCount, joints.size()));
  }
  for (int i = 0; i < kJointCount; ++i) {
    joints[i].require_only_keys({"name", "drive", "controller"});
    if (const auto name = joints[i].optional_child("name")) {
      if (name->as_string() != robot.joints[i].name) {
        name->fail(fmt::format("the URDF's joint {} is '{}'", i + 1, robot.joints[i].name));
      }
    }
    robot.joints[i].drive = read_drive_parameters(joints[i].child("drive"));
    robot.joints[i].controller = read_controller_gains(joints[i].child("controller"));
  }
}

void read_side_tool(const ConfigNode& tool, RobotDescription& robot) {
  tool.require_only_keys({"name", "xyz_m", "rpy_deg", "mass_kg", "com_m", "inertia_kg_m2"});
  robot.tool.name = tool.child("name").as_string();
  robot.tool.T_H_T = read_pose_xyz_rpy_deg(tool);
  robot.tool.body = read_rigid_body(tool);
}

double side_positive(const ConfigNode& side, std::string_view key, double fallback) {
  const std::optional<ConfigNode> node = side.optional_child(key);
  if (!node) return fallback;
  const double value = node->as_double();
  if (!(value > 0.0)) node->fail(fmt::format("expected a number > 0, got {}", value));
  return value;
}

std::string side_string(const std::optional<ConfigNode>& side, std::string_view key,
                        const std::string& fallback) {
  if (!side) return fallback;
  const std::optional<ConfigNode> node = side->optional_child(key);
  return node ? node->as_string() : fallback;
}

// Everything of the side file but the chain's end links, which were read first.
void apply_side_file(const ConfigNode& side, RobotDescription& robot) {
  robot.name = side_string(side, "name", robot.name);
  if (const auto payload = side.optional_child("nominal_payload_kg")) {
    robot.nominal_payload_kg = payload->as_double();
    if (!(robot.nominal_payload_kg >= 0.0)) payload->fail("expected a number >= 0");
  }
  robot.reach_m = side_positive(side, "reach_m", robot.reach_m);
  robot.controller_cycle_s = side_positive(side, "controller_cycle_s", robot.controller_cycle_s);
  if (const auto tool = side.optional_child("tool")) read_side_tool(*tool, robot);
  if (const auto joints = side.optional_child("joints")) read_side_joints(*joints, robot);
}

}  // namespace

UrdfChain read_urdf_chain(const std::filesystem::path& urdf, const std::string& base_link,
                          const std::string& tip_link) {
  const UrdfReader reader(urdf);
  const std::string base = base_link.empty() ? reader.model().getRoot()->name : base_link;
  return walk_chain(reader, base, tip_link).chain;
}

Eigen::Isometry3d urdf_chain_pose(const UrdfChain& chain, const JointVector& q) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  for (int i = 0; i < kJointCount; ++i) {
    pose = pose * chain.fixed[i] * Eigen::AngleAxisd(q(i), chain.axis[i]);
  }
  return pose * chain.fixed[kJointCount];
}

std::filesystem::path urdf_side_file(const std::filesystem::path& urdf) {
  std::filesystem::path side = urdf;
  side.replace_extension(".imscal.yaml");
  return side;
}

RobotDescription load_urdf_robot(const std::filesystem::path& urdf) {
  std::optional<ConfigNode> side;
  if (std::filesystem::exists(urdf_side_file(urdf))) {
    side = ConfigNode::load_file(urdf_side_file(urdf));
    side->require_only_keys({"name", "nominal_payload_kg", "reach_m", "controller_cycle_s",
                             "base_link", "tip_link", "tool", "joints"});
  }
  const UrdfReader reader(urdf);
  const std::string base = side_string(side, "base_link", reader.model().getRoot()->name);
  const ChainWalk walk = walk_chain(reader, base, side_string(side, "tip_link", "tool0"));

  RobotDescription robot;
  robot.source = urdf.string();
  robot.name = walk.chain.robot_name;
  robot.tool.name = "flange";
  std::array<DhFrame, kJointCount + 1> frames;
  robot.kinematics = dh_model_of(walk.chain, frames);
  fill_limits(walk, robot);
  for (int i = 0; i < kJointCount; ++i) {  // link i+1 lives in DH frame i+1
    robot.joints[i].link = merged_body(walk.pieces[i], frames[i + 1].pose());
  }
  robot.reach_m = stretched_reach(robot.kinematics);
  if (side) apply_side_file(*side, robot);
  return robot;
}

}  // namespace imscal::calib
