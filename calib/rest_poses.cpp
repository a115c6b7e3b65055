#include "calib/rest_poses.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "core/input_error.hpp"
#include "ims/earth_model.hpp"
#include "ims/zupt_options.hpp"
#include "robot/jacobian.hpp"

namespace imscal::calib {
namespace {

// The rest detector's options from the data sheet, as the zero-velocity smoother fills them,
// with the configured threshold.
ims::RestDetectorOptions detector_options(const ims::SensorSpec& spec, double threshold_sigmas) {
  const ims::ZuptOptions zupt = ims::zupt_options_from_spec(spec);
  ims::RestDetectorOptions r = zupt.rest;
  r.threshold_sigmas = threshold_sigmas;
  r.gyro_noise_density_rad_per_sqrt_s = zupt.gyro_noise_density_rad_per_sqrt_s;
  r.gyro_quantization_lsb_rad = zupt.gyro_quantization_lsb_rad;
  r.acc_noise_density_m_s_per_sqrt_s = zupt.acc_noise_density_m_s_per_sqrt_s;
  r.acc_quantization_lsb_m_s = zupt.acc_quantization_lsb_m_s;
  // A bias of 3 sigma still passes the magnitude tests.
  r.gyro_bias_bound_rad_s = 3.0 * zupt.initial_gyro_bias_sigma_rad_s;
  r.acc_bias_bound_m_s2 = 3.0 * zupt.initial_acc_bias_sigma_m_s2;
  return r;
}

std::string seconds(double t) {
  return fmt::format("{:.3f} s", t);
}

using SampleIterator = const RobotLogSample*;

// The first sample of [from, to) at or after t, and the first after t [s, robot clock].
SampleIterator first_at_or_after(SampleIterator from, SampleIterator to, double t) {
  return std::lower_bound(from, to, t, [](const RobotLogSample& s, double x) { return s.t_s < x; });
}
SampleIterator first_after(SampleIterator from, SampleIterator to, double t) {
  return std::upper_bound(from, to, t, [](double x, const RobotLogSample& s) { return x < s.t_s; });
}

// Per joint, max - min of the readings of [first, last) (not empty) [rad].
JointVector reading_spread(SampleIterator first, SampleIterator last) {
  JointVector low = first->q_internal_rad, high = first->q_internal_rad;
  for (auto it = first; it != last; ++it) {
    low = low.cwiseMin(it->q_internal_rad);
    high = high.cwiseMax(it->q_internal_rad);
  }
  return high - low;
}

}  // namespace

RestPoseResult find_rest_poses(const RestPoseInput& input, const RestPoseOptions& options) {
  const std::string source = input.source.empty() ? "rest poses" : input.source;
  if (input.imu == nullptr || input.log == nullptr || input.robot == nullptr) {
    throw InputError(source, 0, "", "the IMS record, the robot log and the robot are required");
  }
  const auto& samples = input.log->samples;
  if (samples.size() < 2) throw InputError(source, 0, "robot log", "fewer than 2 samples");

  RestPoseResult result;
  const ims::EarthModel earth(input.site);
  result.detection = ims::detect_rest(
      *input.imu, earth, detector_options(input.sensor, options.detector_threshold_sigmas));

  for (const ims::RestInterval& interval : result.detection.intervals) {
    const double begin = interval.begin_s + options.edge_trim_s;
    const double end = interval.end_s - options.edge_trim_s;
    const std::string where = fmt::format("rest at {} .. {} (IMS clock)", seconds(interval.begin_s),
                                          seconds(interval.end_s));
    if (interval.duration_s() < options.min_duration_s || end <= begin) {
      result.rejected.push_back(
          fmt::format("{}: shorter than {} s", where, options.min_duration_s));
      continue;
    }
    // The same interval on the robot clock.
    const double robot_begin = begin - input.time_offset_s;
    const double robot_end = end - input.time_offset_s;
    if (robot_begin < samples.front().t_s || robot_end > samples.back().t_s) {
      result.rejected.push_back(fmt::format("{}: the robot log ({} .. {}) does not cover it", where,
                                            seconds(samples.front().t_s),
                                            seconds(samples.back().t_s)));
      continue;
    }
    auto first = first_at_or_after(samples.begin(), samples.end(), robot_begin);
    auto last = first_after(samples.begin(), samples.end(), robot_end);
    if (last - first < 2) {
      result.rejected.push_back(fmt::format("{}: fewer than 2 robot samples", where));
      continue;
    }
    RestPoseDetail detail;
    double payload_low = first->payload_kg, payload_high = first->payload_kg;
    for (auto it = first; it != last; ++it) {
      payload_low = std::min(payload_low, it->payload_kg);
      payload_high = std::max(payload_high, it->payload_kg);
    }
    detail.q_internal_spread_rad = reading_spread(first, last);
    int moving = -1;
    detail.q_internal_spread_rad.maxCoeff(&moving);
    if (detail.q_internal_spread_rad(moving) > options.max_joint_spread_rad) {
      result.rejected.push_back(fmt::format(
          "{}: the robot is not still there: joint {} moves by {:.3g} rad (> {:.3g} rad)", where,
          input.robot->joints[moving].name, detail.q_internal_spread_rad(moving),
          options.max_joint_spread_rad));
      continue;
    }
    // Of a still rest only the settled part: from where every joint's reading stays within
    // settle_tolerance_rad of its value at the rest's end (the controllers' settling tail).
    double rest_begin = begin;
    if (options.settle_tolerance_rad > 0.0) {
      const JointVector& final_q = (last - 1)->q_internal_rad;
      auto settled = last - 1;
      while (settled != first && ((settled - 1)->q_internal_rad - final_q).cwiseAbs().maxCoeff() <=
                                     options.settle_tolerance_rad)
        --settled;
      if (settled != first) {
        first = settled;
        rest_begin = first->t_s + input.time_offset_s;
        const double still_s = end - rest_begin;
        if (still_s < options.min_settled_s) {
          result.rejected.push_back(fmt::format(
              "{}: the joints settle within {:.3g} rad of their final reading only {:.3f} s "
              "before its end (< {} s): the robot is not still enough there",
              where, options.settle_tolerance_rad, still_s, options.min_settled_s));
          continue;
        }
      }
    }
    // The IMS must be still there too, beyond what the readings show (rest_stillness.hpp).
    double rest_end = end;
    if (options.check_stillness) {
      const JointVector q_reference = first->q_internal_rad;
      const Eigen::Matrix<double, 3, kJointCount> rotation_jacobian =
          geometric_jacobian(input.robot->kinematics, q_reference).bottomRows<3>();
      // The flange's mean rotation over [t0, t1] from the readings, relative to the rest's
      // first reading (the Jacobian holds over the few 1e-4 rad a rest creeps).
      const ExplainedRotation explained = [&](double t0_ims, double t1_ims) {
        const auto from = first_at_or_after(first, last, t0_ims - input.time_offset_s);
        const auto to = first_at_or_after(from, last, t1_ims - input.time_offset_s);
        if (from == to) return Eigen::Vector3d(Eigen::Vector3d::Zero());
        JointVector q_sum = JointVector::Zero();
        for (auto it = from; it != to; ++it) q_sum += it->q_internal_rad - q_reference;
        return Eigen::Vector3d(rotation_jacobian * q_sum / double(to - from));
      };
      const RestStillness stillness = assess_rest_stillness(
          *input.imu, earth, input.sensor, rest_begin, end, explained, options.stillness);
      if (stillness.flagged && !stillness.usable) {
        result.rejected.push_back(fmt::format("{}: {}; still for less than {} s", where,
                                              stillness.describe(), options.stillness.min_still_s));
        continue;
      }
      if (stillness.flagged) {
        rest_begin = stillness.still_begin_ims_s;
        rest_end = stillness.still_end_ims_s;
        result.trimmed.push_back(fmt::format("{}: {}; used only where still, {} .. {}", where,
                                             stillness.describe(), seconds(rest_begin),
                                             seconds(rest_end)));
        first = first_at_or_after(first, last, rest_begin - input.time_offset_s);
        last = first_after(first, last, rest_end - input.time_offset_s);
        if (last - first < 2) {
          result.rejected.push_back(
              fmt::format("{}: fewer than 2 robot samples where still", where));
          continue;
        }
        detail.q_internal_spread_rad = reading_spread(first, last);
      }
    }
    JointVector sum = JointVector::Zero();
    for (auto it = first; it != last; ++it) sum += it->q_internal_rad;
    detail.robot_samples = static_cast<std::size_t>(last - first);
    detail.q_internal_mean_rad = sum / static_cast<double>(detail.robot_samples);
    if (payload_high != payload_low) {
      result.rejected.push_back(fmt::format("{}: the payload changes during it", where));
      continue;
    }
    detail.payload_kg = payload_low;
    RigidBodyParameters payload = input.payload;
    payload.mass_kg = detail.payload_kg;
    detail.deflection =
        correct_static_deflection(*input.robot, payload.mass_kg > 0.0 ? &payload : nullptr,
                                  detail.q_internal_mean_rad, options.deflection);

    // The readings and rates at the two ends: a line through the samples within creep_fit_s.
    const auto end_fit = [&](double t_robot, JointVector& q, JointVector& rate) {
      double s_t = 0.0, s_tt = 0.0;
      JointVector s_q = JointVector::Zero(), s_tq = JointVector::Zero();
      int n = 0;
      for (auto it = first; it != last; ++it) {
        const double t = it->t_s - t_robot;
        if (std::abs(t) > options.creep_fit_s) continue;
        s_t += t;
        s_tt += t * t;
        s_q += it->q_internal_rad;
        s_tq += t * it->q_internal_rad;
        ++n;
      }
      const double det = n * s_tt - s_t * s_t;
      if (n < 2 || !(det > 0.0)) {
        q = detail.q_internal_mean_rad;
        rate.setZero();
        return;
      }
      rate = (n * s_tq - s_t * s_q) / det;
      q = (s_q - rate * s_t) / n;
    };
    JointVector q_begin, q_end, rate_begin, rate_end;
    end_fit(rest_begin - input.time_offset_s, q_begin, rate_begin);
    end_fit(rest_end - input.time_offset_s, q_end, rate_end);

    RestObservation rest;
    rest.q_creep_begin_rad = q_begin - detail.q_internal_mean_rad;
    rest.q_creep_end_rad = q_end - detail.q_internal_mean_rad;
    rest.q_rate_begin_rad_s = rate_begin;
    rest.q_rate_end_rad_s = rate_end;

    rest.label = fmt::format("rest {} at {:.1f} s", result.rests.size() + 1, begin);
    rest.begin_ims_s = rest_begin;
    rest.end_ims_s = rest_end;
    rest.q_link_rad = detail.deflection.q_link_rad;
    rest.q_link_sigma_rad = detail.deflection.q_link_sigma_rad;
    rest.q_windup_rad = detail.deflection.windup_rad;
    rest.q_play_rad = detail.deflection.play_rad;
    result.rests.push_back(rest);
    result.details.push_back(detail);
  }
  return result;
}

RobotJointSeries robot_joint_series(const RobotLog& log) {
  RobotJointSeries series;
  series.t_robot_s.reserve(log.samples.size());
  series.q_rad.reserve(log.samples.size());
  for (const RobotLogSample& s : log.samples) {
    series.t_robot_s.push_back(s.t_s);
    series.q_rad.push_back(s.q_internal_rad);
  }
  return series;
}

RobotJointSeries robot_joint_series(const RobotLog& log, const RobotDescription& robot) {
  RobotJointSeries series = robot_joint_series(log);
  for (int j = 0; j < kJointCount; ++j) {
    const DriveParameters& drive = robot.joints[j].drive;
    if (drive.stiffness_nm_per_rad > 0.0)
      series.link_lag_per_share_s[j] = drive.viscous_nm_s_per_rad / drive.stiffness_nm_per_rad;
  }
  return series;
}

TimeOffsetResult estimate_initial_time_offset(const ims::ImuSeries& imu, const RobotLog& log,
                                              const KinematicModel& kinematics,
                                              const ims::RestInterval& initial_rest,
                                              const TimeOffsetOptions& options) {
  if (initial_rest.last_sample >= imu.samples.size() ||
      initial_rest.last_sample <= initial_rest.first_sample) {
    throw InputError(imu.source, 0, "", "the initial rest lies outside the IMS record");
  }
  // Mean gyro rate over the rest: the Earth rate in S plus the gyro bias [rad/s].
  Eigen::Vector3d earth_rate_S = Eigen::Vector3d::Zero();
  if (imu.quantity == ims::ImuQuantity::kIncrements) {
    Eigen::Vector3d angle = Eigen::Vector3d::Zero();
    for (std::size_t i = initial_rest.first_sample + 1; i <= initial_rest.last_sample; ++i) {
      angle += imu.samples[i].gyro;
    }
    earth_rate_S = angle / (imu.samples[initial_rest.last_sample].t_s -
                            imu.samples[initial_rest.first_sample].t_s);
  } else {
    for (std::size_t i = initial_rest.first_sample; i <= initial_rest.last_sample; ++i) {
      earth_rate_S += imu.samples[i].gyro;
    }
    earth_rate_S /= static_cast<double>(initial_rest.last_sample - initial_rest.first_sample + 1);
  }
  // The joint series only while the flange rate is computed (both grow with the log).
  const RateMagnitudeSeries robot_rate = [&] {
    const RobotJointSeries joints = robot_joint_series(log);
    return flange_rate_magnitude(kinematics, joints.t_robot_s, joints.q_rad, "robot log");
  }();
  const RateMagnitudeSeries ims_rate = ims_rate_magnitude(imu, earth_rate_S);
  return estimate_time_offset(robot_rate, ims_rate, options);
}

}  // namespace imscal::calib
