#include "eval/refined_links_choice.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <utility>

#include "eval/mass_refinement.hpp"
#include "ident/identify_joints.hpp"

namespace imscal::eval {
namespace {

// Each joint's table's held-out joint-error fit [%] and rows with the model's torque.
std::vector<ident::TableFit> table_fits(ident::JointErrorLog log,
                                        const ident::IdentificationConfig& config,
                                        const ModelTorqueSource& model) {
  attach_model_torques(log, model, config.options);
  std::vector<ident::TableFit> fits;
  for (const ident::JointOutcome& outcome : ident::identify_joints(log, config))
    fits.push_back(outcome.result.table_fit);
  return fits;
}

}  // namespace

RefinedLinksChoice choose_refined_links(const ident::JointErrorLog& log,
                                        const ident::IdentificationConfig& config,
                                        const ModelTorqueSource& nominal,
                                        const ModelTorqueSource& refined,
                                        const std::vector<ident::LinkMassParameters>& links) {
  RefinedLinksChoice choice;
  int parameters = 0;
  const int per_link = config.refine_gravity ? 3 : 4;  // gravity: the centre of mass only
  for (const ident::LinkMassParameters& l : links) parameters += l.refined ? per_link : 0;
  if (parameters == 0 || !config.options.model_torque_input) return choice;
  const std::vector<ident::TableFit> before = table_fits(log, config, nominal);
  const std::vector<ident::TableFit> after = table_fits(log, config, refined);
  std::size_t rows = 0;
  for (std::size_t j = 0; j < before.size() && j < after.size(); ++j) {
    const double f0 = before[j].joint_error_fit_percent, f1 = after[j].joint_error_fit_percent;
    choice.nominal_fit_percent.push_back(f0);
    choice.refined_fit_percent.push_back(f1);
    if (!std::isfinite(f0) || !std::isfinite(f1) || f0 >= 100.0 || f1 >= 100.0) continue;
    const double n = double(std::min(before[j].rows, after[j].rows));
    choice.bic_change += n * 2.0 * std::log((100.0 - f1) / (100.0 - f0));
    rows = std::max(rows, std::size_t(n));
  }
  if (rows == 0) return choice;
  choice.bic_change += double(parameters) * std::log(double(rows));
  choice.keep_refined = choice.bic_change < 0.0;
  return choice;
}

ModelTorqueSource refined_and_chosen_model(const ident::JointErrorLog& log,
                                           const ident::IdentificationConfig& config,
                                           const ModelTorqueSource& nominal,
                                           std::vector<ident::LinkMassParameters>& links,
                                           const std::string& who) {
  MassRefinementOptions options;
  options.gravity_first_moments = config.refine_gravity;
  if (config.refine_gravity) {  // the drive model takes the identification's further inputs
    options.further_inputs = ident::extra_inputs_of(config.options);
    options.torque_sign_scale_fraction = config.options.torque_sign_scale_fraction;
    // Rests and slow moves only, where the deflection is the static one: one tap of each input.
    options.gravity_max_speed_rad_s = 0.05;
    options.input_taps = 1;
    options.further_input_taps = 1;
    options.payload_centre_free = true;
    for (std::size_t j = 0; j < options.further_parameters.size(); ++j)
      options.further_parameters[j] = ident::exogenous_parameters(config.joint_options(j), 0.0);
  }
  spdlog::info("{}: refining the model torque's {} from the record", who,
               config.refine_gravity ? "gravity (the links' first moments)" : "link masses");
  const MassRefinement refinement = refine_mass_parameters(log, nominal, options);
  links = table_links(refinement);
  for (std::size_t i = 0; i < links.size(); ++i)
    spdlog::info("{}: link {}: {}", who, i + 1, describe_link(links[i]));
  const RefinedLinksChoice choice =
      choose_refined_links(log, config, nominal, refinement.model, links);
  if (!choice.nominal_fit_percent.empty())
    spdlog::info(
        "{}: tables' held-out joint-error fit with the nominal links [{:.2f}] %, with the "
        "refined [{:.2f}] %: BIC change {:.1f}, {}",
        who, fmt::join(choice.nominal_fit_percent, " "), fmt::join(choice.refined_fit_percent, " "),
        choice.bic_change,
        choice.keep_refined ? "the refined links kept" : "the nominal links kept");
  if (choice.keep_refined) return refinement.model;
  links = without_refinement(std::move(links));
  return nominal;
}

std::vector<ident::LinkMassParameters> without_refinement(
    std::vector<ident::LinkMassParameters> links) {
  for (ident::LinkMassParameters& l : links) l.refined = false;
  return links;
}

}  // namespace imscal::eval
