#pragma once
// The held-out joint-error fit of a joint's whole table as the precontrol uses it
// (ident/precontrol.hpp): every cell's model runs free over each held-out stretch of the record
// (not restarted from the measured output where the operating point enters another cell), and
// their errors are blended with the precontrol's operating-point weights
// (ident/cell_blending.hpp); a filled cell predicts with the model it was filled from. A cell's
// own figure (CellFitFigures::joint_error_fit_percent) runs its model only on its own held-out
// runs, each restarted from the measured output, so with several cells per joint it can
// overstate what the table achieves; with one cell the two are the same.
#include <cstddef>
#include <limits>
#include <span>
#include <utility>
#include <vector>

#include "ident/arx_model.hpp"
#include "ident/operating_point.hpp"

namespace imscal::ident {

struct TableFitInput {
  const CellGrid* grid = nullptr;
  // Per cell of the grid: the model that predicts there (a filled cell's source model), or null
  // for none (the joint is then not judged).
  std::vector<const ArxModel*> models = {};
  // True: the models are error models on (w, e) (the inverse form) whose free run is the
  // predicted error ê itself, judged against e; false: angle models on (q_d, y) predicting
  // Δq̂ = q_d(k - d) - q̂(k), judged against q_d - y with the spread of q_d - q_m (as
  // CellFitFigures::joint_error_fit_percent in each form).
  bool error_models = false;
  IoSegment model_signals = {};  // what the models run on, over the whole record
  std::span<const double> q_desired = {}, q_measured = {}, payload_kg = {};
  const OperatingSignals* operating = nullptr;
  std::span<const std::pair<std::size_t, std::size_t>> segments = {};
  std::span<const std::pair<std::size_t, std::size_t>> held_out = {};  // inside the segments
};

struct TableFit {
  double joint_error_fit_percent = std::numeric_limits<double>::quiet_NaN();
  std::size_t rows = 0;  // held-out rows judged
};

// NaN (0 rows) when a cell has no model or no held-out row has every model's history.
TableFit table_held_out_fit(const TableFitInput& input);

}  // namespace imscal::ident
