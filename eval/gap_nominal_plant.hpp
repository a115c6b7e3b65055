#pragma once
// The simulator of the nominal model ("sim") as the shape of a gap candidate: an effect that is a
// parameter of the nominal model, changed by p, models the gap
//
//   m(p) = q_link(nominal) - q_link(nominal with p)   [rad], every joint and sample
//
// (gap = Δq_real - Δq_sim with Δq = q_d - q_link) through the same loop, coupled dynamics and
// nonlinearities as the nominal model itself, at any size: a friction halved or a transmission
// error of another order is not the linear response the candidates' Laguerre bases approximate.
// The effects that are parameters of the nominal model say so in their definitions
// (EffectDefinition::nominal, eval/gap_effects.hpp): how many values p has, in which units, and
// its physical bound.
#include <Eigen/Core>
#include <cstddef>
#include <string>
#include <vector>

#include "eval/gap_candidates.hpp"
#include "sim/desired_path.hpp"
#include "sim/plant_config.hpp"

namespace imscal::eval {

// The nominal model as the lab simulates it: the plant and the desired path of the "sim" record
// (one output sample per controller cycle, as the record's).
struct NominalPlant {
  sim::PlantConfig config;
  sim::DesiredJointPath path;
  // The path sample of each sample of the gap's record (a measured record has gaps and may be cut
  // to windows); empty: one to one.
  std::vector<std::size_t> samples;
};

// One member's parameter change (see the file's head).
struct NominalParameter {
  EffectKind kind = EffectKind::kCoulombFriction;
  std::size_t joint = 0;
  double harmonic_per_motor_rev = 1.0;  // effects with a per-motor order only
  Eigen::Index size() const;            // the values of its change p
};

// Whether `kind` on `joint` is a parameter of this nominal model.
bool has_nominal_parameter(const NominalPlant& plant, EffectKind kind, std::size_t joint);

// The finite-difference step of each parameter at p (its units): 10 % of the nominal robot's
// value or of |p|, whichever is larger.
Eigen::VectorXd nominal_steps(const NominalPlant& plant,
                              const std::vector<NominalParameter>& parameters,
                              const Eigen::VectorXd& p);

// p with every size within its physical bound.
Eigen::VectorXd physical_parameters(const NominalPlant& plant,
                                    const std::vector<NominalParameter>& parameters,
                                    Eigen::VectorXd p);

// The link angles [joint][sample of the record, NominalPlant::samples] of the nominal model with
// the changes p (stacked in the order of `parameters`).
std::vector<std::vector<double>> simulate_links(const NominalPlant& plant,
                                                const std::vector<NominalParameter>& parameters,
                                                const Eigen::VectorXd& p);

// A joint model refined on the nominal model (eval/gap_refinement.hpp).
struct NominalRefinement {
  bool applied = false;                      // its held-out residual is below the linear model's
  double shrinkage_percent = 0.0;            // held-out, all joints, of the refined model
  double heldout_energy = 0.0;               // of its residual [rad²]
  std::vector<std::size_t> members;          // the members refined (indices into the joint model)
  std::vector<NominalParameter> parameters;  // what each stands for, in the same order
  std::vector<Eigen::VectorXd> values;       // its change p (the units of the file's head)
  std::vector<std::string> changes;          // in words
  int simulations = 0;                       // runs of the nominal model it took
};

// The parameters in words, e.g. "A3 Coulomb friction 20.1 N m (nominal 40.2 N m)".
std::string describe_nominal_change(const NominalPlant& plant, const NominalParameter& parameter,
                                    const Eigen::VectorXd& p_own);

}  // namespace imscal::eval
