#include "calib/frame_measurements.hpp"

#include <fmt/format.h>

#include <algorithm>

#include "core/input_error.hpp"

namespace imscal::calib {

std::size_t first_sample_after(const ims::ImuSeries& imu, double t_s) {
  const auto it =
      std::upper_bound(imu.samples.begin(), imu.samples.end(), t_s,
                       [](double t, const ims::ImuSample& sample) { return t < sample.t_s; });
  return static_cast<std::size_t>(it - imu.samples.begin());
}

void mean_increments(const ims::ImuSeries& imu, std::size_t first, std::size_t count,
                     double duration_s, Eigen::Vector3d* rate, Eigen::Vector3d* specific_force) {
  Eigen::Vector3d angle = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  for (std::size_t k = first; k < first + count; ++k) {
    angle += imu.samples[k].gyro;
    velocity += imu.samples[k].acc;
  }
  *rate = angle / duration_s;
  *specific_force = velocity / duration_s;
}

RestWindow cut_rest_window(const ims::ImuSeries& imu, double begin_s, double end_s,
                           const std::string& label, const std::string& source) {
  if (imu.samples.size() < 2) throw InputError(source, 0, "imu", "fewer than 2 IMS samples");
  const double record_begin = imu.samples.front().t_s - imu.nominal_dt_s;
  const double record_end = imu.samples.back().t_s;
  if (!(begin_s < end_s) || begin_s < record_begin || end_s > record_end) {
    throw InputError(source, 0, "rests",
                     fmt::format("{}: rest [{:.4f} s, {:.4f} s] is empty or outside the IMS "
                                 "record [{:.4f} s, {:.4f} s] (IMS clock)",
                                 label, begin_s, end_s, record_begin, record_end));
  }
  RestWindow w;
  // First sample whose interval starts at or after begin_s: its stamp is > begin_s + ~dt.
  std::size_t first = first_sample_after(imu, begin_s);
  if (first < imu.samples.size() && first > 0 && imu.samples[first - 1].t_s < begin_s) {
    ++first;  // the interval of `first` starts before begin_s: skip it
  }
  if (first == 0) first = 1;  // the first sample's interval start has no stamp of its own
  const std::size_t last_plus_one = first_sample_after(imu, end_s);
  if (last_plus_one < first + 2) {
    throw InputError(
        source, 0, "rests",
        fmt::format("{}: fewer than 2 IMS samples in [{:.4f} s, {:.4f} s]", label, begin_s, end_s));
  }
  w.first_sample = first;
  w.sample_count = last_plus_one - first;
  w.begin_s = imu.samples[first - 1].t_s;
  w.end_s = imu.samples[last_plus_one - 1].t_s;
  mean_increments(imu, w.first_sample, w.sample_count, w.duration_s(), &w.mean_rate_rad_s,
                  &w.mean_specific_force_m_s2);
  return w;
}

std::vector<ImuPreintegration> integrate_motions(const ims::ImuSeries& imu,
                                                 const std::vector<RestWindow>& rests,
                                                 const ImuBiases& linearisation) {
  std::vector<ImuPreintegration> motions;
  motions.reserve(rests.size());
  for (std::size_t i = 0; i + 1 < rests.size(); ++i) {
    motions.emplace_back(imu, rests[i].end_s, rests[i + 1].begin_s, linearisation);
  }
  return motions;
}

}  // namespace imscal::calib
