#pragma once
// identification_report.json of `imscal identify` (datasets/FORMAT.md): per joint the backlash,
// and per operating-point cell its status, rows, chosen orders with the criterion curves, the fit
// and its held-out validation figures; the transmission-error order search when one was run.
// Written and read here, so that the two cannot drift apart. The reader returns the figures a
// later step uses (not the criterion curves nor the correlation tests).
#include <cstddef>
#include <filesystem>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "ident/friction_levels_report.hpp"
#include "ident/identified_structure.hpp"
#include "ident/identify_joints.hpp"
#include "ident/parameter_table.hpp"

namespace imscal::ident {

// An order the joint errors' order spectrum holds significantly (`--track-transmission-error-
// orders`, eval/transmission_error_order_spectrum.hpp).
struct TrackedOrder {
  double order_per_motor_rev = 0.0;
  double amplitude_rad = 0.0;       // the windows' RMS amplitude at the order
  double floor_rad = 0.0;           // the neighbouring orders' RMS amplitude
  double significance_sigma = 0.0;  // the power's excess over the floor in σ of a noise-only floor
  double t_statistic = 0.0;         // the excess's t statistic over the windows
};

// The search of each joint's transmission-error harmonic (`--search-transmission-error-order`).
struct OrderSearchJoint {
  std::string name;
  double config_harmonic_per_motor_rev = 0.0;
  double best_harmonic_per_motor_rev = 0.0;
  double gain_points = 0.0;  // NaN when not found
  double chosen_harmonic_per_motor_rev = 0.0;
  std::vector<double> held_out_joint_error_fit_percent;  // per candidate; NaN where none
  // With the second pass (`--search-second-transmission-error-order`): the second harmonic kept
  // (0: none) and the BIC of the best second candidate against the first alone (negative: kept).
  // NaN without the second pass.
  double second_harmonic_per_motor_rev = std::numeric_limits<double>::quiet_NaN();
  double second_bic = std::numeric_limits<double>::quiet_NaN();
  // With `--track-transmission-error-orders`: the spectrum's windows (0: not tracked) and its
  // significant orders, strongest first; the first replaces chosen_harmonic_per_motor_rev, the
  // second second_harmonic_per_motor_rev (0 without one).
  std::size_t tracking_windows = 0;
  std::vector<TrackedOrder> tracked_orders{};
};
struct OrderSearchReport {
  std::vector<double> candidates_per_motor_rev;
  std::vector<OrderSearchJoint> joints;
};

struct IdentificationReportHeader {
  std::string created_by;  // "imscal 0.1.0"
  std::string joint_errors, joint_errors_sha256, config;
  std::size_t samples = 0, segments = 0;
  double sample_time_s = 0.0;
  double seconds = 0.0;  // wall time of the whole identification
  std::optional<OrderSearchReport> order_search;
};

struct ReportedValidation {
  std::size_t samples = 0;
  double one_step_fit_percent = 0.0, simulation_fit_percent = 0.0;
  double joint_error_fit_percent = 0.0;  // NaN without held-out rows
  double residual_rms_rad = 0.0;
};

struct ReportedOrders {
  int na = 0, nb = 0, dead_time = 0;
};

struct ReportedCell {
  int cell = 0;
  std::string label;
  CellStatus status = CellStatus::kIdentified;
  std::size_t estimation_rows = 0, validation_rows = 0;
  double rms_desired_speed_rad_s = 0.0;
  int filled_from = -1;                  // with kFilled
  std::string reason;                    // with kFilled
  std::optional<ReportedOrders> chosen;  // of the order sweep, when the cell had one
  std::optional<ReportedValidation> validation;
};

struct ReportedBacklash {
  bool identified = false;
  double l_rad = 0.0, l_sigma_rad = 0.0, full_play_rad = 0.0;
  std::size_t reversals_found = 0, reversals_used = 0;
  int lag_samples = 0;
  std::vector<double> per_reversal_l_rad;
  std::string reason;
};

struct ReportedJoint {
  std::string name;
  double seconds = 0.0;
  // The whole table's held-out joint-error fit, cells blended as the precontrol does
  // (ident/table_fit.hpp; NaN: not judged), and the rows it is over.
  double table_joint_error_fit_percent = 0.0;
  std::size_t table_validation_rows = 0;
  ReportedBacklash backlash;
  // The drive structure the models imply, with 1σ (absent in reports written before it was).
  std::optional<IdentifiedStructure> structure;
  std::vector<ReportedCell> cells;
};

struct IdentificationReport {
  IdentificationReportHeader header;
  std::vector<ReportedJoint> joints;
  // The model torque's links refined from the data (the table's model_torque_links; empty when
  // the identification did not refine them).
  std::vector<LinkMassParameters> model_torque_links;
  // The friction levels from the motor encoders (ident/friction_levels_report.hpp; empty when
  // the identification had no rigid-body model or the report predates them).
  std::vector<ReportedFrictionLevels> friction_levels;
};

// The document of the identification of every joint (outcomes in joint order).
nlohmann::json identification_report_json(const IdentificationReportHeader& header,
                                          const std::vector<JointOutcome>& outcomes);

// Reads `file`; InputError naming the file and the field (its JSON path) for a file that is not
// JSON, repeats a key, is of another kind or format version, or lacks a field or holds one of
// another type.
IdentificationReport read_identification_report(const std::filesystem::path& file);

}  // namespace imscal::ident
