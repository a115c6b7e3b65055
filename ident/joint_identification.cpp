#include "ident/joint_identification.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace imscal::ident {
namespace {

using Ranges = std::vector<std::pair<std::size_t, std::size_t>>;

std::size_t rows_of(std::span<const IoSegment> views, std::size_t first_row) {
  std::size_t rows = 0;
  for (const auto& v : views)
    if (v.output.size() > first_row) rows += v.output.size() - first_row;
  return rows;
}

// NRMSE fit [%] streamed over pieces (ident/model_validation.hpp's fit_percent takes one
// contiguous series): 100 (1 - |residual| / |reference - mean(reference)|); NaN when the
// reference is constant.
struct NrmseFit {
  double misfit = 0.0, sum = 0.0, sum_sq = 0.0;
  std::size_t count = 0;
  void add(double residual, double reference) {
    misfit += residual * residual;
    sum += reference;
    sum_sq += reference * reference;
    ++count;
  }
  double percent() const {
    const double spread = count ? sum_sq - sum * sum / double(count) : 0.0;
    if (!(spread > 0.0)) return std::numeric_limits<double>::quiet_NaN();
    return 100.0 * (1.0 - std::sqrt(misfit / spread));
  }
};

// NRMSE fit [%] of the free-run joint error on the views: what the precontrol adds,
// Δq̂(k) = q_d(k-d) - (ŷ(k) - l s(k)) (eq. 2 + eq. 3), against the error it has to cancel at
// that cycle, Δq(k) = q_d(k) - q_m(k). With y = q_m + l s the fitted output,
// Δq - Δq̂ = q_d(k) - q_d(k-d) + ŷ - y: for d > 0 the desired motion over the dead time is part
// of the misfit (the error is measured against q_d(k), not q_d(k-d)). NaN when the joint error
// is constant.
double joint_error_fit(const ArxModel& model, std::span<const IoSegment> views,
                       std::span<const double> output, std::span<const double> q_desired,
                       std::span<const double> q_measured) {
  const auto first = std::size_t(model.structure().max_lag());
  const auto d = std::size_t(model.structure().dead_time);
  std::vector<double> simulated;
  NrmseFit fit;
  for (const IoSegment& v : views) {
    const std::size_t offset = std::size_t(v.output.data() - output.data());
    simulated.resize(v.output.size());
    model.simulate(v, simulated);
    for (std::size_t k = first; k < v.output.size(); ++k)
      fit.add(v.input[k] - v.input[k - d] + simulated[k] - v.output[k],
              q_desired[offset + k] - q_measured[offset + k]);
  }
  return fit.percent();
}

// NRMSE fit [%] of the command an inverse-form error model predicts, q̂_d = y + ê (free run of
// the error model on the link increments), against the command that was given, q_d; the views
// are (w, e) views into `error` (e = q_d - y). NaN when q_d is constant.
double command_fit(const ArxModel& error_model, std::span<const IoSegment> views,
                   std::span<const double> error, std::span<const double> q_desired) {
  const auto first = std::size_t(error_model.structure().max_lag());
  std::vector<double> simulated;
  NrmseFit fit;
  for (const IoSegment& v : views) {
    const std::size_t offset = std::size_t(v.output.data() - error.data());
    simulated.resize(v.output.size());
    error_model.simulate(v, simulated);
    for (std::size_t k = first; k < v.output.size(); ++k)
      fit.add(simulated[k] - v.output[k], q_desired[offset + k]);
  }
  return fit.percent();
}

// Fills `cell` from its nearest identified cell (band steps, then the lower number).
void fill_from_nearest(const CellGrid& grid, std::vector<CellIdentification>& reports,
                       std::vector<CellParameters>& cells, int cell) {
  int best = -1, best_distance = std::numeric_limits<int>::max();
  for (int other = 0; other < grid.cell_count(); ++other) {
    if (reports[std::size_t(other)].status != CellStatus::kIdentified) continue;
    const int distance = grid.band_distance(cell, other);
    if (distance < best_distance) best = other, best_distance = distance;
  }
  auto& report = reports[std::size_t(cell)];
  auto& target = cells[std::size_t(cell)];
  const auto& source = cells[std::size_t(best)];
  target.status = report.status = CellStatus::kFilled;
  target.filled_from = report.filled_from = best;
  target.reason = report.reason;
  target.structure = source.structure;
  target.a = source.a;
  target.b = source.b;
  target.c = source.c;
  target.figures = source.figures;
  target.figures.estimation_rows = report.estimation_rows;
  target.figures.validation_rows = report.validation_rows;
}

// The last validation_fraction of every segment (or of every block of validation_block_s) held
// out: (estimation, held-out) ranges.
std::pair<Ranges, Ranges> split_held_out(
    std::span<const std::pair<std::size_t, std::size_t>> segments, double cycle_s,
    const JointIdentificationOptions& options) {
  Ranges estimation, held_out;
  const std::size_t block =
      options.validation_block_s > 0.0
          ? std::max<std::size_t>(1,
                                  std::size_t(std::llround(options.validation_block_s / cycle_s)))
          : std::numeric_limits<std::size_t>::max();
  for (const auto& [segment_begin, segment_end] : segments) {
    for (std::size_t begin = segment_begin; begin < segment_end;) {
      // The last block takes the remainder when it would be shorter than half a block.
      std::size_t end = segment_end - begin > block ? begin + block : segment_end;
      if (segment_end - end < block / 2) end = segment_end;
      const std::size_t len = end - begin;
      const auto cut = end - std::size_t(std::llround(options.validation_fraction * double(len)));
      if (cut > begin) estimation.emplace_back(begin, cut);
      if (end > cut) held_out.emplace_back(cut, end);
      begin = end;
    }
  }
  return {std::move(estimation), std::move(held_out)};
}

// The joint's RMS model torque times torque_sign_scale_fraction: the scale of tanh(τ / τ_s).
double torque_sign_scale_of(const std::string& name,
                            std::span<const std::pair<std::size_t, std::size_t>> segments,
                            std::span<const double> model_torque_nm,
                            const JointIdentificationOptions& options) {
  double sum_sq = 0.0;
  std::size_t count = 0;
  for (const auto& [begin, end] : segments)
    for (std::size_t k = begin; k < end; ++k, ++count)
      sum_sq += model_torque_nm[k] * model_torque_nm[k];
  const double scale =
      count ? options.torque_sign_scale_fraction * std::sqrt(sum_sq / double(count)) : 0.0;
  if (!(scale > 0.0))
    throw std::runtime_error(fmt::format("joint {}: the model torque is zero throughout", name));
  return scale;
}

// The signals an ARX structure of the options' form is fitted to, over the whole record: (q_d, y)
// in the angle form, (w, e) in the joint-error and inverse forms (w: desired increments, or the
// link's increments P cycles ahead; 0 beyond the end of a run, where the robot stands), and the
// further inputs (multi-input form), P cycles ahead like w and held at the end of a run: the
// model torque along the driver's path, the direction of the driver's motion, the side of the
// gear the torque presses on (tanh(τ / torque_sign_scale_nm)).
struct FitSignals {
  std::vector<double> input, output;  // (w, e); empty in the angle form
  std::array<std::vector<double>, kMaxExtraInputs> extra;
  int extra_count = 0;

  IoSegment with_extras(std::span<const double> in, std::span<const double> out) const {
    IoSegment all{in, out, {}, extra_count};
    for (int e = 0; e < extra_count; ++e) all.extra[std::size_t(e)] = extra[std::size_t(e)];
    return all;
  }
};

// The further inputs' values at every sample of the segments, input after input, along the
// path `driver` (its speed over one cycle, 0 at a segment's first sample) with the model torque
// (0 when not given). A gear mode's filter restarts at each segment's first sample.
std::vector<std::vector<double>> exogenous_signals(
    std::span<const TableInput> inputs, const ExogenousParameters& parameters,
    std::span<const double> driver, std::span<const double> model_torque_nm,
    std::span<const std::pair<std::size_t, std::size_t>> segments, double cycle_s) {
  const std::size_t n = driver.size();
  std::vector<std::vector<double>> values(inputs.size(), std::vector<double>(n, 0.0));
  std::array<double, kMaxExtraInputs> sample_values{};
  ExogenousFilterState filter;
  for (const auto& [begin, end] : segments) {
    restart_exogenous_filter(filter, parameters, cycle_s);
    for (std::size_t k = begin; k < end; ++k) {
      ExogenousSample sample;
      sample.angle_rad = driver[k];
      sample.speed_rad_s = k > begin ? (driver[k] - driver[k - 1]) / cycle_s : 0.0;
      sample.model_torque_nm = model_torque_nm.empty() ? 0.0 : model_torque_nm[k];
      exogenous_values(inputs, parameters, sample, filter, sample_values.data());
      for (std::size_t e = 0; e < inputs.size(); ++e) values[e][k] = sample_values[e];
    }
  }
  return values;
}

bool is_error_form(const JointIdentificationOptions& options) {
  return options.form == ArxModelForm::kJointError || options.form == ArxModelForm::kInverse;
}

// output: the play-free joint angle y.
FitSignals make_fit_signals(std::span<const double> q_desired, std::span<const double> output,
                            std::span<const std::pair<std::size_t, std::size_t>> segments,
                            double cycle_s, const JointIdentificationOptions& options,
                            std::span<const double> model_torque_nm, double torque_sign_scale_nm) {
  const std::size_t n = q_desired.size();
  const bool inverse = options.form == ArxModelForm::kInverse;
  const auto preview = std::size_t(options.preview_cycles);
  // The path the model's input follows: the desired angles, or (inverse form) the play-free link
  // angle y, whose increments the precontrol is later fed from the desired path.
  const std::span<const double> driver = inverse ? output : q_desired;
  FitSignals s;
  if (is_error_form(options)) {
    s.input.assign(n, 0.0);
    s.output.resize(n);
    for (std::size_t k = 0; k < n; ++k) s.output[k] = q_desired[k] - output[k];
    for (const auto& [begin, end] : segments)
      for (std::size_t k = begin; k + preview < end; ++k)
        if (k + preview > begin) s.input[k] = driver[k + preview] - driver[k + preview - 1];
  }
  const std::vector<TableInput> inputs = extra_inputs_of(options);
  const std::vector<std::vector<double>> values =
      exogenous_signals(inputs, exogenous_parameters(options, torque_sign_scale_nm), driver,
                        model_torque_nm, segments, cycle_s);
  s.extra_count = int(inputs.size());
  for (std::size_t e = 0; e < inputs.size(); ++e) {
    s.extra[e].resize(n);
    for (const auto& [begin, end] : segments)
      for (std::size_t k = begin; k < end; ++k)
        s.extra[e][k] = values[e][std::min(k + preview, end - 1)];
  }
  return s;
}

// y = q_m + l s: the joint lags by l in the direction of motion, so adding l s restores the
// play-free angle (no change without an identified, non-negative l).
std::vector<double> play_free_angle(std::span<const double> q_desired,
                                    std::span<const double> q_measured,
                                    std::span<const std::pair<std::size_t, std::size_t>> segments,
                                    double cycle_s, const BacklashOptions& options,
                                    const BacklashEstimate& backlash) {
  std::vector<double> output(q_measured.begin(), q_measured.end());
  if (!backlash.identified || backlash.l_rad < 0.0) return output;
  const std::vector<double> s =
      motion_direction(q_desired, segments, cycle_s, options.min_speed_rad_s, backlash.lag_samples);
  for (std::size_t k = 0; k < output.size(); ++k) output[k] += backlash.l_rad * s[k];
  return output;
}

}  // namespace

const char* to_string(ArxModelForm form) {
  switch (form) {
    case ArxModelForm::kJointError:
      return "joint-error";
    case ArxModelForm::kAngle:
      return "angle";
    case ArxModelForm::kInverse:
      return "inverse";
  }
  return "?";
}

const char* to_string(GearModePairs pairs) {
  switch (pairs) {
    case GearModePairs::kNone:
      return "none";
    case GearModePairs::kInstead:
      return "instead";
    case GearModePairs::kBeside:
      return "beside";
  }
  return "?";
}

GearModePairs gear_mode_pairs_from_string(const std::string& text) {
  for (const GearModePairs pairs :
       {GearModePairs::kNone, GearModePairs::kInstead, GearModePairs::kBeside})
    if (text == to_string(pairs)) return pairs;
  throw std::invalid_argument("gear-mode pairs '" + text +
                              "' unknown; expected none, instead or beside");
}

ArxModelForm arx_model_form_from_string(const std::string& text) {
  for (const ArxModelForm form :
       {ArxModelForm::kJointError, ArxModelForm::kAngle, ArxModelForm::kInverse})
    if (text == to_string(form)) return form;
  throw std::invalid_argument("model form '" + text +
                              "' unknown; expected joint-error, angle or inverse");
}

ArxModel angle_form_of_error_model(const ArxModel& error_model) {
  const ArxStructure& e = error_model.structure();
  const int na = e.na, delta = e.dead_time, nb_e = e.nb;
  const int nb = std::max(na + 1, delta + nb_e + 1);
  // B(z) = A(z) - z^-δ (1 - z^-1) β(z), coefficients of z^0 .. z^-(nb-1).
  Eigen::VectorXd b = Eigen::VectorXd::Zero(nb);
  b(0) = 1.0;
  for (int i = 1; i <= na; ++i) b(i) += error_model.a()(i - 1);
  for (int j = 0; j < nb_e; ++j) {
    b(delta + j) -= error_model.b()(j);
    b(delta + j + 1) += error_model.b()(j);
  }
  if (e.extra_inputs == 0)
    return ArxModel({na, nb, 0}, error_model.a(), b, error_model.sample_time_s());
  // Further inputs: q̂ = x - e, so their coefficients change sign and move behind δ zeros (the
  // angle form has dead time 0): C'_e(z) = -z^-δ C_e(z), δ + nx[e] coefficients each.
  ArxStructure angle{na, nb, 0, e.extra_inputs, {}};
  for (int x = 0; x < e.extra_inputs; ++x) angle.nx[std::size_t(x)] = delta + e.nx[std::size_t(x)];
  Eigen::VectorXd c = Eigen::VectorXd::Zero(angle.extra_coefficient_count());
  for (int x = 0; x < e.extra_inputs; ++x)
    for (int j = 0; j < e.nx[std::size_t(x)]; ++j)
      c(angle.extra_offset(x) + delta + j) = -error_model.c()(e.extra_offset(x) + j);
  return ArxModel(angle, error_model.a(), b, c, error_model.sample_time_s());
}

std::vector<TableInput> extra_inputs_of(const JointIdentificationOptions& options) {
  std::vector<TableInput> inputs;
  if (options.model_torque_input) inputs.push_back(TableInput::kModelTorque);
  if (options.direction_input) inputs.push_back(TableInput::kDirection);
  if (options.torque_sign_input) inputs.push_back(TableInput::kTorqueSign);
  if (!options.transmission_error_input) return inputs;
  const bool second = options.second_transmission_error_input;
  using enum TableInput;
  if (options.transmission_error_mode_pairs != GearModePairs::kInstead) {
    inputs.insert(inputs.end(), {kTransmissionErrorSin, kTransmissionErrorCos});
    if (second) inputs.insert(inputs.end(), {kTransmissionError2Sin, kTransmissionError2Cos});
  }
  if (options.transmission_error_mode_pairs != GearModePairs::kNone) {
    inputs.insert(inputs.end(), {kTransmissionErrorModeSin, kTransmissionErrorModeCos});
    if (second)
      inputs.insert(inputs.end(), {kTransmissionError2ModeSin, kTransmissionError2ModeCos});
  }
  return inputs;
}

int extra_input_count(const JointIdentificationOptions& options) {
  return int(extra_inputs_of(options).size());
}

int extra_input_taps(TableInput input, const JointIdentificationOptions& options) {
  switch (input) {
    case TableInput::kModelTorque:
    case TableInput::kDirection:
      return options.input_taps;
    case TableInput::kTorqueSign:
      return options.torque_sign_taps;
    case TableInput::kTransmissionErrorSin:
    case TableInput::kTransmissionErrorCos:
    case TableInput::kTransmissionError2Sin:
    case TableInput::kTransmissionError2Cos:
      return options.transmission_error_taps;
    case TableInput::kTransmissionErrorModeSin:
    case TableInput::kTransmissionErrorModeCos:
    case TableInput::kTransmissionError2ModeSin:
    case TableInput::kTransmissionError2ModeCos:
      return options.transmission_error_mode_pairs == GearModePairs::kBeside
                 ? options.transmission_error_mode_taps
                 : options.transmission_error_taps;
  }
  return options.input_taps;
}

int longest_extra_input_taps(const JointIdentificationOptions& options) {
  const JointIdentificationOptions& o = options;
  return std::max({o.model_torque_input || o.direction_input ? o.input_taps : 0,
                   o.torque_sign_input ? o.torque_sign_taps : 0,
                   o.transmission_error_input ? o.transmission_error_taps : 0,
                   o.transmission_error_mode_pairs == GearModePairs::kBeside
                       ? o.transmission_error_mode_taps
                       : 0});
}

ExogenousParameters exogenous_parameters(const JointIdentificationOptions& options,
                                         double torque_sign_scale_nm) {
  ExogenousParameters p;
  p.direction_speed_scale_rad_s = options.direction_speed_scale_rad_s;
  p.torque_sign_scale_nm = torque_sign_scale_nm;
  p.transmission_error_rad_per_rad = options.transmission_error_rad_per_rad;
  p.transmission_error_2_rad_per_rad =
      options.second_transmission_error_input ? options.transmission_error_2_rad_per_rad : 0.0;
  p.transmission_error_compliance_rad_per_nm = options.transmission_error_compliance_rad_per_nm;
  if (options.transmission_error_mode_pairs != GearModePairs::kNone) {
    p.transmission_error_mode_rad_s = options.transmission_error_mode_rad_s;
    p.transmission_error_mode_damping = options.transmission_error_mode_damping;
  }
  return p;
}

JointParameters neutral_joint_parameters(const std::string& name, double max_speed_rad_s,
                                         const std::string& reason, int extra_inputs) {
  JointParameters p;
  p.name = name;
  p.dimensions = {{OperatingQuantity::kSpeed, {0.0, max_speed_rad_s}}};
  p.backlash_l_rad = 0.0;
  p.backlash_identified = false;
  CellParameters cell;
  cell.bands = {0};
  cell.status = CellStatus::kNeutral;
  cell.reason = "not identified, neutral pass-through model (no compensation): " + reason;
  cell.structure = {0, 1, 0, extra_inputs, {}};
  for (int e = 0; e < extra_inputs; ++e) cell.structure.nx[std::size_t(e)] = 1;
  cell.b = {1.0};
  cell.c.assign(std::size_t(extra_inputs), 0.0);  // the further inputs do nothing
  p.cells.push_back(cell);
  return p;
}

JointIdentification neutral_joint_identification(const std::string& name, double max_speed_rad_s,
                                                 const std::string& reason, int extra_inputs) {
  JointIdentification out;
  out.parameters = neutral_joint_parameters(name, max_speed_rad_s, reason, extra_inputs);
  out.backlash.reason = "joint not identified: no backlash term";
  out.cells.resize(1);
  out.cells[0].status = CellStatus::kNeutral;
  out.cells[0].label = "neutral";
  out.cells[0].reason = out.parameters.cells[0].reason;
  return out;
}

namespace {

// The whole table's held-out fit (ident/table_fit.hpp): each cell predicts with the model the
// precontrol holds there (a filled cell with its source's); in the joint-error form that is the
// angle form of the fitted error model, as the cell's own figure uses it.
TableFit table_fit_of(const JointIdentification& joint, const CellGrid& grid, TableFitInput input,
                      bool angle_form_of_fit) {
  std::vector<std::optional<ArxModel>> models(joint.cells.size());
  for (std::size_t c = 0; c < joint.cells.size(); ++c) {
    const CellIdentification& cell = joint.cells[c];
    if (cell.status != CellStatus::kIdentified || !cell.fit) continue;
    models[c] = angle_form_of_fit ? angle_form_of_error_model(cell.fit->model) : cell.fit->model;
  }
  input.grid = &grid;
  for (const CellIdentification& cell : joint.cells) {
    const int source = cell.status == CellStatus::kFilled ? cell.filled_from : cell.cell;
    const bool known = source >= 0 && models[std::size_t(source)].has_value();
    input.models.push_back(known ? &*models[std::size_t(source)] : nullptr);
  }
  return table_held_out_fit(input);
}

}  // namespace

JointIdentification identify_joint(const std::string& name, std::span<const double> q_desired,
                                   std::span<const double> q_measured,
                                   std::span<const double> payload,
                                   std::span<const std::pair<std::size_t, std::size_t>> segments,
                                   double cycle_s, const CellGrid& grid,
                                   const JointIdentificationOptions& options,
                                   std::span<const double> model_torque_nm) {
  const std::size_t n = q_desired.size();
  if (q_measured.size() != n || payload.size() != n)
    throw std::invalid_argument("identify_joint: signal lengths differ");
  if (!(options.validation_fraction >= 0.0 && options.validation_fraction < 1.0))
    throw std::invalid_argument("identify_joint: validation_fraction must be in [0, 1)");
  JointIdentification out;
  out.parameters.name = name;
  out.parameters.dimensions = grid.dimensions();

  // 1. Backlash and the output without it, y = q_m + l s (play_free_angle).
  if (options.identify_backlash) {
    out.backlash = identify_backlash(q_desired, q_measured, segments, cycle_s, options.backlash);
    if (out.backlash.identified) {
      out.parameters.backlash_identified = true;
      // A negative estimate (noise around a play-free joint) is kept in the report but the
      // table holds l >= 0: equation 3 has no meaning for l < 0.
      out.parameters.backlash_l_rad = std::max(out.backlash.l_rad, 0.0);
      out.parameters.backlash_l_sigma_rad = out.backlash.l_sigma_rad;
      // The precontrol sees its input P cycles ahead in the inverse form: the same direction
      // signal is then P cycles further back in its history.
      out.parameters.backlash_lag_samples =
          out.backlash.lag_samples + std::size_t(std::max(options.preview_cycles, 0));
      if (out.backlash.l_rad < 0.0) {
        out.parameters.backlash_identified = false;
        out.backlash.reason =
            fmt::format("estimate {:.3g} rad is negative: no backlash", out.backlash.l_rad);
      }
    }
  } else {
    out.backlash.reason = "backlash identification disabled";
  }
  const std::vector<double> output =
      play_free_angle(q_desired, q_measured, segments, cycle_s, options.backlash, out.backlash);

  // The envelope of the joint error in the data (the supervisor's default tolerances): its
  // largest magnitude, and its largest rate over 8 ms (central difference over ±2 cycles: the
  // bandwidth of the precontrol's smoother, whose rate the supervisor watches, with measurement
  // noise averaged over 4 cycles).
  for (const auto& [begin, end] : segments) {
    constexpr std::size_t kHalf = 2;
    for (std::size_t k = begin; k < end; ++k) {
      const double e = q_desired[k] - q_measured[k];
      out.parameters.offset_envelope_rad =
          std::max(out.parameters.offset_envelope_rad, std::abs(e));
      if (k < begin + kHalf || k + kHalf >= end) continue;
      const double rate = ((q_desired[k + kHalf] - q_measured[k + kHalf]) -
                           (q_desired[k - kHalf] - q_measured[k - kHalf])) /
                          (2.0 * kHalf * cycle_s);
      out.parameters.offset_rate_envelope_rad_s =
          std::max(out.parameters.offset_rate_envelope_rad_s, std::abs(rate));
    }
  }

  // 2. Estimation and held-out parts of every segment.
  const std::pair<Ranges, Ranges> split = split_held_out(segments, cycle_s, options);
  const Ranges& estimation = split.first;
  const Ranges& held_out = split.second;

  // The signals the structure is fitted to (make_fit_signals).
  const bool inverse = options.form == ArxModelForm::kInverse;
  const bool error_form = is_error_form(options);
  if (options.preview_cycles < 0 || (options.preview_cycles > 0 && !inverse))
    throw std::invalid_argument("identify_joint: preview_cycles >= 0, and only in inverse form");
  if ((options.model_torque_input || options.torque_sign_input) && model_torque_nm.size() != n)
    throw std::invalid_argument(
        "identify_joint: the model torque and torque-sign inputs need one model torque per "
        "sample");
  if (options.torque_sign_input)
    out.parameters.torque_sign_scale_nm =
        torque_sign_scale_of(name, segments, model_torque_nm, options);
  if (options.transmission_error_input) {
    if (!(options.transmission_error_rad_per_rad > 0.0))
      throw std::invalid_argument(
          "identify_joint: the transmission-error inputs need a phase "
          "rate > 0 (harmonic x gear ratio)");
    if (!(options.transmission_error_compliance_rad_per_nm >= 0.0) ||
        (options.transmission_error_compliance_rad_per_nm > 0.0 && model_torque_nm.size() != n))
      throw std::invalid_argument(
          "identify_joint: the transmission error's compliance must be "
          ">= 0, and > 0 needs the model torque");
    out.parameters.transmission_error_rad_per_rad = options.transmission_error_rad_per_rad;
    out.parameters.transmission_error_compliance_rad_per_nm =
        options.transmission_error_compliance_rad_per_nm;
    if (options.transmission_error_mode_pairs != GearModePairs::kNone) {
      out.parameters.transmission_error_mode_rad_s = options.transmission_error_mode_rad_s;
      out.parameters.transmission_error_mode_damping = options.transmission_error_mode_damping;
    }
    if (options.second_transmission_error_input) {
      if (!(options.transmission_error_2_rad_per_rad > 0.0) ||
          options.transmission_error_2_rad_per_rad == options.transmission_error_rad_per_rad)
        throw std::invalid_argument(
            "identify_joint: the second transmission-error inputs need a phase rate > 0 other "
            "than the first's");
      out.parameters.transmission_error_2_rad_per_rad = options.transmission_error_2_rad_per_rad;
    }
  }
  const FitSignals signals_of_fit =
      make_fit_signals(q_desired, output, segments, cycle_s, options, model_torque_nm,
                       out.parameters.torque_sign_scale_nm);
  const std::vector<double>& fit_output = signals_of_fit.output;
  // (input, output) of the fitted structure, and of the stored angle-form model (forward forms).
  const IoSegment fit_signals = error_form
                                    ? signals_of_fit.with_extras(signals_of_fit.input, fit_output)
                                    : signals_of_fit.with_extras(q_desired, output);
  const IoSegment angle_signals = signals_of_fit.with_extras(q_desired, output);

  // 3. Cells and their runs (one pass each).
  const OperatingSignals signals = operating_signals(q_desired, segments, cycle_s);
  const std::vector<int> cell_of = assign_cells(grid, q_desired, payload, signals);
  const auto est_runs = cell_runs(cell_of, grid.cell_count(), estimation);
  const auto val_runs = cell_runs(cell_of, grid.cell_count(), held_out);

  OrderSelectionOptions sweep_options;
  sweep_options.grid = options.grid;
  const std::vector<TableInput> inputs = extra_inputs_of(options);
  for (std::size_t e = 0; e < inputs.size(); ++e)
    sweep_options.grid.extra_taps[e] = extra_input_taps(inputs[e], options);
  sweep_options.criterion = options.criterion;
  sweep_options.min_relative_pivot = options.min_relative_pivot;
  sweep_options.final_fit = options.fit;
  sweep_options.validation_fraction = 0.0;  // the held-out runs are passed explicitly
  // History before each run: every lag of the grid, the further inputs' too, so that the sweep
  // and the final fit (on the sweep's Gram matrix) take every sample of the run as a row.
  const OrderGrid& g = options.grid;
  int longest_lag = std::max(g.na_max, g.dead_time_max + g.nb_max - 1);
  for (int e = 0; e < signals_of_fit.extra_count; ++e)
    longest_lag =
        std::max(longest_lag, g.dead_time_max + sweep_options.grid.extra_taps[std::size_t(e)] - 1);
  const auto history = std::size_t(longest_lag);

  out.cells.resize(std::size_t(grid.cell_count()));
  out.parameters.cells.resize(std::size_t(grid.cell_count()));
  for (int cell = 0; cell < grid.cell_count(); ++cell) {
    auto& report = out.cells[std::size_t(cell)];
    auto& params = out.parameters.cells[std::size_t(cell)];
    report.cell = cell;
    report.label = grid.label(cell);
    params.bands = grid.bands_of(cell);
    const auto& runs = est_runs[std::size_t(cell)];
    double speed_sq = 0.0;
    std::size_t samples = 0;
    for (const CellRun& r : runs)
      for (std::size_t k = r.begin; k < r.end; ++k, ++samples)
        speed_sq += signals.speed_rad_s[k] * signals.speed_rad_s[k];
    report.rms_speed_rad_s = samples ? std::sqrt(speed_sq / double(samples)) : 0.0;
    const auto sweep_est = run_views(runs, fit_signals, history);
    const auto sweep_val = run_views(val_runs[std::size_t(cell)], fit_signals, history);
    report.estimation_rows = rows_of(sweep_est, history);
    report.validation_rows = rows_of(sweep_val, history);
    auto reject = [&](std::string reason) {
      report.status = CellStatus::kFilled;
      report.reason = std::move(reason);
    };
    if (report.estimation_rows < options.min_rows_per_cell) {
      reject(fmt::format("{} estimation rows, fewer than min_rows_per_cell = {}",
                         report.estimation_rows, options.min_rows_per_cell));
      continue;
    }
    if (report.rms_speed_rad_s < options.min_rms_speed_rad_s) {
      reject(fmt::format("too little excitation: RMS desired speed {:.3g} rad/s < {:.3g} rad/s",
                         report.rms_speed_rad_s, options.min_rms_speed_rad_s));
      continue;
    }
    try {
      // The final fit on the sweep's rows, from its Gram matrix (no further pass to build one).
      LaggedGram gram;
      report.sweep = sweep_arx_orders(sweep_est, sweep_options, sweep_val, &gram);
      report.fit = fit_arx(sweep_est, report.sweep->chosen, gram, options.fit);
    } catch (const std::exception& e) {
      reject(fmt::format("fit failed: {}", e.what()));
      continue;
    }
    // Same poles in either form (A(z) is shared).
    report.stability = check_stability(report.fit->model, options.stability_margin);
    if (!report.stability->stable) {
      reject(report.stability->reason);
      continue;
    }
    const ArxModel model =
        error_form ? angle_form_of_error_model(report.fit->model) : report.fit->model;
    params.structure = model.structure();
    params.a.assign(model.a().data(), model.a().data() + model.a().size());
    params.b.assign(model.b().data(), model.b().data() + model.b().size());
    params.c.assign(model.c().data(), model.c().data() + model.c().size());
    CellFitFigures& f = params.figures;
    f.estimation_rows = report.fit->row_count;
    f.spectral_radius = report.stability->spectral_radius;
    f.one_step_fit_percent = f.simulation_fit_percent = f.joint_error_fit_percent =
        f.residual_rms_rad = std::numeric_limits<double>::quiet_NaN();
    if (inverse) {
      // The inverse model's figures are those of its error model on (w, e): the one-step and
      // free-run fits of the offset, residual tests against the link increments; the angle
      // fit is that of the command it predicts, q_d = y + ê.
      const auto val_views = run_views(val_runs[std::size_t(cell)], fit_signals,
                                       std::size_t(report.fit->model.structure().max_lag()));
      if (!val_views.empty()) {
        report.validation = validate_arx(report.fit->model, val_views, options.validation);
        f.validation_rows = report.validation->sample_count;
        f.one_step_fit_percent = report.validation->one_step_fit_percent;
        f.joint_error_fit_percent = report.validation->simulation_fit_percent;
        f.simulation_fit_percent = command_fit(report.fit->model, val_views, fit_output, q_desired);
        f.residual_rms_rad = report.validation->residual_rms;
        f.whiteness_passed = report.validation->residual_whiteness.passed;
        f.input_residual_passed = report.validation->input_residual.passed;
      }
      continue;
    }
    const auto val_views = run_views(val_runs[std::size_t(cell)], angle_signals,
                                     std::size_t(model.structure().max_lag()));
    try {
      if (!val_views.empty()) {
        report.validation = validate_arx(model, val_views, options.validation);
        f.validation_rows = report.validation->sample_count;
        f.one_step_fit_percent = report.validation->one_step_fit_percent;
        f.simulation_fit_percent = report.validation->simulation_fit_percent;
        f.residual_rms_rad = report.validation->residual_rms;
        f.joint_error_fit_percent =
            joint_error_fit(model, val_views, output, q_desired, q_measured);
        f.whiteness_passed = report.validation->residual_whiteness.passed;
        f.input_residual_passed = report.validation->input_residual.passed;
      }
    } catch (const std::invalid_argument& e) {
      spdlog::warn("joint {} cell {}: no validation figures ({})", name, report.label, e.what());
    }
  }

  // 5. Fill the cells that failed from their nearest identified neighbour, with the reason.
  bool any = false;
  std::string reasons;
  for (const auto& r : out.cells) {
    any = any || r.status == CellStatus::kIdentified;
    reasons += fmt::format("\n  cell {} ({}): {}", r.cell, r.label,
                           r.reason.empty() ? "identified" : r.reason);
  }
  if (!any)
    throw std::runtime_error(
        fmt::format("joint {}: no cell could be identified:{}", name, reasons));
  for (int cell = 0; cell < grid.cell_count(); ++cell) {
    if (out.cells[std::size_t(cell)].status == CellStatus::kIdentified) continue;
    fill_from_nearest(grid, out.cells, out.parameters.cells, cell);
    const auto& r = out.cells[std::size_t(cell)];
    spdlog::warn("joint {} cell {} ({}) filled from cell {}: {}", name, cell, r.label,
                 r.filled_from, r.reason);
  }
  out.table_fit = table_fit_of(out, grid,
                               {.error_models = inverse,
                                .model_signals = inverse ? fit_signals : angle_signals,
                                .q_desired = q_desired,
                                .q_measured = q_measured,
                                .payload_kg = payload,
                                .operating = &signals,
                                .segments = segments,
                                .held_out = held_out},
                               error_form && !inverse);
  return out;
}

HeldOutReplay replay_held_out_fit(const JointIdentification& identified,
                                  std::span<const double> q_desired,
                                  std::span<const double> q_measured,
                                  std::span<const double> payload,
                                  std::span<const std::pair<std::size_t, std::size_t>> segments,
                                  double cycle_s, const CellGrid& grid,
                                  const JointIdentificationOptions& options,
                                  std::span<const double> model_torque_nm) {
  const std::size_t n = q_desired.size();
  if (q_measured.size() != n || payload.size() != n)
    throw std::invalid_argument("replay_held_out_fit: signal lengths differ");
  if ((options.model_torque_input || options.torque_sign_input ||
       (options.transmission_error_input &&
        options.transmission_error_compliance_rad_per_nm > 0.0)) &&
      model_torque_nm.size() != n)
    throw std::invalid_argument("replay_held_out_fit: the model's inputs need the model torque");
  HeldOutReplay out;
  if (std::none_of(identified.cells.begin(), identified.cells.end(),
                   [](const CellIdentification& c) { return c.status == CellStatus::kIdentified; }))
    return out;  // a neutral joint: no model to judge
  if (identified.cells.size() != std::size_t(grid.cell_count()))
    throw std::invalid_argument("replay_held_out_fit: the identification has another cell grid");
  const std::vector<double> output = play_free_angle(
      q_desired, q_measured, segments, cycle_s, options.backlash,
      identified.parameters.backlash_identified ? identified.backlash : BacklashEstimate{});
  const FitSignals s =
      make_fit_signals(q_desired, output, segments, cycle_s, options, model_torque_nm,
                       identified.parameters.torque_sign_scale_nm);
  const bool inverse = options.form == ArxModelForm::kInverse;
  const IoSegment fit_signals =
      is_error_form(options) ? s.with_extras(s.input, s.output) : s.with_extras(q_desired, output);
  const IoSegment angle_signals = s.with_extras(q_desired, output);
  const std::vector<int> cell_of =
      assign_cells(grid, q_desired, payload, operating_signals(q_desired, segments, cycle_s));
  const auto val_runs =
      cell_runs(cell_of, grid.cell_count(), split_held_out(segments, cycle_s, options).second);

  double weighted = 0.0;
  for (std::size_t c = 0; c < identified.cells.size(); ++c) {
    const CellIdentification& cell = identified.cells[c];
    if (cell.status != CellStatus::kIdentified || !cell.fit) continue;
    const ArxModel& fitted = cell.fit->model;
    double fit = std::numeric_limits<double>::quiet_NaN();
    std::size_t rows = 0;
    if (inverse) {
      const auto views =
          run_views(val_runs[c], fit_signals, std::size_t(fitted.structure().max_lag()));
      if (views.empty()) continue;
      const ArxValidationReport report = validate_arx(fitted, views, options.validation);
      fit = report.simulation_fit_percent;
      rows = report.sample_count;
    } else {
      const ArxModel model = is_error_form(options) ? angle_form_of_error_model(fitted) : fitted;
      const auto views =
          run_views(val_runs[c], angle_signals, std::size_t(model.structure().max_lag()));
      if (views.empty()) continue;
      fit = joint_error_fit(model, views, output, q_desired, q_measured);
      rows = rows_of(views, std::size_t(model.structure().max_lag()));
    }
    if (!std::isfinite(fit) || rows == 0) continue;
    weighted += fit * double(rows);
    out.validation_rows += rows;
  }
  if (out.validation_rows) out.joint_error_fit_percent = weighted / double(out.validation_rows);
  return out;
}

}  // namespace imscal::ident
