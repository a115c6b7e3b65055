#include "eval/transmission_error_order.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "eval/verification.hpp"
#include "ident/identification_config_record.hpp"

namespace imscal::eval {
namespace {

constexpr int kSearchOrder = 20;
// The config's harmonic is the prior: a candidate replaces it when it fits the held-out rows by
// more than this many points better. Measured at the fixed order: on the data-sheet plant (1 per
// revolution) the other candidates beat the prior by at most 0.08 points on A1..A5 (A2: 4 per
// revolution), on the deviating plant (2 per revolution) the right order beat it by 0.22 (A1),
// 0.69 (A2) and 0.95 (A3). A6's fit (~60 %) is flat: a wrong 2.5 gained 0.63 there, and
// left seed-line's max deviation at 0.515 mm (3 cycles, IMS chain).
constexpr double kMinGainPoints = 0.15;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// One joint's held-out figures of an identification: the row-weighted joint-error fit [%] and
// each cell's fit and held-out rows (NaN / 0 where the cell or the joint was not identified).
struct JointHeldOut {
  double fit_percent = kNaN;
  std::vector<double> cell_fit_percent;
  std::vector<std::size_t> cell_rows;
};

std::vector<JointHeldOut> held_out(const ident::JointErrorLog& data,
                                   const ident::IdentificationConfig& config) {
  const IdentifiedTable identified = identify_table(data, config, "order search");
  std::vector<JointHeldOut> out(data.joint_count());
  for (std::size_t j = 0; j < identified.joints.size() && j < out.size(); ++j) {
    const ident::JointIdentification& joint = identified.joints[j];
    out[j].fit_percent = summarize_fit(joint).joint_error_fit_percent;
    for (std::size_t c = 0; c < joint.cells.size(); ++c) {
      const bool fitted = joint.cells[c].status == ident::CellStatus::kIdentified;
      const ident::CellFitFigures& f = joint.parameters.cells[c].figures;
      out[j].cell_fit_percent.push_back(fitted ? f.joint_error_fit_percent : kNaN);
      out[j].cell_rows.push_back(fitted ? f.validation_rows : 0);
    }
  }
  return out;
}

std::vector<double> fits_of(const std::vector<JointHeldOut>& joints) {
  std::vector<double> fits;
  for (const JointHeldOut& j : joints) fits.push_back(j.fit_percent);
  return fits;
}

// The Bayesian information criterion's change when a joint's model takes the second pair,
// summed over the cells held out in both identifications: n ln(RSS_2 / RSS_1) + k ln n per cell
// of n held-out rows, k the pair's coefficients in the cell. The held-out joint error's residual
// sum of squares is (1 - fit / 100)² times the rows' spread, the same rows in both, so
// RSS_2 / RSS_1 = ((100 - fit_2) / (100 - fit_1))². Negative: the pair pays for its coefficients.
// NaN when no cell was held out in both. References: [Schwarz1978].
double second_pair_bic(const JointHeldOut& first, const JointHeldOut& second,
                       int pair_coefficients) {
  double bic = 0.0;
  bool any = false;
  for (std::size_t c = 0; c < first.cell_rows.size() && c < second.cell_rows.size(); ++c) {
    const double n = double(first.cell_rows[c]);
    const double residual_1 = 100.0 - first.cell_fit_percent[c];
    const double residual_2 = 100.0 - second.cell_fit_percent[c];
    if (!(n > 0.0) || first.cell_rows[c] != second.cell_rows[c] || !(residual_1 > 0.0) ||
        !(residual_2 > 0.0))
      continue;
    bic += n * 2.0 * std::log(residual_2 / residual_1) + double(pair_coefficients) * std::log(n);
    any = true;
  }
  return any ? bic : kNaN;
}

// The single-harmonic fit of a candidate on a joint (NaN when not among the candidates).
double fit_of(const TransmissionErrorOrderSearch& search, double harmonic, std::size_t joint) {
  for (std::size_t c = 0; c < search.candidates.size(); ++c)
    if (search.candidates[c] == harmonic) return search.fit_percent[c][joint];
  return kNaN;
}

// Per joint the best single harmonic, its gain over the config's, and the one chosen.
void choose_first_harmonics(TransmissionErrorOrderSearch& search,
                            const ident::IdentificationConfig& config, std::size_t joints);
// Per joint the second harmonic beside the chosen one with the lowest BIC, kept where the BIC
// falls (second_pair_bic).
void search_second_harmonics(TransmissionErrorOrderSearch& search,
                             const std::vector<std::vector<JointHeldOut>>& first_pass,
                             const ident::JointErrorLog& data,
                             const ident::IdentificationConfig& fixed);

}  // namespace

TransmissionErrorOrderSearch search_transmission_error_orders(
    const ident::JointErrorLog& log, const ident::IdentificationConfig& given_config,
    const std::vector<double>& candidates, const ModelTorqueSource* torque_model,
    bool second_harmonic) {
  const ident::IdentificationConfig config =
      given_config.resolved_cycle_s == log.cycle_s
          ? given_config
          : ident::resolve_for_record(given_config, log.robot, log.cycle_s, "the joint errors");
  if (!config.options.transmission_error_input)
    throw std::invalid_argument("order search: the config's models take no transmission error");
  if (candidates.empty()) throw std::invalid_argument("order search: no candidate harmonic");
  for (double h : candidates)
    if (!(h > 0.0)) throw std::invalid_argument("order search: every harmonic must be > 0");
  // The model torques do not depend on the harmonic: attached once for every candidate.
  ident::JointErrorLog data = log;
  if (config.options.model_torque_input && data.model_torque_nm.empty() && torque_model)
    attach_model_torques(data, *torque_model, config.options);

  TransmissionErrorOrderSearch search;
  search.candidates = candidates;
  const std::size_t joints = data.joint_count();
  // One model order for every candidate, so that the fits differ by the transmission-error
  // input only: with the order sweep each candidate also got its own orders, and on the
  // deviating plant's identification record (2 per revolution) A2's best fit went to 3 per
  // revolution. 20: inside the default sweep (1..32), the order that told 2 on A1..A3 there.
  ident::IdentificationConfig fixed = config;
  ident::OrderGrid& grid = fixed.options.grid;
  const int order = std::clamp(kSearchOrder, std::max(grid.na_min, grid.nb_min),
                               std::min(grid.na_max, grid.nb_max));
  grid.na_min = grid.na_max = grid.nb_min = grid.nb_max = order;
  std::vector<std::vector<JointHeldOut>> first_pass;
  for (double h : candidates) {
    ident::IdentificationConfig candidate = fixed;
    candidate.transmission_error_harmonic_per_joint.assign(joints, h);
    first_pass.push_back(held_out(data, candidate));
    search.fit_percent.push_back(fits_of(first_pass.back()));
  }
  choose_first_harmonics(search, config, joints);
  if (second_harmonic) search_second_harmonics(search, first_pass, data, fixed);
  return search;
}

namespace {

void choose_first_harmonics(TransmissionErrorOrderSearch& search,
                            const ident::IdentificationConfig& config, std::size_t joints) {
  const std::vector<double>& candidates = search.candidates;
  for (std::size_t j = 0; j < joints; ++j) {
    const double prior = config.transmission_error_harmonic(j);
    double best = -std::numeric_limits<double>::infinity();
    double prior_fit = std::numeric_limits<double>::quiet_NaN();
    double best_h = prior;
    for (std::size_t c = 0; c < candidates.size(); ++c) {
      const double fit = search.fit_percent[c][j];
      if (!std::isfinite(fit)) continue;
      if (candidates[c] == prior) prior_fit = fit;
      if (fit > best) {
        best = fit;
        best_h = candidates[c];
      }
    }
    const double gain = best - prior_fit;  // NaN when the prior was not fitted
    search.prior_harmonic.push_back(prior);
    search.best_harmonic.push_back(best_h);
    search.gain_points.push_back(std::isfinite(best) ? gain
                                                     : std::numeric_limits<double>::quiet_NaN());
    const bool prior_fitted = std::isfinite(prior_fit);
    search.chosen_harmonic.push_back(
        !std::isfinite(best) || (prior_fitted && !(gain > kMinGainPoints)) ? prior : best_h);
  }
}

// The second pass: once per candidate, every joint with its chosen harmonic and the candidate as
// the second pair (a joint whose chosen harmonic the candidate is goes without the pair).
void search_second_harmonics(TransmissionErrorOrderSearch& search,
                             const std::vector<std::vector<JointHeldOut>>& first_pass,
                             const ident::JointErrorLog& data,
                             const ident::IdentificationConfig& fixed) {
  const std::size_t joints = search.chosen_harmonic.size();
  const std::vector<double>& candidates = search.candidates;
  const int pair_coefficients = 2 * fixed.options.transmission_error_taps;
  std::vector<std::vector<JointHeldOut>> second_pass;
  for (double h : candidates) {
    ident::IdentificationConfig candidate = fixed;
    candidate.transmission_error_harmonic_per_joint = search.chosen_harmonic;
    candidate.options.second_transmission_error_input = true;
    candidate.transmission_error_second_harmonic_per_joint.assign(joints, h);
    for (std::size_t j = 0; j < joints; ++j)
      if (search.chosen_harmonic[j] == h)
        candidate.transmission_error_second_harmonic_per_joint[j] = 0.0;
    second_pass.push_back(held_out(data, candidate));
    std::vector<double> fits = fits_of(second_pass.back());
    for (std::size_t j = 0; j < joints; ++j)
      if (search.chosen_harmonic[j] == h) fits[j] = kNaN;
    search.second_fit_percent.push_back(std::move(fits));
  }
  for (std::size_t j = 0; j < joints; ++j) {
    const auto chosen = std::ranges::find(candidates, search.chosen_harmonic[j]);
    double best_bic = kNaN, best_h = 0.0, best_fit = kNaN;
    for (std::size_t c = 0; c < candidates.size() && chosen != candidates.end(); ++c) {
      if (candidates[c] == search.chosen_harmonic[j]) continue;
      const double bic = second_pair_bic(first_pass[std::size_t(chosen - candidates.begin())][j],
                                         second_pass[c][j], pair_coefficients);
      if (std::isfinite(bic) && !(bic >= best_bic)) {
        best_bic = bic;
        best_h = candidates[c];
        best_fit = search.second_fit_percent[c][j];
      }
    }
    const bool kept = best_bic < 0.0;
    search.second_harmonic.push_back(kept ? best_h : 0.0);
    search.second_best_harmonic.push_back(best_h);
    search.second_bic.push_back(best_bic);
    search.second_gain_points.push_back(best_fit - fit_of(search, search.chosen_harmonic[j], j));
    if (kept) search.second_harmonic_used = true;
  }
}

}  // namespace

std::vector<double> default_order_candidates() {
  return {0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 3.5, 4.0};
}

std::string describe_order_search(const TransmissionErrorOrderSearch& search, std::size_t joint) {
  std::string fits;
  for (std::size_t c = 0; c < search.candidates.size(); ++c)
    fits += fmt::format(" {}:{:.2f}", search.candidates[c], search.fit_percent[c][joint]);
  std::string second;
  if (joint < search.second_harmonic.size())
    second = fmt::format("; second {} ({:+.2f} points, BIC {:+.0f}{})",
                         search.second_best_harmonic[joint], search.second_gain_points[joint],
                         search.second_bic[joint],
                         search.second_harmonic[joint] > 0.0 ? "" : ", not kept");
  return fmt::format(
      "{} per motor revolution (config {}; best {}, {:+.2f} points of held-out fit over the "
      "config's); fits [%]{}{}",
      search.chosen_harmonic[joint], search.prior_harmonic[joint], search.best_harmonic[joint],
      search.gain_points[joint], fits, second);
}

ident::IdentificationConfig with_searched_orders(ident::IdentificationConfig config,
                                                 const TransmissionErrorOrderSearch& search) {
  config.transmission_error_harmonic_per_joint = search.chosen_harmonic;
  config.options.second_transmission_error_input = search.second_harmonic_used;
  config.transmission_error_second_harmonic_per_joint =
      search.second_harmonic_used ? search.second_harmonic : std::vector<double>{};  // 0: none
  return config;
}

}  // namespace imscal::eval
