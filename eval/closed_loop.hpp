#pragma once
// The precontrol in the loop of the robot (paper, Fig. 3 and 4): every controller cycle the
// precontrol (ident/precontrol.hpp) gets the desired joint angles q_d and the payload, and its
// offset Δq̂ is added to the command the joint controllers receive, q_c = q_d + Δq̂; the plant
// then follows q_c. The result holds the attained link-side joints with and without compensation.
//
// The precontrol sees only the desired values, never the plant, so the offsets of a whole path
// are computed first and the plant is then run once on the modified command: the same cycle-by-
// cycle data flow as stepping both together, with the plant free to be any PlantRun (the
// simulator, or a test's linear plant).
//
// Feed-forward: the controller's velocity/acceleration feed-forward of the modified command is
// q̇_d + ȯ and q̈_d + ö, with ȯ, ö central differences of the offsets over the cycle (one-sided at
// the path's ends). The interpolator plans ahead, so o(k+1) is known at cycle k.
//
// Look-ahead: with look_ahead_cycles = L the precontrol is fed q_d(k + L + P) at cycle k (held at
// the path's end; P = the table's preview_cycles, 0 for a forward-form table) and its output is
// applied at cycle k. The model's own offset is
// Δq̂(k) = q_d(k - d) - q̂(k) (paper, eq. 2): with L = d it refers to the desired value of the
// cycle it is applied in.
//
// Inversion of the loop: adding the predicted error once, q_c = q_d + Δq̂, leaves the
// plant's response to the offset itself: with G the loop (q_c -> q) the remainder is
// (1 - G)^2 q_d instead of (1 - G) q_d. With inversion_iterations = n the offset is the n-th
// fixed-point iterate of G(q_d + o) = q_d with the model in place of G,
//   o_0 = P(q_d),  o_{i+1} = P(q_d + o_i),   P(x) = the precontrol's offset for the input x,
// since P(x) = x - Ĝ x (+ backlash): o_{i+1} = o_i + (q_d - Ĝ(q_d + o_i)). The remainder falls
// to (1 - G)^(n+2) q_d where the model matches the loop. Every stage is the same causal
// precontrol fed by the previous stage's command, so this is a cascade of n + 1 precontrols in
// the controller (computed here stage by stage over the whole path: the same numbers). It needs
// look_ahead_cycles = 0 (std::invalid_argument otherwise): with every stage's output shifted L
// cycles early the fixed point would not be G(q_d + o) = q_d.
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "calib/robot_description.hpp"
#include "eval/model_torque.hpp"
#include "ident/parameter_table.hpp"
#include "ident/precontrol.hpp"
#include "sim/desired_path.hpp"
#include "sim/plant_config.hpp"
#include "sim/plant_simulator.hpp"

namespace imscal::eval {

struct CompensationOptions {
  ident::PrecontrolOptions precontrol;  // caller_cycle_s is replaced by the path's cycle
  int look_ahead_cycles = 0;            // L >= 0 [cycles]
  int inversion_iterations = 0;         // n >= 0: cascade stages after the first (see above)
  // W >= 0 cycles the precontrol runs at the path's first sample before the path starts, when the
  // path starts at rest (its first two samples equal, no rates): on a controller the compensation
  // runs from power-on, so it has settled at the start pose's static offset long before a test
  // path. Without it, a run cut out of a program starts the precontrol cold and its offset ramps
  // in during the first cycles (2 mrad on A2 within 40 ms on seed-line): a jump of the robot that
  // its own rest does not show. The warm-up powers the precontrol on as the online bridges do
  // (PrecontrolOptions::auto_engage: settle, then fade in; 0.4 s by default, so W should cover
  // it); on the path itself a deactivation stays final.
  int warm_up_cycles = 0;
  // The robot's rigid-body model, for tables whose models take the model torque: the precontrol
  // is then fed the torque along the desired path at the sample it is fed (eval/model_torque.hpp).
  // Such a table without it: std::invalid_argument.
  std::optional<ModelTorqueSource> model_torque;
};

// The precontrol's offsets along a desired path, one per path sample.
struct CompensationRun {
  std::vector<calib::JointVector> offset_rad;
  std::vector<ident::PrecontrolState> state;
  std::vector<bool> outside_table;
  std::vector<ident::PrecontrolEvent> events;  // in cycle order
};

// Throws std::invalid_argument when the precontrol refuses the table (reason in the message).
CompensationRun run_precontrol(const ident::ParameterTable& table, const std::string& robot_name,
                               const sim::DesiredJointPath& path,
                               const CompensationOptions& options = {});

// q_c = q_d + o with the feed-forward derivatives described above. offsets.size() must equal
// path.samples.size() (std::invalid_argument).
sim::DesiredJointPath command_path(const sim::DesiredJointPath& desired,
                                   const std::vector<calib::JointVector>& offsets);

// A plant: the commanded path in, the attained joints out, one sample per command sample.
using PlantRun = std::function<sim::PlantLog(const sim::DesiredJointPath& command)>;

// The robot simulator (sim::simulate_plant) with its output at every controller cycle.
PlantRun simulator_plant(const sim::PlantConfig& config);

struct ClosedLoopRun {
  sim::DesiredJointPath command;  // what the controllers got with compensation
  CompensationRun compensation;
  sim::PlantLog uncompensated;  // plant on q_d
  sim::PlantLog compensated;    // plant on q_c
};

// Runs both. Throws std::invalid_argument when a plant returns a sample count other than the
// path's.
ClosedLoopRun run_closed_loop(const sim::DesiredJointPath& desired,
                              const ident::ParameterTable& table, const std::string& robot_name,
                              const PlantRun& plant, const CompensationOptions& options = {});

// Link-side joint errors q_d - q_link per cycle (rows: samples).
std::vector<calib::JointVector> joint_errors(const sim::DesiredJointPath& desired,
                                             const sim::PlantLog& attained);

}  // namespace imscal::eval
