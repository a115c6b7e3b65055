#pragma once
// The gears' transmission-error order per motor revolution found from the identification record
// instead of taken from the identification config (which then only gives the candidates' prior):
// the record identified once per candidate harmonic, at one fixed model order (na = nb = 20, within
// the config's sweep), and per joint the harmonic whose model fits the record's held-out part
// best (the joint-error fit of its cells, summarize_fit). A gear whose error repeats twice per
// motor revolution, modelled as once, leaves that error unexplained in the held-out rows; the
// right order explains it. A gear whose error has two orders gets the second as a further pair
// of inputs on that joint only, where the held-out rows' BIC says the pair's coefficients pay
// for themselves (a joint without one keeps zero coefficients for the pair). The final
// identification then sweeps the model orders as configured.
#include <string>
#include <vector>

#include "eval/model_torque.hpp"
#include "ident/identification_config.hpp"
#include "ident/joint_error_io.hpp"

namespace imscal::eval {

struct TransmissionErrorOrderSearch {
  std::vector<double> candidates;  // harmonics per motor revolution, as given
  // Held-out joint-error fit [%], [candidate][joint]; NaN where the joint was not identified.
  std::vector<std::vector<double>> fit_percent;
  // Per joint: the candidate that fitted best, its gain in points of fit over the config's
  // harmonic (the prior; NaN when the prior is not among the candidates or nothing fitted), and
  // the harmonic chosen: the best where it gains more than 0.15 points over the prior (or the
  // prior was not fitted), else the prior.
  std::vector<double> prior_harmonic;  // the config's
  std::vector<double> best_harmonic;
  std::vector<double> gain_points;
  std::vector<double> chosen_harmonic;
  // The second harmonic: the record identified once more per candidate with the chosen harmonic
  // and the candidate as a second pair (second_fit_percent [candidate][joint]; NaN where the
  // candidate is the joint's chosen harmonic). Per joint the second candidate with the lowest
  // BIC against the chosen harmonic alone (second_best_harmonic, second_bic: the held-out rows'
  // n ln(RSS ratio) + the pair's coefficients x ln n, summed over the cells; its gain in points
  // of fit beside it), and the second harmonic kept: that candidate where its BIC is negative,
  // else 0 (the joint's cells get zero coefficients for the pair). second_harmonic_used: some
  // joint kept one (the table then has the pair).
  std::vector<std::vector<double>> second_fit_percent;
  std::vector<double> second_best_harmonic;
  std::vector<double> second_bic;
  std::vector<double> second_gain_points;
  std::vector<double> second_harmonic;
  bool second_harmonic_used = false;
};

// Every candidate must be > 0 and the config's models must take the transmission-error inputs
// (std::invalid_argument otherwise). torque_model as for identify_table.
// second_harmonic: also the second pass (docs/decisions/0028, 0042).
TransmissionErrorOrderSearch search_transmission_error_orders(
    const ident::JointErrorLog& log, const ident::IdentificationConfig& config,
    const std::vector<double>& candidates, const ModelTorqueSource* torque_model = nullptr,
    bool second_harmonic = false);

// The candidates of the commands' searches: 0.5 .. 4 per motor revolution in steps of 0.5 (a
// gear's error repeats at its stages' tooth and lobe counts over the motor revolution; halves for
// a stage that turns at half the motor's speed).
std::vector<double> default_order_candidates();

// One joint's outcome in a line: the chosen harmonic, the prior, the best, its gain and every
// candidate's fit; the second harmonic and its gain.
std::string describe_order_search(const TransmissionErrorOrderSearch& search, std::size_t joint);

// The config with the search's harmonic per joint (and the second harmonics, when used).
ident::IdentificationConfig with_searched_orders(ident::IdentificationConfig config,
                                                 const TransmissionErrorOrderSearch& search);

}  // namespace imscal::eval
