#pragma once
// How far the sim-to-real gap shrinks once an effect is modelled ("how far"), and the
// verdict. The record is cut into alternating blocks (training, held-out, training, ...) so that
// both parts see every kind of motion; every candidate of eval/gap_candidates.hpp is fitted per
// joint on the training blocks and judged on the held-out blocks only:
//
//   shrinkage = 100 % * (1 - RMS_held-out(g - candidate) / RMS_held-out(g))   (all joints)
//
// Significance: a moving-block bootstrap of the held-out per-sample reduction of the squared gap
// (summed over joints); blocks because the residuals are coloured. A candidate is supported when
// the bootstrap p-value is below `alpha` and the shrinkage at least `min_shrinkage_percent`.
// The candidates are then fitted together: forward-backward selection of a joint model starting
// from the candidate ranked first (eval/gap_selection.hpp), a member kept only while it shrinks the
// held-out gap significantly further. Candidates the data cannot tell apart form
// ambiguity groups (eval/gap_ambiguity.hpp), reported together with what would separate them,
// overall and per joint (its candidates ranked on its own gap). A gap concentrated in one joint
// is significant on its own, with a level corrected for the number of joints, or when it stands
// far above that joint's noise (eval/gap_joint_significance.hpp). The plain words are
// eval/gap_verdict.hpp's.
//
// References (docs/references.md): [Kunsch1989] (moving-block bootstrap).
#include <cstdint>
#include <string>
#include <vector>

#include "eval/gap_ambiguity.hpp"
#include "eval/gap_analysis.hpp"
#include "eval/gap_candidates.hpp"
#include "eval/gap_joint_significance.hpp"
#include "eval/gap_measurement_budget.hpp"
#include "eval/gap_model_error.hpp"
#include "eval/gap_nominal_plant.hpp"

namespace imscal::eval {

struct DiagnosisOptions {
  double block_s = 1.0;            // training / held-out alternation [s]
  double bootstrap_block_s = 0.2;  // moving-block length [s], longer than the gap's memory
  int bootstrap_resamples = 400;
  double alpha = 0.01;                        // significance level (one-sided)
  double min_shrinkage_percent = 5.0;         // below this an effect is not worth modelling
  double min_combination_gain_percent = 2.0;  // further shrinkage a combination step must add
  int max_combination = 4;  // candidates in the joint model (eval/gap_selection.hpp)
  std::uint64_t seed = 1;   // of the bootstrap (deterministic reports)
  // A joint's gap this many times its noise reference is significant on its own
  // (eval/gap_joint_significance.hpp).
  double far_above_noise_factor = 10.0;
  ModelErrorOptions model_error;  // of the per-joint model-error model
};

struct CandidateResult {
  CandidateFit fit;
  double shrinkage_percent = 0.0;        // held-out, all joints
  double joint_shrinkage_percent = 0.0;  // held-out, its own joint
  double p_value = 1.0;
  bool supported = false;
  // The same on its own joint only (the gain on that joint's held-out rows), for the per-joint
  // findings: an effect on a joint with a small share of the whole gap is still that joint's cause.
  double joint_p_value = 1.0;
  bool joint_supported = false;
  int ambiguity_group = -1;  // index into Diagnosis::ambiguity_groups, -1: none
};

// Per joint: the candidates located on it, ranked by their held-out shrinkage of that joint's gap
// (less the same parsimony charge), the leading one and those the data cannot tell apart from it
// on that joint (eval/gap_ambiguity.hpp).
struct JointFinding {
  std::size_t joint = 0;
  std::vector<std::size_t> leading;  // indices into Diagnosis::candidates, the leader first
  bool supported = false;            // the leader's own-joint gain is significant
  std::string separate_by;           // when `leading` has several members
};

struct CombinationStep {
  std::string label;               // "A2 backlash"
  double shrinkage_percent = 0.0;  // held-out, all joints, cumulative
  double p_value = 1.0;            // of this step's further shrinkage
  std::size_t candidate = 0;       // index into Diagnosis::candidates
  // The candidate as it stands in the joint model: after the first, its shape and size fitted
  // again to the gap the model's earlier members leave (an effect behind a larger one).
  CandidateFit fit;
};

struct Diagnosis {
  GapAnalysis where;
  // Per joint: the FIR model of the gap from q_d with its frequency response and confidence
  // band (eval/gap_model_error.hpp), same training / held-out rows as the candidates.
  std::vector<ModelErrorModel> model_error;
  double heldout_rms_rad = 0.0;              // held-out gap before any candidate
  double heldout_rms_modelled_rad = 0.0;     // after the joint model
  std::vector<CandidateResult> candidates;   // sorted by held-out shrinkage, best first
  std::vector<CombinationStep> combination;  // the joint model's members
  // The joint model refined on the nominal model's simulator (eval/gap_refinement.hpp; only with
  // one). When applied, the last step's shrinkage and heldout_rms_modelled_rad are the refined
  // model's and its members' size_text the re-simulated parameters.
  NominalRefinement refinement;
  // Candidates the data cannot tell apart (members index `candidates`; groups in ranking order,
  // the group of the first candidate first when it has one).
  std::vector<AmbiguityGroup> ambiguity_groups;
  std::vector<JointFinding> joint_findings;           // every joint with candidates, in joint order
  std::vector<JointSignificance> joint_significance;  // every joint, in joint order
  // Whether the gap is within what the IMS chain's own error explains
  // (eval/gap_measurement_budget.hpp; known only with the chain's noise floor). Within it, no robot
  // cause is raised.
  MeasurementBudget measurement;
  // The first candidate is supported (on all joints), or some joint's gap is significant on its
  // own (joint_significance), and the gap is not within the measurement.
  bool significant_gap = false;
  std::string verdict;                    // plain words
  std::vector<std::string> measure_next;  // when the evidence is weak
};

// Training rows: blocks 0, 2, 4, ... of `block_s` (counted from each run's start).
std::vector<bool> training_rows(const GapSignals& signals, double block_s);

// Moving-block bootstrap p-value of "mean(d) <= 0" for per-row gains d (held-out rows in order).
double block_bootstrap_p_value(const std::vector<double>& d, std::size_t block, int resamples,
                               std::uint64_t seed);

// `nominal`: the simulator of the nominal model that predicted the "sim" joint errors, on the same
// samples; the joint model is then refined on it (eval/gap_refinement.hpp). Null: linear only.
Diagnosis diagnose_gap(const GapSignals& signals, const DiagnosisOptions& options = {},
                       const NominalPlant* nominal = nullptr);

std::string candidate_label(const GapSignals& signals, const CandidateFit& fit);

// The members of the leading ambiguity group (the first candidate and those the data cannot tell
// apart from it), indices into `candidates`; empty without a significant gap. When the gap is
// significant per joint only: the leading explanation of the joint whose gap stands highest above
// its noise among those significant by candidate (empty when none is).
std::vector<std::size_t> leading_group(const Diagnosis& diagnosis);

}  // namespace imscal::eval
