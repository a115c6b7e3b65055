#include "ident/operating_point.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <set>
#include <stdexcept>

#include "ident/cell_blending.hpp"

namespace imscal::ident {

const char* to_string(OperatingQuantity quantity) {
  switch (quantity) {
    case OperatingQuantity::kSpeed:
      return "speed";
    case OperatingQuantity::kPayload:
      return "payload";
    case OperatingQuantity::kPosition:
      return "position";
    case OperatingQuantity::kAcceleration:
      return "acceleration";
  }
  return "?";
}

const char* si_unit(OperatingQuantity quantity) {
  switch (quantity) {
    case OperatingQuantity::kSpeed:
      return "rad/s";
    case OperatingQuantity::kPayload:
      return "kg";
    case OperatingQuantity::kPosition:
      return "rad";
    case OperatingQuantity::kAcceleration:
      return "rad/s^2";
  }
  return "?";
}

OperatingQuantity operating_quantity_from_string(const std::string& name) {
  for (auto q : {OperatingQuantity::kSpeed, OperatingQuantity::kPayload,
                 OperatingQuantity::kPosition, OperatingQuantity::kAcceleration})
    if (name == to_string(q)) return q;
  throw std::invalid_argument("unknown operating quantity '" + name +
                              "' (expected speed, payload, position or acceleration)");
}

std::vector<double> CellDimension::centres() const {
  std::vector<double> c;
  for (std::size_t i = 0; i + 1 < bounds.size(); ++i)
    c.push_back(0.5 * (bounds[i] + bounds[i + 1]));
  return c;
}

int CellDimension::band_of(double value) const {
  const int m = cell_count();
  // upper_bound: the first bound above the value; band = that index - 1, clamped.
  const auto it = std::upper_bound(bounds.begin(), bounds.end(), value);
  const int band = static_cast<int>(it - bounds.begin()) - 1;
  if (std::isnan(value) || band < 0) return 0;
  return std::min(band, m - 1);
}

CellGrid::CellGrid(std::vector<CellDimension> dimensions) : dimensions_(std::move(dimensions)) {
  if (dimensions_.empty()) throw std::invalid_argument("cell grid: no dimension");
  if (dimensions_.size() > std::size_t(kMaxCellDimensions))
    throw std::invalid_argument(fmt::format("cell grid: {} dimensions, at most {}",
                                            dimensions_.size(), kMaxCellDimensions));
  std::set<OperatingQuantity> seen;
  cell_count_ = 1;
  for (const auto& d : dimensions_) {
    if (!seen.insert(d.quantity).second)
      throw std::invalid_argument(
          fmt::format("cell grid: dimension '{}' given twice", to_string(d.quantity)));
    if (d.bounds.size() < 2)
      throw std::invalid_argument(
          fmt::format("cell grid: dimension '{}' needs at least 2 bounds", to_string(d.quantity)));
    for (std::size_t i = 0; i < d.bounds.size(); ++i) {
      if (!std::isfinite(d.bounds[i]) || (i > 0 && !(d.bounds[i] > d.bounds[i - 1])))
        throw std::invalid_argument(
            fmt::format("cell grid: bounds of '{}' must be finite and strictly increasing",
                        to_string(d.quantity)));
    }
    cell_count_ *= d.cell_count();
  }
}

int CellGrid::flat_index(std::span<const int> bands) const {
  if (bands.size() != dimensions_.size())
    throw std::invalid_argument("cell grid: wrong number of band indices");
  int flat = 0;
  for (std::size_t d = 0; d < dimensions_.size(); ++d) {
    if (bands[d] < 0 || bands[d] >= dimensions_[d].cell_count())
      throw std::invalid_argument("cell grid: band index out of range");
    flat = flat * dimensions_[d].cell_count() + bands[d];
  }
  return flat;
}

std::vector<int> CellGrid::bands_of(int flat) const {
  if (flat < 0 || flat >= cell_count_) throw std::invalid_argument("cell grid: cell out of range");
  std::vector<int> bands(dimensions_.size());
  for (std::size_t d = dimensions_.size(); d-- > 0;) {
    bands[d] = flat % dimensions_[d].cell_count();
    flat /= dimensions_[d].cell_count();
  }
  return bands;
}

std::string CellGrid::label(int flat) const {
  const auto bands = bands_of(flat);
  std::string text;
  for (std::size_t d = 0; d < dimensions_.size(); ++d) {
    const auto& b = dimensions_[d].bounds;
    text += fmt::format("{}{}[{:.6g},{:.6g})", d ? " " : "", to_string(dimensions_[d].quantity),
                        b[bands[d]], b[bands[d] + 1]);
  }
  return text;
}

int CellGrid::band_distance(int flat_a, int flat_b) const {
  const auto a = bands_of(flat_a), b = bands_of(flat_b);
  int sum = 0;
  for (std::size_t d = 0; d < a.size(); ++d) sum += std::abs(a[d] - b[d]);
  return sum;
}

OperatingSignals operating_signals(std::span<const double> q,
                                   std::span<const std::pair<std::size_t, std::size_t>> segments,
                                   double cycle_s) {
  OperatingSignals s;
  s.speed_rad_s.assign(q.size(), 0.0);
  s.acceleration_rad_s2.assign(q.size(), 0.0);
  for (const auto& [begin, end] : segments) {
    if (end - begin < 3) continue;  // too short to difference: stays at rest
    for (std::size_t k = begin; k < end; ++k) {
      // Central differences inside, one-sided at the segment ends (never across a gap).
      const std::size_t lo = k == begin ? k : k - 1;
      const std::size_t hi = k + 1 == end ? k : k + 1;
      s.speed_rad_s[k] = std::abs(q[hi] - q[lo]) / (double(hi - lo) * cycle_s);
      const std::size_t c = std::clamp(k, begin + 1, end - 2);
      s.acceleration_rad_s2[k] = std::abs(q[c + 1] - 2.0 * q[c] + q[c - 1]) / (cycle_s * cycle_s);
    }
  }
  return s;
}

std::vector<int> assign_cells(const CellGrid& grid, std::span<const double> q_desired,
                              std::span<const double> payload, const OperatingSignals& signals) {
  const std::size_t n = q_desired.size();
  if (payload.size() != n || signals.speed_rad_s.size() != n ||
      signals.acceleration_rad_s2.size() != n)
    throw std::invalid_argument("assign_cells: signal lengths differ");
  std::vector<int> cells(n);
  const auto& dims = grid.dimensions();
  std::array<const double*, kMaxCellDimensions> source{};
  for (std::size_t d = 0; d < dims.size(); ++d) {
    switch (dims[d].quantity) {
      case OperatingQuantity::kSpeed:
        source[d] = signals.speed_rad_s.data();
        break;
      case OperatingQuantity::kPayload:
        source[d] = payload.data();
        break;
      case OperatingQuantity::kPosition:
        source[d] = q_desired.data();
        break;
      case OperatingQuantity::kAcceleration:
        source[d] = signals.acceleration_rad_s2.data();
        break;
    }
  }
  for (std::size_t k = 0; k < n; ++k) {
    int flat = 0;
    for (std::size_t d = 0; d < dims.size(); ++d)
      flat = flat * dims[d].cell_count() + dims[d].band_of(source[d][k]);
    cells[k] = flat;
  }
  return cells;
}

std::vector<std::vector<CellRun>> cell_runs(
    std::span<const int> cell_of_sample, int cell_count,
    std::span<const std::pair<std::size_t, std::size_t>> ranges) {
  std::vector<std::vector<CellRun>> runs(static_cast<std::size_t>(cell_count));
  for (const auto& [begin, end] : ranges) {
    std::size_t start = begin;
    for (std::size_t k = begin; k < end; ++k) {
      if (k + 1 == end || cell_of_sample[k + 1] != cell_of_sample[k]) {
        const int cell = cell_of_sample[k];
        if (cell < 0 || cell >= cell_count)
          throw std::invalid_argument("cell_runs: cell index out of range");
        runs[static_cast<std::size_t>(cell)].push_back({start, k + 1, begin});
        start = k + 1;
      }
    }
  }
  return runs;
}

std::vector<IoSegment> run_views(std::span<const CellRun> runs, std::span<const double> input,
                                 std::span<const double> output, std::size_t history) {
  return run_views(runs, IoSegment{input, output}, history);
}

std::vector<IoSegment> run_views(std::span<const CellRun> runs, const IoSegment& signals,
                                 std::size_t history) {
  std::vector<IoSegment> views;
  views.reserve(runs.size());
  for (const CellRun& r : runs) {
    const std::size_t back = std::min(history, r.begin - r.segment_begin);
    const std::size_t first = r.begin - back;
    if (r.end - first <= history) continue;  // no row with a complete regressor
    views.push_back(signals.subspan(first, r.end - first));
  }
  return views;
}

}  // namespace imscal::ident
