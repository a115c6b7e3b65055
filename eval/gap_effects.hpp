#pragma once
// The candidate effects of the gap diagnosis, each defined once: an `EffectKind` value, and its
// `EffectDefinition` in its own file eval/gap_effect_<name>.cpp (its name, whether it moves a
// link, its shapes, its size in words, what separates it from the effects it is confused with,
// and, when it is a parameter of the nominal model, how the refinement by re-simulation changes
// that parameter within its physical bound). The diagnosis, the ambiguity groups, the report and
// the refinement read the definitions through `effect_definition`; none of them switches on the
// kind. Adding an effect: docs/ARCHITECTURE.md, "A gap effect".
#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <string>
#include <vector>

namespace imscal::sim {
struct PlantConfig;
struct DesiredJointPath;
}  // namespace imscal::sim

namespace imscal::eval {

enum class EffectKind {
  kBacklash,
  kCoulombFriction,
  kGearCompliance,
  kTransmissionError,
  kResonance,
  kTimeOffset,
  kPayloadMismatch,
  kZeroOffset,
  kThermalDrift,
  kOperatingPoint,
  kKinematicParameters,
  kSensorMounting,
  kImsScaleFactor,
  kImsBias,
  kClockOffset,
};
inline constexpr int kEffectKindCount = 15;

struct CandidateShape;    // eval/gap_candidates.hpp
struct CandidateFit;      // eval/gap_candidates.hpp
struct ShapeContext;      // eval/gap_effect_shapes.hpp
struct ShapePool;         // eval/gap_shape_pool.hpp
struct NominalPlant;      // eval/gap_nominal_plant.hpp
struct NominalParameter;  // eval/gap_nominal_plant.hpp

// An effect that is a parameter of the nominal model (eval/gap_nominal_plant.hpp): the
// refinement re-simulates the nominal model with it changed by p (its units).
struct NominalParameterDefinition {
  Eigen::Index parameter_count = 1;
  // One of a joint's drive effects, which a drive member of the joint model may stand for in the
  // refinement (eval/gap_refinement.cpp).
  bool of_drive = false;
  // Its change is a ripple of an order per motor revolution (NominalParameter::
  // harmonic_per_motor_rev), which the refinement tries at the orders the raw ripple fits best.
  bool per_motor_order = false;
  // Whether the nominal model has the parameter on `joint` (joint < the plant's joint count).
  bool (*applies)(const NominalPlant& plant, std::size_t joint) = nullptr;
  // The nominal model's own value (0 when its effect is off there); its physical bound is
  // value + p >= 0. Null: no bound, and a nominal value of 0.
  double (*nominal_value)(const NominalPlant& plant, std::size_t joint) = nullptr;
  // The robot's value whether the nominal model has it on or not: the scale of the
  // finite-difference step.
  double (*typical_value)(const NominalPlant& plant, std::size_t joint) = nullptr;
  // The change p (parameter_count values) applied to the nominal model's plant and path.
  void (*apply)(const NominalParameter& parameter, const double* p, sim::PlantConfig& config,
                sim::DesiredJointPath& path) = nullptr;
  // The changed parameter in words, e.g. "A3 Coulomb friction 20.1 N m (nominal 40.2 N m)".
  std::string (*describe)(const std::string& joint_name, const NominalParameter& parameter,
                          const Eigen::VectorXd& p_own, double nominal) = nullptr;
};

struct EffectDefinition {
  EffectKind kind;
  const char* name;  // in the report and report.json, e.g. "backlash"
  // It moves a link, and so reaches the other joints through the coupled dynamics
  // (eval/gap_coupling.hpp), unlike offsets, drifts, time offsets, table extrapolation and errors
  // of the IMS chain, which act on the measurement or the model only.
  bool acts_through_dynamics;
  const char* what_to_measure;  // the measurement that pins it down, in plain words
  // Its shapes on a joint (eval/gap_candidates.hpp, candidate_shapes); empty: it does not apply.
  std::vector<CandidateShape> (*shapes)(const ShapeContext& context);
  // An effect with a large grid of shapes (a resonance's frequencies and dampings): their count
  // and the i-th of `shapes`, built one at a time so that the validation holds one shape at a time
  // and keeps only the one it chooses (eval/gap_shape_choice.hpp). Null: all at once.
  std::size_t (*shape_count)(const ShapeContext& context) = nullptr;
  CandidateShape (*shape_at)(const ShapeContext& context, std::size_t index) = nullptr;
  // An effect whose shapes are column subsets of a few pools (eval/gap_shape_pool.hpp): the pools,
  // their shapes in the order of `shapes`, validated from each pool's Gram matrices. Null: the
  // shapes one by one.
  std::vector<ShapePool> (*shape_pools)(const ShapeContext& context) = nullptr;
  // Its size in words from the fit of its chosen shape (`own_rms`: the RMS of its modelled gap on
  // its own joint; the shape's columns are the fit's `columns`, the shape's first, not the
  // shape's own, which the fit took). Null: the first parameter with its sigma.
  std::string (*size_in_words)(const CandidateFit& fit, const CandidateShape& shape,
                               double own_rms) = nullptr;
  // The measurement that separates it from `other` on the same joint (`joint_name`) where that
  // is more specific than the two effects' own measurements; empty: none. Null: none at all.
  std::string (*separate_from)(EffectKind other, const std::string& joint_name) = nullptr;
  // Null: not a parameter of the nominal model.
  const NominalParameterDefinition* nominal = nullptr;
};

// The definitions, one file each (eval/gap_effect_<name>.cpp).
extern const EffectDefinition kBacklashEffect;
extern const EffectDefinition kCoulombFrictionEffect;
extern const EffectDefinition kGearComplianceEffect;
extern const EffectDefinition kTransmissionErrorEffect;
extern const EffectDefinition kResonanceEffect;
extern const EffectDefinition kTimeOffsetEffect;
extern const EffectDefinition kPayloadMismatchEffect;
extern const EffectDefinition kZeroOffsetEffect;
extern const EffectDefinition kThermalDriftEffect;
extern const EffectDefinition kOperatingPointEffect;
extern const EffectDefinition kKinematicParametersEffect;
extern const EffectDefinition kSensorMountingEffect;
extern const EffectDefinition kImsScaleFactorEffect;
extern const EffectDefinition kImsBiasEffect;
extern const EffectDefinition kClockOffsetEffect;

// The registry, in the order of `EffectKind` (tests/eval/test_gap_effects.cpp checks it).
inline constexpr std::array<const EffectDefinition*, kEffectKindCount> kEffectDefinitions = {
    &kBacklashEffect,
    &kCoulombFrictionEffect,
    &kGearComplianceEffect,
    &kTransmissionErrorEffect,
    &kResonanceEffect,
    &kTimeOffsetEffect,
    &kPayloadMismatchEffect,
    &kZeroOffsetEffect,
    &kThermalDriftEffect,
    &kOperatingPointEffect,
    &kKinematicParametersEffect,
    &kSensorMountingEffect,
    &kImsScaleFactorEffect,
    &kImsBiasEffect,
    &kClockOffsetEffect,
};

inline const EffectDefinition& effect_definition(EffectKind kind) {
  return *kEffectDefinitions[static_cast<std::size_t>(kind)];
}

const char* to_string(EffectKind kind);
EffectKind effect_kind_from_index(int index);

// Whether the effect moves a link (EffectDefinition::acts_through_dynamics).
bool acts_through_dynamics(EffectKind kind);

}  // namespace imscal::eval
