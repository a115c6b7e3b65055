#include "ident/table_fit.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "ident/cell_blending.hpp"

namespace imscal::ident {
namespace {

// The operating point of sample k in the grid's dimensions, as the precontrol forms it.
std::array<double, kMaxCellDimensions> operating_point(const TableFitInput& in, std::size_t k) {
  std::array<double, kMaxCellDimensions> point{};
  const auto& dimensions = in.grid->dimensions();
  for (std::size_t d = 0; d < dimensions.size(); ++d) {
    switch (dimensions[d].quantity) {
      case OperatingQuantity::kSpeed:
        point[d] = std::abs(in.operating->speed_rad_s[k]);
        break;
      case OperatingQuantity::kPayload:
        point[d] = in.payload_kg[k];
        break;
      case OperatingQuantity::kPosition:
        point[d] = in.q_desired[k];
        break;
      case OperatingQuantity::kAcceleration:
        point[d] = std::abs(in.operating->acceleration_rad_s2[k]);
        break;
    }
  }
  return point;
}

std::size_t segment_begin_of(const TableFitInput& in, std::size_t k) {
  for (const auto& [begin, end] : in.segments)
    if (k >= begin && k < end) return begin;
  return k;
}

// Residual and reference of the blended prediction over one held-out stretch [begin, end).
void add_stretch(const TableFitInput& in, std::size_t begin, std::size_t end,
                 const std::vector<std::vector<double>>& centres, std::vector<double>& residuals,
                 std::vector<double>& references) {
  const std::size_t segment_begin = segment_begin_of(in, begin);
  const std::size_t cells = in.models.size();
  std::vector<std::size_t> first(cells);
  std::size_t judged_from = begin;
  for (std::size_t c = 0; c < cells; ++c) {
    const auto lag = std::size_t(in.models[c]->structure().max_lag());
    first[c] = begin - std::min(lag, begin - segment_begin);
    judged_from = std::max(judged_from, first[c] + lag);
  }
  if (judged_from >= end) return;
  std::vector<std::vector<double>> predicted(cells);
  for (std::size_t c = 0; c < cells; ++c) {
    const ArxModel& model = *in.models[c];
    const IoSegment view = in.model_signals.subspan(first[c], end - first[c]);
    std::vector<double> simulated(view.output.size());
    model.simulate(view, simulated);
    const auto d = std::size_t(model.structure().dead_time);
    predicted[c].resize(end - judged_from);
    for (std::size_t k = judged_from; k < end; ++k) {
      const std::size_t i = k - first[c];
      predicted[c][k - judged_from] =
          in.error_models ? simulated[i] : view.input[i - d] - simulated[i];
    }
  }
  std::array<std::span<const double>, kMaxCellDimensions> centre_spans{};
  for (std::size_t d = 0; d < centres.size(); ++d) centre_spans[d] = centres[d];
  for (std::size_t k = judged_from; k < end; ++k) {
    const auto point = operating_point(in, k);
    const CellBlend blend = blend_cells(std::span(centre_spans.data(), centres.size()),
                                        std::span<const double>(point.data(), centres.size()));
    double blended = 0.0;
    for (int i = 0; i < blend.count; ++i)
      blended += blend.weight[i] * predicted[std::size_t(blend.cell[i])][k - judged_from];
    const double target = in.model_signals.output[k];  // e, or the play-free y
    residuals.push_back(in.error_models ? target - blended : in.q_desired[k] - target - blended);
    references.push_back(in.error_models ? target : in.q_desired[k] - in.q_measured[k]);
  }
}

}  // namespace

TableFit table_held_out_fit(const TableFitInput& in) {
  TableFit out;
  if (in.grid == nullptr || in.operating == nullptr ||
      in.models.size() != std::size_t(in.grid->cell_count()) ||
      std::any_of(in.models.begin(), in.models.end(), [](const ArxModel* m) { return !m; }))
    return out;
  std::vector<std::vector<double>> centres;
  for (const CellDimension& dimension : in.grid->dimensions())
    centres.push_back(dimension.centres());
  std::vector<double> residuals, references;
  for (const auto& [begin, end] : in.held_out)
    add_stretch(in, begin, end, centres, residuals, references);
  double mean = 0.0, misfit = 0.0, spread = 0.0;
  for (double r : references) mean += r;
  mean /= double(std::max<std::size_t>(references.size(), 1));
  for (std::size_t k = 0; k < references.size(); ++k) {
    misfit += residuals[k] * residuals[k];
    spread += (references[k] - mean) * (references[k] - mean);
  }
  out.rows = references.size();
  if (spread > 0.0) out.joint_error_fit_percent = 100.0 * (1.0 - std::sqrt(misfit / spread));
  return out;
}

}  // namespace imscal::ident
