#pragma once
// Raw IMS samples in memory, as read from a file or synthesised.
#include <Eigen/Core>
#include <string>
#include <vector>

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
};

}  // namespace imscal::ims
