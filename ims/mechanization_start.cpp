#include "ims/mechanization_start.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <stdexcept>

#include "core/input_error.hpp"
#include "core/units.hpp"
#include "ims/coarse_alignment.hpp"
#include "ims/imu_conversion.hpp"
#include "ims/imu_file.hpp"
#include "ims/sensor_error_model.hpp"

namespace imscal::ims {
namespace {

ImuSeries read_increments(const MechanizationRequest& request) {
  ImuSeries series = read_imu_file(request.input);
  const std::string input = request.input.string();
  if (series.samples.size() < 2) {
    throw InputError(input, 0, "", "fewer than two samples: nothing to mechanize");
  }
  if (series.quantity == ImuQuantity::kRates) {
    // The rectangle rule of ims/imu_conversion.hpp: errs by -(1/2) d(rate)/dt dt^2 per sample.
    spdlog::warn(
        "{} holds rates, not increments: converted by the rectangle rule, which is not "
        "exact for a changing rate (ims/imu_conversion.hpp)",
        input);
    series = rates_to_increments(series);
  }
  if (!request.sensor_errors.empty()) {
    // Error correction on read: the unit's calibration (bias, scale factor, misalignment).
    series = correct(series, load_sensor_error_model(request.sensor_errors));
    spdlog::info("corrected {} with the sensor error model {}", input,
                 request.sensor_errors.string());
  }
  return series;
}

std::unique_ptr<EarthModel> earth_at_site(const MechanizationRequest& request,
                                          const ImuSeries& series) {
  if (!request.site && !series.site) {
    throw InputError(request.input.string(), 0, "site",
                     "the file names no site; give --site LAT,LON,H (needed for the Earth "
                     "rate and gravity)");
  }
  try {
    return std::make_unique<EarthModel>(request.site ? *request.site : *series.site);
  } catch (const std::invalid_argument& e) {
    throw InputError(request.origin, 0, "--site", e.what());
  }
}

// The coarse alignment over the first align_s seconds; returns the index of the first sample
// after its reference time.
std::size_t align(const MechanizationRequest& request, MechanizationStart& p, double record_start) {
  const auto& samples = p.increments.samples;
  const double align_s = *request.align_s;
  if (!(align_s > 0.0) || record_start + align_s > samples.back().t_s) {
    throw InputError(request.origin, 0, "--align-s",
                     fmt::format("{} s is not inside the record ({} s long)", align_s,
                                 samples.back().t_s - record_start));
  }
  CoarseAlignment alignment;
  try {
    alignment = align_at_rest(p.increments,
                              samples_in_interval(p.increments, record_start, align_s), *p.earth);
  } catch (const std::invalid_argument& e) {
    throw InputError(request.origin, 0, "--align-s", e.what());
  }
  // The alignment holds at t_ref (a sample time in the middle of the interval); the trajectory
  // starts there, at rest.
  p.initial.t_s = alignment.t_ref_s;
  p.initial.q_W_S = alignment.q_W_S;
  const double level_sigma = std::max(alignment.sigma_roll_rad, alignment.sigma_pitch_rad);
  p.attitude_sigma_rad = {level_sigma, level_sigma, alignment.sigma_heading_rad};
  if (request.heading_deg) {
    alignment.angles.heading_rad = *request.heading_deg * kRadPerDeg;
    alignment.sigma_heading_rad = request.heading_sigma_deg * kRadPerDeg;
    p.initial.q_W_S = Eigen::Quaterniond(R_W_S_from_angles(
        alignment.angles.roll_rad, alignment.angles.pitch_rad, -alignment.angles.heading_rad));
    p.attitude_sigma_rad.z() = alignment.sigma_heading_rad;
  }
  p.attitude_source = fmt::format(
      "coarse alignment over the first {} s (roll {:.4f} +- {:.4f}, pitch {:.4f} +- {:.4f}, "
      "heading {:.4f} +- {:.4f} deg{})",
      align_s, alignment.angles.roll_rad / kRadPerDeg, alignment.sigma_roll_rad / kRadPerDeg,
      alignment.angles.pitch_rad / kRadPerDeg, alignment.sigma_pitch_rad / kRadPerDeg,
      alignment.angles.heading_rad / kRadPerDeg, alignment.sigma_heading_rad / kRadPerDeg,
      request.heading_deg ? " from --heading-deg" : " by gyrocompassing");
  std::size_t first_sample = 0;
  while (first_sample < samples.size() && samples[first_sample].t_s <= alignment.t_ref_s) {
    ++first_sample;
  }
  return first_sample;
}

}  // namespace

MechanizationStart prepare_mechanization(const MechanizationRequest& request) {
  if (request.initial_attitude_deg.has_value() == request.align_s.has_value()) {
    throw InputError(request.origin, 0, "--initial-attitude/--align-s",
                     "give exactly one of --initial-attitude ROLL,PITCH,HEADING_DEG and "
                     "--align-s SECONDS");
  }
  MechanizationStart p;
  p.increments = read_increments(request);
  p.earth = earth_at_site(request, p.increments);
  const auto& samples = p.increments.samples;
  const double first_dt =
      p.increments.nominal_dt_s > 0.0 ? p.increments.nominal_dt_s : samples[1].t_s - samples[0].t_s;
  const double record_start = samples.front().t_s - first_dt;
  std::size_t first_sample = 0;
  p.initial.t_s = record_start;
  if (request.initial_attitude_deg) {
    const Eigen::Vector3d& deg = *request.initial_attitude_deg;
    // Heading is clockwise from North; the angle convention's yaw counter-clockwise.
    p.initial.q_W_S = Eigen::Quaterniond(
        R_W_S_from_angles(deg.x() * kRadPerDeg, deg.y() * kRadPerDeg, -deg.z() * kRadPerDeg));
    p.attitude_source = "command line";
  } else {
    first_sample = align(request, p, record_start);
  }
  p.increments.samples.erase(p.increments.samples.begin(),
                             p.increments.samples.begin() + static_cast<long>(first_sample));
  return p;
}

}  // namespace imscal::ims
