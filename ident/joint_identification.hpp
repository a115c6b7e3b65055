#pragma once
// The whole identification of one joint (paper, section 3.3), from its desired and measured
// angles:
//  1. backlash l (equation 3) from direction reversals (ident/backlash_identification.hpp), and
//     the joint angle with the backlash part removed, y = q_m + l s(k);
//  2. the last validation_fraction of every segment held out;
//  3. every sample assigned to its operating-point cell (ident/operating_point.hpp), the
//     regression rows of a cell = its samples (regressors reach back into other cells);
//  4. per cell: checks of row count and excitation, order and dead-time sweep on the cell's
//     estimation rows (AIC/BIC/hold-out curves, ident/order_selection.hpp), least-squares fit of
//     the chosen structure on the cell's estimation rows (ident/arx_fit.hpp), stability
//     (ident/model_stability.hpp), validation on the cell's held-out rows
//     (ident/model_validation.hpp);
//  5. cells that failed any step are filled with the model of the nearest identified cell (in
//     band steps; ties: the lower cell number), with the reason — never silently.
#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "ident/backlash_identification.hpp"
#include "ident/model_stability.hpp"
#include "ident/model_validation.hpp"
#include "ident/operating_point.hpp"
#include "ident/order_selection.hpp"
#include "ident/parameter_table.hpp"

namespace imscal::ident {

struct JointIdentificationOptions {
  OrderGrid grid{1, 32, 1, 32, 0, 4};
  OrderCriterion criterion = OrderCriterion::kBic;
  double validation_fraction = 0.3;  // of every segment, held out (its end)
  ValidationOptions validation;
  std::size_t min_rows_per_cell = 1000;  // estimation rows; fewer: the cell is filled
  // Excitation: RMS of the desired speed over the cell's estimation rows [rad/s]; a cell where
  // the joint (nearly) stands still carries no information about its dynamics.
  double min_rms_speed_rad_s = 1e-3;
  double stability_margin = 1e-3;
  bool identify_backlash = true;
  BacklashOptions backlash;
  double min_relative_pivot = 1e-12;  // of the sweep (OrderSelectionOptions)
  ArxFitOptions fit;
};

struct CellIdentification {
  int cell = 0;
  std::string label;
  CellStatus status = CellStatus::kIdentified;
  int filled_from = -1;
  std::string reason;  // why it was not identified
  std::size_t estimation_rows = 0, validation_rows = 0;
  double rms_speed_rad_s = 0.0;
  std::optional<OrderSweepResult> sweep;
  std::optional<ArxFitResult> fit;
  std::optional<ArxValidationReport> validation;
  std::optional<StabilityCheck> stability;
};

struct JointIdentification {
  JointParameters parameters;
  BacklashEstimate backlash;
  std::vector<CellIdentification> cells;  // flat order of the grid
};

// segments: [begin, end) ranges of separate runs. Throws std::invalid_argument for bad sizes,
// std::runtime_error when no cell at all can be identified (with every cell's reason).
JointIdentification identify_joint(const std::string& name, std::span<const double> q_desired_rad,
                                   std::span<const double> q_measured_rad,
                                   std::span<const double> payload_kg,
                                   std::span<const std::pair<std::size_t, std::size_t>> segments,
                                   double cycle_s, const CellGrid& grid,
                                   const JointIdentificationOptions& options = {});

}  // namespace imscal::ident
