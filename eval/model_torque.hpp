#pragma once
// The joint torques of the robot's rigid-body model along a joint path: the further input of the
// multi-input error models (ident/joint_identification.hpp). The torque a joint must produce
// (inertia of the whole arm in its pose, coupling, gravity, the payload) drives its controller's
// following error and its gear's deflection; the joint's own angle alone cannot tell it.
//
// Which path: the models read the torque along the path their main input follows, the measured
// link path in the inverse form (in the identification data) and the desired path otherwise and
// at run time (torque_along_measured_path). Derivatives of a sampled path are central
// differences (one-sided at the ends of a segment).
//
// The payload: a point mass at the origin of the robot's tool frame T (the IMS frame of the
// robot file), the only payload datum the joint-error log and the precontrol's caller have (its
// mass). Its lever and inertia, like the model's own inertial errors, are absorbed by the
// identified torque coefficients.
//
// References (docs/references.md): [KDL], [Featherstone2008] (inverse dynamics).
#include <Eigen/Core>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "ident/joint_error_io.hpp"
#include "ident/joint_identification.hpp"
#include "ident/parameter_table.hpp"
#include "robot/robot_description.hpp"
#include "sim/desired_path.hpp"
#include "sim/rigid_body_dynamics.hpp"

namespace imscal::eval {

// The rigid-body model: the robot description and gravity in the robot base R [m/s²].
struct ModelTorqueSource {
  calib::RobotDescription robot;
  Eigen::Vector3d gravity_in_base_m_s2 = Eigen::Vector3d(0.0, 0.0, -9.81);
};

// The rigid-body model with the payload of the current sample, a point mass at T's origin
// (rebuilt only when it changes: payloads change a few times per program).
class PayloadDynamics {
 public:
  explicit PayloadDynamics(const ModelTorqueSource& model);
  calib::JointVector torque(double payload_kg, const calib::JointVector& q,
                            const calib::JointVector& qd, const calib::JointVector& qdd);

 private:
  sim::RigidBodyDynamics dynamics_;
  double payload_kg_ = 0.0;
};

// The rigid-body model of `robot_file` for the data of `data_robot` (file `data_file`, for
// messages): InputError naming `needed_by_file` and `needed_by_field` (what asked for the torque)
// when robot_file is empty, and the robot file when its robot is not the data's or (data_cycle_s >
// 0) its controller cycle is not the data's sample time [s].
ModelTorqueSource load_model_torque_source(
    const std::string& robot_file, const Eigen::Vector3d& gravity_in_base_m_s2,
    const std::string& data_robot, const std::string& data_file, const std::string& needed_by_file,
    const std::string& needed_by_field, double data_cycle_s = 0.0);

// Torques [joint][sample] along a sampled path q_rad [joint][sample] with cycle cycle_s and
// payload_kg per sample, over the [begin, end) segments (samples outside every segment: 0).
// Throws std::invalid_argument for inconsistent sizes.
std::vector<std::vector<double>> model_torques_along(
    const ModelTorqueSource& model, double cycle_s, const std::vector<std::vector<double>>& q_rad,
    std::span<const double> payload_kg,
    std::span<const std::pair<std::size_t, std::size_t>> segments);

// Torques [sample] along a planned desired path, from its exact derivatives.
std::vector<calib::JointVector> model_torques_along(const ModelTorqueSource& model,
                                                    const sim::DesiredJointPath& path);

// Whether the identification reads the torque along the measured path (inverse form).
bool torque_along_measured_path(const ident::JointIdentificationOptions& options);

// Fills log.model_torque_nm along the path the options' model form reads (nothing when the
// options take no torque input).
void attach_model_torques(ident::JointErrorLog& log, const ModelTorqueSource& model,
                          const ident::JointIdentificationOptions& options);

// The model with the table's refined links (ident::ParameterTable::model_torque_links: the
// refined links' masses and centres of mass in place of the robot file's), the torque the table
// was identified with; the model unchanged for a table without them. InputError naming
// `table_file` when the table's links are not the model's or its nominal values are not the
// robot file's (a table refined from another robot file).
ModelTorqueSource with_table_links(ModelTorqueSource model, const ident::ParameterTable& table,
                                   const std::string& table_file);

}  // namespace imscal::eval
