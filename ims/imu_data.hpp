#pragma once
// Raw IMS samples in memory, as read from a file or synthesised.
#include <Eigen/Core>
#include <cstddef>
#include <optional>
#include <string>
#include <utility>
#include <vector>

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
  std::vector<ImuSample> samples;
  std::string source;  // file the data came from (for messages); empty if synthesised
  // Line of the file that holds samples[0] (1-based), so that sample i is on line
  // first_data_line + i in text files; 0 for binary files and synthesised data.
  std::size_t first_data_line = 0;
  std::optional<Site> site;  // where the record was taken, if the file says
  std::vector<std::pair<std::string, std::string>> metadata;  // other header fields, in order
};

}  // namespace imscal::ims
