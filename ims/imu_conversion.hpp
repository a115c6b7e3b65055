#pragma once
// Conversion between the two quantities a raw IMS record can hold (ims/imu_data.hpp):
// angular rate / specific force at the stamp, and angular / velocity increments over the
// interval that ends at the stamp.
//
// rates -> increments: increment_i = rate_i * (t_i - t_{i-1}), the rectangle rule with the
//   value at the END of the interval (the first sample's interval is one nominal interval).
//   For a smooth signal the exact increment is the integral of the rate over (t_{i-1}, t_i],
//   which differs from this by -(1/2) * d(rate)/dt * dt^2 + O(dt^3) per sample: 5e-7 rad for a
//   rate changing by 1 rad/s^2 at 1 kHz. The error does not accumulate into a drift for a
//   bounded signal (it telescopes to half an interval of time shift), but a record synthesised
//   this way is not what an integrating sensor would give; use it for bookkeeping, not to make
//   reference data.
// increments -> rates: rate_i = increment_i / (t_i - t_{i-1}), the mean rate over the interval.
//   It is the exact inverse of the above up to rounding (a few ulp). The mean rate belongs to
//   the middle of the interval, to O(dt^2); stamped at the end it lags by dt/2.
//
// Site, metadata, source and first_data_line are kept (sample i stays on the same line).
#include "ims/imu_data.hpp"

namespace imscal::ims {

// Throws std::invalid_argument if the series holds increments already, or if its time stamps
// do not increase strictly (validate it first: ims/imu_validation.hpp).
ImuSeries rates_to_increments(const ImuSeries& rates);
// The same, sample by sample in place (no second copy of a long record; the same values); on
// an exception the series is left part converted.
ImuSeries rates_to_increments(ImuSeries&& rates);

// Throws std::invalid_argument if the series holds rates already, or if its time stamps do not
// increase strictly.
ImuSeries increments_to_rates(const ImuSeries& increments);

// Either of the above, or a copy if the series holds `quantity` already.
ImuSeries to_quantity(const ImuSeries& series, ImuQuantity quantity);

}  // namespace imscal::ims
