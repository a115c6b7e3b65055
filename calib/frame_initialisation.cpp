#include "calib/frame_initialisation.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <stdexcept>

#include "core/input_error.hpp"
#include "ims/coarse_alignment.hpp"
#include "robot/forward_kinematics.hpp"

namespace imscal::calib {

FrameInitialValues initial_frame_values(const FrameCalibrationInput& input,
                                        const std::vector<RestWindow>& rests,
                                        const std::vector<ImuPreintegration>& motions,
                                        const ims::EarthModel& earth) {
  FrameInitialValues out;
  out.time_offset_s = input.time_offset_initial_s;
  const ims::ImuSeries& imu = *input.imu;
  // 1. Coarse alignment on the first rest; fewer blocks for short rests (>= 20 samples each).
  ims::CoarseAlignmentOptions alignment_options;
  alignment_options.block_count =
      std::clamp(static_cast<int>(rests.front().sample_count / 20), 8, 64);
  ims::CoarseAlignment alignment;
  try {
    alignment = ims::align_at_rest(
        imu, ims::SampleRange{rests.front().first_sample, rests.front().sample_count}, earth,
        alignment_options);
  } catch (const std::invalid_argument& e) {
    throw InputError(input.source, 0, "rests",
                     fmt::format("{}: coarse alignment (initial attitude) failed: {}",
                                 input.rests.front().label, e.what()));
  }
  // 2. The zero-bias chain.
  ims::NavState state;
  state.q_W_S = alignment.q_W_S;
  state.p_W = input.first_rest_position_W_m;
  const ImuBiases zero;
  for (std::size_t i = 0; i < rests.size(); ++i) {
    Eigen::Isometry3d T_W_S = Eigen::Isometry3d::Identity();
    T_W_S.linear() = state.q_W_S.toRotationMatrix();
    T_W_S.translation() = state.p_W - input.first_rest_position_W_m;
    out.T_W_S_rest.push_back(T_W_S);
    out.T_R_H_rest.push_back(
        forward_kinematics<double>(input.kinematics, input.rests[i].q_link_rad));
    if (i + 1 < rests.size()) {
      state.t_s = rests[i].end_s;
      state.v_W.setZero();
      state = motions[i].predict(state, earth, zero);
    }
  }
  // 3. Closed-form hand-eye.
  HandEyeOptions options;
  options.source = input.source.empty() ? std::string("frame calibration rests") : input.source;
  out.hand_eye = solve_robot_world_hand_eye(out.T_R_H_rest, out.T_W_S_rest, options);
  out.T_R_W = out.hand_eye.T_R_W;
  out.T_S_H = out.hand_eye.T_S_H;
  return out;
}

}  // namespace imscal::calib
