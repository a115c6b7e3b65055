// The optional models of the frame-and-bias bundle (calib/frame_bundle.hpp) other than the time
// offset (calib/frame_bundle_time_offset.cpp): known frames, a heading reference, the
// accelerometer bias's drift, scale factors and the deflection scales.
#include <algorithm>
#include <cmath>

#include "calib/frame_bundle.hpp"

namespace imscal::calib {
namespace {

// The spec's prior of a bias triad, N(0, sigma) per axis (with known frames only, see below).
struct BiasPriorResidual {
  double inverse_sigma = 0.0;
  template <typename T>
  bool operator()(const T* bias, T* residual) const {
    for (int k = 0; k < 3; ++k) residual[k] = bias[k] * T(inverse_sigma);
    return true;
  }
};

// A surveyed heading of the base (HeadingReference): the yaw of R_W_R = Rz(yaw) Ry Rx,
// atan2(R_10, R_00) of the unit quaternion q_W_R (x, y, z, w), minus the reference, wrapped to
// (-pi, pi], over its sigma. Its derivative along a small rotation about W's up axis is 1.
struct HeadingPriorResidual {
  double yaw_rad = 0.0;
  double inverse_sigma = 0.0;
  template <typename T>
  bool operator()(const T* q, T* residual) const {
    const T r00 = T(1) - T(2) * (q[1] * q[1] + q[2] * q[2]);
    const T r10 = T(2) * (q[0] * q[1] + q[3] * q[2]);
    T difference = ceres::atan2(r10, r00) - T(yaw_rad);
    if (difference > T(M_PI)) difference -= T(2 * M_PI);
    if (difference <= T(-M_PI)) difference += T(2 * M_PI);
    residual[0] = difference * T(inverse_sigma);
    return true;
  }
};

}  // namespace

void add_heading_reference(FrameBundle& b, ceres::Problem& problem) {
  const std::optional<HeadingReference>& reference = b.input.heading_reference;
  if (!reference) return;
  problem.AddResidualBlock(
      new ceres::AutoDiffCostFunction<HeadingPriorResidual, 1, 4>(
          new HeadingPriorResidual{reference->yaw_rad, 1.0 / reference->sigma_rad}),
      nullptr, b.x.q_W_R);
}

void set_up_deflection_scale(FrameBundle& b) {
  DeflectionScaleModel& d = b.deflection;
  const FrameCalibrationOptions& options = b.options;
  for (int k = 0; k < kJointCount; ++k) {
    double windup = 0.0, play = 0.0;
    for (const RestObservation& r : b.input.rests) {
      windup = std::max(windup, std::abs(r.q_windup_rad[k]));
      play = std::max(play, std::abs(r.q_play_rad[k]));
    }
    const bool estimate = options.estimate_deflection_scale && options.deflection_scale_sigma > 0.0;
    if (estimate && windup > 0.0)
      d.windup_inverse_sigma[k] = 1.0 / options.deflection_scale_sigma;
    else
      d.fixed_windup.push_back(k);
    if (estimate && play > 0.0)
      d.play_inverse_sigma[k] = 1.0 / options.deflection_scale_sigma;
    else
      d.fixed_play.push_back(k);
  }
}

void add_known_frames(FrameBundle& b, ceres::Problem& problem) {
  if (!b.frames_known) return;
  FrameUnknowns& x = b.x;
  problem.SetParameterBlockConstant(x.q_W_R);
  problem.SetParameterBlockConstant(x.q_S_H);
  problem.SetParameterBlockConstant(x.p_S_H);
  // With few rests and no motion between them the tilt of a rest (its joint deviations:
  // backlash play, deflection; priors of up to ~1e-3 rad) trades with the accelerometer bias
  // (1e-3 rad of tilt = 1000 ug); a full session separates them through the motions. The
  // spec's turn-on priors (ImuNoiseModel::*_bias_sigma) keep the biases to what the unit
  // can have (measured on the two-session chain: 1 rest gave acc_bias 1200 ug 1-sigma
  // without them and joint errors that diverged from the first move on).
  for (auto [block, sigma] : {std::pair{x.b_g, b.input.noise.gyro_bias_sigma_rad_s},
                              std::pair{x.b_a_blocks.front(), b.input.noise.acc_bias_sigma_m_s2}})
    if (sigma > 0.0)
      problem.AddResidualBlock(new ceres::AutoDiffCostFunction<BiasPriorResidual, 3, 3>(
                                   new BiasPriorResidual{1.0 / sigma}),
                               nullptr, block);
}

void add_acc_bias_drift(FrameBundle& b, ceres::Problem& problem) {
  const std::vector<RestWindow>& rests = b.rests;
  for (std::size_t i = 0; b.acc_bias_drifts && i + 1 < rests.size(); ++i) {
    // Between the rests' mid-times.
    const double gap_s = 0.5 * (rests[i + 1].begin_s + rests[i + 1].end_s) -
                         0.5 * (rests[i].begin_s + rests[i].end_s);
    BiasDriftResidual drift;
    drift.inverse_sigma = 1.0 / std::sqrt(b.input.noise.acc_bias_drift_psd * gap_s);
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<BiasDriftResidual, 3, 3, 3>(new BiasDriftResidual(drift)),
        nullptr, b.x.b_a_blocks[i], b.x.b_a_blocks[i + 1]);
  }
}

// Scale factors enter only the rest residuals; held at zero unless estimated.
void add_scale_factors(FrameBundle& b, ceres::Problem& problem) {
  problem.AddParameterBlock(b.x.s_g, 3);
  problem.AddParameterBlock(b.x.s_a, 3);
  if (!b.options.estimate_scale_factors) {
    problem.SetParameterBlockConstant(b.x.s_g);
    problem.SetParameterBlockConstant(b.x.s_a);
  }
}

void add_deflection_scale(FrameBundle& b, ceres::Problem& problem) {
  FrameUnknowns& x = b.x;
  const DeflectionScaleModel& d = b.deflection;
  problem.AddParameterBlock(x.m_w, 6);
  problem.AddParameterBlock(x.m_p, 6);
  for (auto [block, fixed] : {std::pair{x.m_w, &d.fixed_windup}, std::pair{x.m_p, &d.fixed_play}}) {
    if (fixed->size() == static_cast<std::size_t>(kJointCount))
      problem.SetParameterBlockConstant(block);
    else if (!fixed->empty())
      problem.SetManifold(block, new ceres::SubsetManifold(6, *fixed));
  }
  if (d.windup_estimated() || d.play_estimated()) {
    DeflectionScalePriorResidual prior;
    prior.inverse_sigma_windup = d.windup_inverse_sigma;
    prior.inverse_sigma_play = d.play_inverse_sigma;
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<DeflectionScalePriorResidual, 12, 6, 6>(
            new DeflectionScalePriorResidual(prior)),
        nullptr, x.m_w, x.m_p);
  }
}

}  // namespace imscal::calib
