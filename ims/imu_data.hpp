#pragma once
// Raw IMS samples in memory, as read from a file or synthesised.
#include <Eigen/Core>
#include <cstddef>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "core/spillable_vector.hpp"
#include "ims/earth_model.hpp"

namespace imscal::ims {

// What the two triads of a file report.
enum class ImuQuantity {
  kIncrements,  // angular increment [rad] and velocity increment [m/s] over (t_prev, t]
  kRates,       // angular rate [rad/s] and specific force [m/s^2] at t
};

// One sample in the sensor frame S. Increments are stamped at the END of their interval;
// the first sample's interval starts one nominal interval earlier.
struct ImuSample {
  double t_s = 0.0;
  Eigen::Vector3d gyro = Eigen::Vector3d::Zero();  // [rad] or [rad/s], see ImuQuantity
  Eigen::Vector3d acc = Eigen::Vector3d::Zero();   // [m/s] or [m/s^2], see ImuQuantity
};

struct ImuSeries {
  ImuQuantity quantity = ImuQuantity::kIncrements;
  double nominal_dt_s = 0.0;  // nominal sample interval
  // In memory, or in a temporary file for a long record (core/spillable_vector.hpp).
  SpillableVector<ImuSample> samples;
  std::string source;  // file the data came from (for messages); empty if synthesised
  // Line of the file that holds samples[0] (1-based), so that sample i is on line
  // first_data_line + i in text files; 0 for binary files and synthesised data.
  std::size_t first_data_line = 0;
  std::optional<Site> site;  // where the record was taken, if the file says
  std::vector<std::pair<std::string, std::string>> metadata;  // other header fields, in order
};

// The samples of a record from index `first` on with its header, without a copy: what the
// smoother and the rest detector read. As in a record cut there, the first sample's interval is
// the nominal one. The record must outlive it.
struct ImuSamples {
  ImuQuantity quantity = ImuQuantity::kIncrements;
  double nominal_dt_s = 0.0;
  std::span<const ImuSample> samples;
  std::string source;
  std::size_t first_data_line = 0;  // line of samples[0] in a text file; 0: not known

  ImuSamples() = default;
  // A whole record reads as its samples wherever ImuSamples is asked for.
  ImuSamples(const ImuSeries& record, std::size_t first = 0)  // NOLINT(google-explicit-constructor)
      : quantity(record.quantity),
        nominal_dt_s(record.nominal_dt_s),
        source(record.source),
        first_data_line(record.first_data_line == 0 ? 0 : record.first_data_line + first) {
    if (first > record.samples.size()) throw std::out_of_range("ImuSamples: first past the end");
    samples = std::span<const ImuSample>(record.samples).subspan(first);
  }

  // The interval of sample i [s]: t_i - t_{i-1}, the nominal one for the first.
  double interval_s(std::size_t i) const {
    return i == 0 ? nominal_dt_s : samples[i].t_s - samples[i - 1].t_s;
  }
};

}  // namespace imscal::ims
