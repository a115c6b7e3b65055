#pragma once
// The common interface of the inverse-kinematics solvers of 6R arms, and the factory that picks
// the solver from the arm's structure:
// - robot/inverse_kinematics.hpp: spherical wrist (KUKA KR 16, ABB IRB, Fanuc, PUMA);
// - robot/ur_inverse_kinematics.hpp: axes 2, 3, 4 parallel with wrist offsets (Universal
//   Robots UR3/5/10/16, e-Series).
// Both take the closed form of their class as the start of Newton steps on the full model, fill
// the same IkResult (failures reported, never thrown) and use the same three configuration flags,
// each class stating what they mean for it.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "robot/robot_description.hpp"

namespace imscal::calib {

// The three binary branches of a 6R arm (8 solutions of a general pose). Their geometric meaning
// depends on the class (see the solver's header).
struct ArmConfiguration {
  bool shoulder_front = true;
  bool elbow_up = true;
  bool wrist_flip = false;
  bool operator==(const ArmConfiguration&) const = default;
};
std::string to_string(const ArmConfiguration& configuration);  // "front/up/noflip"

enum class IkStatus {
  kOk,
  kUnreachable,
  kShoulderSingular,
  kElbowSingular,
  kWristSingular,
  kOutsideJointLimits,
  kNotConverged,
};
const char* to_string(IkStatus status);

struct IkOptions {
  // Distance to a singularity below which solve() refuses: shoulder [m] (wrist point from the
  // singular cylinder about axis 1), elbow and wrist [sine of the bend angle].
  double singularity_tolerance = 1e-6;
  int max_newton_iterations = 20;
  double position_tolerance_m = 1e-12;       // flange position error after refinement
  double orientation_tolerance_rad = 1e-12;  // flange rotation error after refinement
  bool enforce_joint_limits = true;
  // Among the 2*pi-equivalents of each angle within the limits, take the one nearest to this
  // (default: nearest to 0).
  std::optional<JointVector> q_near;
};

struct IkResult {
  IkStatus status = IkStatus::kNotConverged;
  std::string reason;  // empty when ok
  JointVector q = JointVector::Zero();
  ArmConfiguration configuration;
  double position_error_m = 0.0;       // |p_H(q) - p_target| after refinement
  double orientation_error_rad = 0.0;  // angle of R_H(q)^T R_target after refinement
  int newton_iterations = 0;
  bool ok() const { return status == IkStatus::kOk; }
};

// Distances to the three singularities at q (same units as IkOptions::singularity_tolerance).
struct SingularityMeasures {
  double shoulder_m = 0.0;
  double elbow = 0.0;  // |sin| of the elbow bend from the stretched arm
  double wrist = 0.0;  // |sin| of the wrist bend
};

class IkSolver {
 public:
  virtual ~IkSolver() = default;

  // The solution of the given configuration for the flange pose T_R_H.
  virtual IkResult solve(const Eigen::Isometry3d& T_R_H, const ArmConfiguration& configuration,
                         const IkOptions& options = {}) const = 0;
  virtual ArmConfiguration configuration_of(const JointVector& q) const = 0;
  virtual SingularityMeasures singularity_measures(const JointVector& q) const = 0;
  // "spherical wrist" or "UR class" (for messages).
  virtual const char* structure() const = 0;

  // The solution nearest (largest joint difference) to a reference reading, e.g. the robot's
  // own encoders: of q_reference's arm configuration with either wrist branch. Near the wrist
  // singularity (wrist bend ~ 0) a pose error of microradians can put the pose's wrist bend on
  // the other side of zero; the reference's own branch is then a different physical pose, the
  // other branch the true one. options.q_near defaults to q_reference.
  IkResult solve_nearest(const Eigen::Isometry3d& T_R_H, const JointVector& q_reference,
                         IkOptions options = {}) const;
  // All 8 configurations, in the order of all_configurations(); each with its own status.
  std::vector<IkResult> solve_all(const Eigen::Isometry3d& T_R_H,
                                  const IkOptions& options = {}) const;
  static std::vector<ArmConfiguration> all_configurations();

  const KinematicModel& model() const { return model_; }

 protected:
  explicit IkSolver(const KinematicModel& model) : model_(model) {}
  // After the Newton refinement (robot/ik_refinement.hpp), for every solver: converged; for an arm
  // that is not of the ideal structure (whose closed form checked its singularities before),
  // away from a singularity and still on the requested configuration; within the joint limits.
  // Sets result.status and result.reason.
  void finish_refined(bool ideal, const ArmConfiguration& configuration, const IkOptions& options,
                      IkResult& result) const;
  KinematicModel model_;
};

// The solver of the arm's class: spherical wrist, else UR class. Throws std::invalid_argument
// naming why the arm is of neither class.
std::unique_ptr<IkSolver> make_inverse_kinematics(const KinematicModel& model);

}  // namespace imscal::calib
