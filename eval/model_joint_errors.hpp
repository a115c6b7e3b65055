#pragma once
// The model side of a sim-to-real comparison: the joint errors the nominal model predicts on the
// same samples as a measured joint_errors.csv, so that `imscal diagnose --sim-joint-errors` can
// compare the two row by row.
//
// The nominal robot (sim::NominalRobot: the data sheet and model the lab believes, never the
// plant) runs in the plant simulator (sim/plant_simulator.hpp) along the measured desired path:
// q_d of the log on the controller-cycle grid from its first sample, with the derivatives as
// central differences (one-sided at the ends; the planner's own derivatives are not in the log),
// samples the log lacks (gaps of the IMS chain) filled by linear interpolation of q_d. The
// effects, the gravity and the payloads are the scenario's when one is given (its `effects:`
// section on the nominal robot, the site's gravity in the base, the program's payload of the
// logged mass with its centre of mass and inertia), else the simulator's defaults (every effect
// but the transmission error on, upright base, 9.80665 m/s², the logged mass as a point mass at
// the tool frame's origin, as eval/gap_signals.hpp's torques).
// The record should start at rest: the simulated plant starts balanced at rest there.
//
// The result is a log of the nominal robot with the measured log's time stamps, q_desired and
// payload; q_measured the model's link-side angles, q_internal its motor angles / N.
#include "eval/gap_nominal_plant.hpp"
#include "ident/joint_error_io.hpp"
#include "sim/scenario.hpp"

namespace imscal::eval {

// Throws std::invalid_argument when the log's robot or joints are not the nominal robot's, or
// the log is empty.
ident::JointErrorLog nominal_model_joint_errors(const ident::JointErrorLog& measured,
                                                const sim::NominalRobot& nominal,
                                                const sim::Scenario* scenario_or_null = nullptr);

// The same nominal model as a simulator for the gap diagnosis (eval/gap_nominal_plant.hpp): the
// plant and the desired path on the controller-cycle grid, with the grid sample of every logged
// sample (NominalPlant::samples), so that its re-simulations line up with the log's rows.
NominalPlant nominal_plant_along(const ident::JointErrorLog& measured,
                                 const sim::NominalRobot& nominal,
                                 const sim::Scenario* scenario_or_null = nullptr);

}  // namespace imscal::eval
