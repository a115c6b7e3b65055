#pragma once
// Checks of a raw IMS record after parsing, shared by every reader (CSV, binary, PSINS): finite
// values, strictly increasing time stamps, gaps and jitter against the nominal interval,
// saturated values, and the unit plausibility of both triads (the static specific force must be
// close to the local normal gravity; sustained angular rates beyond what a robot can do mean the
// values are in degrees). Problems become imscal::InputError naming file, line (or binary
// record) and field; tolerable findings become warnings in ImuReadReport.
//
// Increments are judged through their mean rate over the interval (increment / time step), so
// one set of limits in rad/s and m/s^2 serves both quantities.
#include <array>
#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/units.hpp"
#include "ims/imu_data.hpp"

namespace imscal::ims {

struct ImuReadOptions {
  // The samples go to a temporary file as they are read and the file's text leaves resident
  // memory behind the parser (core/spillable_vector.hpp): for a command that holds a long
  // record whole (calibrate), whose resident memory then does not grow with it.
  bool samples_to_file = false;
  // A time step longer than gap_factor nominal intervals is a gap (missing samples).
  double gap_factor = 1.5;
  bool allow_gaps = false;  // gaps become a warning with their count instead of an error
  // A step that differs from the nominal interval by more than jitter_fraction of it (and is not
  // a gap) counts as jitter; jitter is reported as a warning with statistics, never an error.
  double jitter_fraction = 0.1;

  // Measurement ranges of the sensor: a rate at or beyond them is a saturated (clipped) value.
  double gyro_range_rad_s = 17.453292519943295;  // 1000 deg/s, a typical ring-laser-gyro range
  double acc_range_m_s2 = 196.133;               // 20 g, a typical servo-accelerometer range
  bool allow_saturation = false;  // saturated values become a warning with their count

  // Units: static specific force against normal gravity. Rest windows are found where the
  // standard deviation of every specific-force component stays below static_acc_std_m_s2 and of
  // every rate component below static_gyro_std_rad_s over static_window_s.
  bool check_units = true;
  double static_window_s = 0.5;
  double static_acc_std_m_s2 = 0.05;
  double static_gyro_std_rad_s = 0.01;
  // |mean |f| - g| beyond this is an error; when the file has no site, the default gravity is
  // used and default_gravity_extra_tolerance_m_s2 is added (|g| ranges over 9.78..9.83 m/s^2 on
  // the Earth's surface).
  double gravity_tolerance_m_s2 = 0.2;
  double default_gravity_m_s2 = kStandardGravity_m_s2;  // used when the file has no site
  double default_gravity_extra_tolerance_m_s2 = 0.05;
  // Angular rate above max_plausible_rate_rad_s (on every sample) for at least
  // sustained_rate_duration_s is not a robot motion: the values are taken to be in degrees.
  double max_plausible_rate_rad_s = 35.0;
  double sustained_rate_duration_s = 0.2;

  // CSV only: accept a last line without end-of-line (by default it means a truncated file).
  bool allow_missing_final_newline = false;
};

// What a reader found, for the user and for the log.
struct ImuReadReport {
  std::string file;
  std::size_t samples = 0;
  double duration_s = 0.0;          // last stamp - first stamp
  double median_dt_s = 0.0;         // median time step
  double max_step_s = 0.0;          // longest time step (a gap if > gap_factor * nominal)
  std::size_t gap_count = 0;        // steps counted as gaps (only with allow_gaps)
  std::size_t jitter_count = 0;     // steps counted as jitter
  double jitter_rms_s = 0.0;        // RMS of (step - nominal) over all steps
  double jitter_max_abs_s = 0.0;    // largest |step - nominal| among non-gap steps
  std::size_t saturated_count = 0;  // saturated values (only with allow_saturation)
  std::size_t static_windows = 0;   // rest windows found for the gravity check
  std::optional<double> static_specific_force_m_s2;  // mean |f| at rest
  std::optional<double> expected_gravity_m_s2;       // the |g| it was compared with
  std::vector<std::string> warnings;                 // also logged with spdlog::warn

  std::string brief() const;  // one paragraph: counts, duration, rates, warnings
};

// The field names of the seven columns in SI units, as the project's CSV names them:
// t_s, then the gyro triad, then the accelerometer triad.
using ImuColumnNames = std::array<std::string, 7>;
ImuColumnNames si_column_names(ImuQuantity quantity);

// The seven values of sample `index` in column order (t_s, gyro, acc), as the writers store them.
// Throws std::invalid_argument naming the sample and the column when a value is not finite.
std::array<double, 7> finite_sample_values(const ImuSeries& series, std::size_t index);

// Where the samples came from, for messages. Defaults (from the series itself): SI column names,
// no header line for nominal_dt_s.
struct ImuSourceInfo {
  std::optional<ImuColumnNames> columns;  // names as written in the file (e.g. "acc_x_g")
  std::size_t nominal_dt_line = 0;        // line of the nominal_dt_s header (0 if none)
  std::size_t record_count = 0;           // records a binary file announces (0: the series' size)
};

// The same checks, run by a reader while it parses: construct it once the header is known
// (quantity, nominal_dt_s, source, first_data_line set), call check_up_to(n) whenever samples
// [0, n) are in series.samples (the samples just parsed are still in cache then), and finish()
// at the end. Throws InputError as validate_imu_series; the report is filled when finish()
// returns or throws. The series may grow (and reallocate) between calls.
class ImuValidator {
 public:
  ImuValidator(const ImuSeries& series, const ImuReadOptions& options,
               ImuReadReport* report = nullptr, const ImuSourceInfo& info = {});
  ImuValidator(const ImuValidator&) = delete;
  ImuValidator& operator=(const ImuValidator&) = delete;
  ~ImuValidator();

  void check_up_to(std::size_t n);
  void finish();

 private:
  class Scan;
  void publish();
  ImuReadReport report_;
  ImuReadReport* report_out_;
  std::unique_ptr<Scan> scan_;
};

// Runs every check above on a parsed series; throws InputError and fills
// `report` (if given) with statistics and warnings. Sample i is located at line
// series.first_data_line + i when first_data_line > 0, else as "record i+1" (binary files).
// Which error is reported when there are several: non-finite values, stamps out of order and
// degree-like rates in file order; then a nominal interval that does not match the median step,
// gaps, the static gravity check, saturation (see ImuValidator::Scan in the source).
void validate_imu_series(const ImuSeries& series, const ImuReadOptions& options,
                         ImuReadReport* report = nullptr, const ImuSourceInfo& info = {});

// Adds a warning to the report (if any) and logs it.
void add_imu_warning(ImuReadReport* report, const std::string& warning);

}  // namespace imscal::ims
