#pragma once
// The measurements of the frame calibration cut out of an IMS record: the rest windows snapped to
// the increment stamps with their mean angular rate and specific force, and the motions between
// consecutive rests as IMU preintegrations (calib/imu_preintegration.hpp).
//
// Snapping: a window (t_a, t_b] on the IMS clock is taken as the increments whose stamps lie in
// it, i.e. from the stamp before the first of them to the last of them; the means are the sums of
// the increments over that span divided by it (exact for the mean rate and specific force).
// The motion i -> i+1 runs from the end of rest i to the beginning of rest i+1 (both stamps), so
// rests and motions use disjoint samples and their noises are independent.
#include <Eigen/Core>
#include <cstddef>
#include <string>
#include <vector>

#include "calib/imu_preintegration.hpp"
#include "ims/imu_data.hpp"

namespace imscal::calib {

struct RestWindow {
  double begin_s = 0.0;          // IMS clock, an increment stamp (start of the first interval)
  double end_s = 0.0;            // the last increment stamp
  std::size_t first_sample = 0;  // samples [first_sample, first_sample + sample_count)
  std::size_t sample_count = 0;
  Eigen::Vector3d mean_rate_rad_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d mean_specific_force_m_s2 = Eigen::Vector3d::Zero();
  double duration_s() const { return end_s - begin_s; }
};

// Index of the first sample whose stamp is > t (samples.size() if none).
std::size_t first_sample_after(const ims::ImuSeries& imu, double t_s);

// The rest window inside [begin_s, end_s] (IMS clock). Throws InputError naming `label` when
// the window lies outside the record or holds fewer than 2 samples.
RestWindow cut_rest_window(const ims::ImuSeries& imu, double begin_s, double end_s,
                           const std::string& label, const std::string& source);

// The mean rate and specific force over samples (t_a, t_b] of an increment series, where t_a
// and t_b are stamps (or t_a the start of the first interval).
void mean_increments(const ims::ImuSeries& imu, std::size_t first, std::size_t count,
                     double duration_s, Eigen::Vector3d* rate, Eigen::Vector3d* specific_force);

// The preintegrations of the motions between consecutive rests at the biases `linearisation`.
std::vector<ImuPreintegration> integrate_motions(const ims::ImuSeries& imu,
                                                 const std::vector<RestWindow>& rests,
                                                 const ImuBiases& linearisation);

}  // namespace imscal::calib
