#pragma once
// Whether the model torque's refined links (eval/mass_refinement.hpp) make better tables: the
// record identified once with the nominal model's torque and once with the refined one, each
// joint's table judged on its held-out rows (ident/table_fit.hpp, the free run of every cell
// blended as the precontrol applies them), and the refinement kept only where the Bayesian
// information criterion on those rows prefers it:
//   BIC change = Σ_j n_j ln(RSS_j,refined / RSS_j,nominal) + k ln n < 0,
// n_j the joint's held-out rows, RSS_j = spread_j (1 − fit_j / 100)² (the same spread for both),
// k = 4 parameters per refined link (3, its centre of mass, with the gravity only), n the rows of
// one joint. The refinement's own drive model (a FIR of the error) is an approximation, and its
// held-out score also passes where the nominal model is the plant's (measured: decision 0054); the
// tables' held-out fit judges the torque by what uses it.
//
// References (docs/references.md): [Schwarz1978] (BIC), [Ljung1999] (validation on held-out data).
#include <string>
#include <vector>

#include "eval/model_torque.hpp"
#include "ident/identification_config.hpp"
#include "ident/joint_error_io.hpp"
#include "ident/parameter_table.hpp"

namespace imscal::eval {

struct RefinedLinksChoice {
  bool keep_refined = false;
  double bic_change = 0.0;  // < 0: the refined links' tables fit the held-out rows better
  std::vector<double> nominal_fit_percent, refined_fit_percent;  // per joint (NaN: not judged)
};

// `links`: the refinement (ident::LinkMassParameters::refined marks the links it changes);
// nothing is identified when no link is refined (keep_refined false, no change).
RefinedLinksChoice choose_refined_links(const ident::JointErrorLog& log,
                                        const ident::IdentificationConfig& config,
                                        const ModelTorqueSource& nominal,
                                        const ModelTorqueSource& refined,
                                        const std::vector<ident::LinkMassParameters>& links);

// The links with every `refined` mark cleared (the nominal values kept; the estimates stay for
// the report).
std::vector<ident::LinkMassParameters> without_refinement(
    std::vector<ident::LinkMassParameters> links);

// The links refined from the log (eval/mass_refinement.hpp) and chosen as above, logged with
// the caller's name `who`: the model the tables are to be identified with, and the links as the
// table carries them into `links`. std::invalid_argument from the refinement (a short record).
ModelTorqueSource refined_and_chosen_model(const ident::JointErrorLog& log,
                                           const ident::IdentificationConfig& config,
                                           const ModelTorqueSource& nominal,
                                           std::vector<ident::LinkMassParameters>& links,
                                           const std::string& who);

}  // namespace imscal::eval
