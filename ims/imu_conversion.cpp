#include "ims/imu_conversion.hpp"

#include <fmt/format.h>
#include <utility>

#include <cmath>
#include <stdexcept>

namespace imscal::ims {
namespace {

// Interval ending at sample i [s]; the first is one nominal interval (ims/imu_data.hpp).
double interval_before(const ImuSeries& series, std::size_t i) {
  const double dt =
      i == 0 ? series.nominal_dt_s : series.samples[i].t_s - series.samples[i - 1].t_s;
  if (!(dt > 0.0 && std::isfinite(dt))) {
    throw std::invalid_argument(fmt::format(
        "{}: sample {}: interval {} s is not positive; validate the series before converting",
        series.source, i, dt));
  }
  return dt;
}

}  // namespace

ImuSeries rates_to_increments(const ImuSeries& rates) {
  return rates_to_increments(ImuSeries(rates));
}

ImuSeries rates_to_increments(ImuSeries&& rates) {
  if (rates.quantity != ImuQuantity::kRates) {
    throw std::invalid_argument("rates_to_increments: the series holds increments already");
  }
  // Sample i's interval reads the time stamps only, which the conversion keeps.
  for (std::size_t i = 0; i < rates.samples.size(); ++i) {
    const double dt = interval_before(rates, i);
    rates.samples[i].gyro *= dt;
    rates.samples[i].acc *= dt;
  }
  rates.quantity = ImuQuantity::kIncrements;
  return std::move(rates);
}

ImuSeries increments_to_rates(const ImuSeries& increments) {
  if (increments.quantity != ImuQuantity::kIncrements) {
    throw std::invalid_argument("increments_to_rates: the series holds rates already");
  }
  ImuSeries out = increments;
  out.quantity = ImuQuantity::kRates;
  for (std::size_t i = 0; i < out.samples.size(); ++i) {
    const double dt = interval_before(increments, i);
    out.samples[i].gyro = increments.samples[i].gyro / dt;
    out.samples[i].acc = increments.samples[i].acc / dt;
  }
  return out;
}

ImuSeries to_quantity(const ImuSeries& series, ImuQuantity quantity) {
  if (series.quantity == quantity) return series;
  return quantity == ImuQuantity::kIncrements ? rates_to_increments(series)
                                              : increments_to_rates(series);
}

}  // namespace imscal::ims
