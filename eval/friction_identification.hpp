#pragma once
// Every joint's friction levels (Coulomb, viscous) and reflected motor inertia from an
// identification record, with 1σ, beside the nominal robot's values
// (ident/friction_levels.hpp): the following error of the motor encoders (the log's q_internal
// block), the nominal model's torque along the desired path (eval/model_torque.hpp), the desired
// path's speed and acceleration by central differences within each segment. The nominal robot's
// drive values are the prior the estimate starts from and is reported beside; the plant is never
// read.
#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "eval/model_torque.hpp"
#include "ident/friction_levels.hpp"
#include "ident/joint_error_io.hpp"

namespace imscal::eval {

// One entry per joint of the log; every joint not estimated (with the reason) when the log has
// no q_internal block. Throws std::invalid_argument when the log is not of the model's joints.
std::vector<ident::JointFrictionLevels> identify_friction_levels(
    const ident::JointErrorLog& log, const ModelTorqueSource& nominal,
    const ident::FrictionLevelOptions& options = {});

// Speed and acceleration of x [rad] by central differences inside each segment (one-sided at its
// ends, acceleration 0 there).
void path_derivatives(const std::vector<double>& x, double cycle_s,
                      const std::vector<std::pair<std::size_t, std::size_t>>& segments,
                      std::vector<double>& speed, std::vector<double>& acceleration);

// One line per joint for the identification's log.
std::string describe_friction_levels(const ident::JointFrictionLevels& levels);

}  // namespace imscal::eval
