#pragma once
// Operating-point cells of one joint (paper, Table 2): the ARX parameters depend on where the
// joint works. A cell grid has one or more dimensions, each a quantity with increasing band
// bounds in SI units; by default joint speed |q̇_d| (bands as fractions of the joint's maximum
// speed) × payload (fractions of the nominal payload); joint position and |acceleration| can be
// added. Values outside the outer bounds belong to the outermost band (a faster move than the
// grid's maximum uses the fastest cell).
//
// The operating point of a sample is computed from the desired joint angle (what the
// precontrol knows online): speed and acceleration by central differences within a segment.
//
// How regression rows are split among cells: the row of sample k (target y(k), regressors
// y(k-1..), u(k-d..)) belongs to the cell of sample k's operating point; a cell's Gram matrix
// sums only its own rows, while the regressors of a row may reach back into samples of other
// cells (the model's memory does not stop at a cell boundary). cell_runs() finds, in one pass,
// the maximal runs of consecutive samples of the same cell; each run becomes a data view that
// starts `history` samples earlier, so the existing lagged-Gram machinery (ident/arx_fit.hpp)
// sums exactly the run's rows with their full regressors.
#include <cstddef>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "ident/arx_structure.hpp"

namespace imscal::ident {

enum class OperatingQuantity {
  kSpeed,         // |q̇_d| [rad/s]
  kPayload,       // [kg]
  kPosition,      // q_d [rad]
  kAcceleration,  // |q̈_d| [rad/s²]
};

const char* to_string(OperatingQuantity quantity);
const char* si_unit(OperatingQuantity quantity);
// Throws std::invalid_argument for an unknown name.
OperatingQuantity operating_quantity_from_string(const std::string& name);

struct CellDimension {
  OperatingQuantity quantity = OperatingQuantity::kSpeed;
  std::vector<double> bounds;  // SI, strictly increasing, at least 2: cells [b_i, b_{i+1})

  int cell_count() const { return static_cast<int>(bounds.size()) - 1; }
  std::vector<double> centres() const;
  // Band of a value (clamped to the outer bands; NaN goes to band 0).
  int band_of(double value) const;
};

class CellGrid {
 public:
  CellGrid() = default;
  // Throws std::invalid_argument for no dimension, more than kMaxCellDimensions, a repeated
  // quantity or bounds that are not finite and strictly increasing.
  explicit CellGrid(std::vector<CellDimension> dimensions);

  const std::vector<CellDimension>& dimensions() const { return dimensions_; }
  int cell_count() const { return cell_count_; }
  // Row-major, last dimension fastest (as ident/cell_blending.hpp).
  int flat_index(std::span<const int> bands) const;
  std::vector<int> bands_of(int flat) const;
  // "speed[0.00,0.54) payload[0,8)" style label, SI numbers.
  std::string label(int flat) const;
  // Distance of two cells in band steps (sum over dimensions).
  int band_distance(int flat_a, int flat_b) const;

 private:
  std::vector<CellDimension> dimensions_;
  int cell_count_ = 0;
};

// Per-sample operating quantities of one joint, computed from its desired angle.
struct OperatingSignals {
  std::vector<double> speed_rad_s, acceleration_rad_s2;
};
// segments: [begin, end) sample ranges (differences never cross them).
OperatingSignals operating_signals(std::span<const double> q_desired_rad,
                                   std::span<const std::pair<std::size_t, std::size_t>> segments,
                                   double cycle_s);

// The cell of every sample (one pass).
std::vector<int> assign_cells(const CellGrid& grid, std::span<const double> q_desired_rad,
                              std::span<const double> payload_kg, const OperatingSignals& signals);

// A run of consecutive samples [begin, end) in one cell and one segment.
struct CellRun {
  std::size_t begin = 0, end = 0;
  std::size_t segment_begin = 0;  // first sample of the segment holding the run
};

// Maximal runs per cell (result[cell]), restricted to the sample ranges `ranges` (e.g. the
// estimation or the validation part of every segment). One pass over the samples.
std::vector<std::vector<CellRun>> cell_runs(
    std::span<const int> cell_of_sample, int cell_count,
    std::span<const std::pair<std::size_t, std::size_t>> ranges);

// Data views of the runs for ARX work: each view starts min(history, begin - range start)
// samples before the run, so that with first row = history the rows summed are the run's own
// (those with a complete regressor). Runs too short to hold a row are skipped.
std::vector<IoSegment> run_views(std::span<const CellRun> runs, std::span<const double> input,
                                 std::span<const double> output, std::size_t history);
// The same for whole-record signals with further inputs (multi-input form).
std::vector<IoSegment> run_views(std::span<const CellRun> runs, const IoSegment& signals,
                                 std::size_t history);

}  // namespace imscal::ident
