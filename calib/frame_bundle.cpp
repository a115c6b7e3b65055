// Setting the frame-and-bias bundle up (calib/frame_bundle.hpp): input checks, rest windows,
// initial values, the optional models' switches and the parameter layout.
#include "calib/frame_bundle.hpp"

#include <fmt/format.h>

#include <cmath>

#include "core/input_error.hpp"
#include "robot/forward_kinematics.hpp"

namespace imscal::calib {
namespace {

// The input's site, once the input is checked.
const ims::Site& checked_site(const FrameCalibrationInput& input, const std::string& source) {
  if (input.imu == nullptr || input.imu->samples.empty()) {
    throw InputError(source, 0, "imu", "no IMS samples");
  }
  if (input.imu->quantity != ims::ImuQuantity::kIncrements) {
    throw InputError(source, 0, "imu", "the frame calibration needs increments, not rates");
  }
  const bool frames_known = input.known_frames.has_value();
  if (frames_known && input.rests.empty()) {
    throw InputError(source, 0, "rests",
                     "no rest pose: with the frames known (from " + input.known_frames->source +
                         ") at least one is needed for the biases");
  }
  if (!frames_known && input.rests.size() < 3) {
    throw InputError(source, 0, "rests",
                     fmt::format("{} rest poses; at least 3 are needed (T_R_W and T_S_H from "
                                 "rotations about two different axes)",
                                 input.rests.size()));
  }
  check_heading_reference(input.heading_reference, input.known_frames, source);
  return input.site;
}

std::vector<RestWindow> cut_rest_windows(const FrameCalibrationInput& input,
                                         const std::string& source) {
  std::vector<RestWindow> rests;
  for (std::size_t i = 0; i < input.rests.size(); ++i) {
    const RestObservation& r = input.rests[i];
    if (i > 0 && r.begin_ims_s < input.rests[i - 1].end_ims_s) {
      throw InputError(source, 0, "rests", fmt::format("{}: rests are not in time order", r.label));
    }
    rests.push_back(cut_rest_window(*input.imu, r.begin_ims_s, r.end_ims_s, r.label, source));
  }
  return rests;
}

// Closed-form hand-eye and cross-correlation; with known frames: those, held constant (no
// hand-eye: it needs >= 3 rests).
FrameInitialValues initial_values(const FrameBundle& b) {
  const FrameCalibrationInput& input = b.input;
  if (!b.frames_known) return initial_frame_values(input, b.rests, b.chain_motions, b.earth);
  FrameInitialValues known;
  known.T_S_H = input.known_frames->T_S_H;
  known.T_R_W.linear() = input.known_frames->R_W_R.transpose();
  known.time_offset_s = input.time_offset_initial_s;
  for (const RestObservation& r : input.rests)
    known.T_R_H_rest.push_back(forward_kinematics<double>(input.kinematics, r.q_link_rad));
  return known;
}

void set_quaternion(double* q, const Eigen::Matrix3d& R) {
  const Eigen::Quaterniond quaternion = Eigen::Quaterniond(R).normalized();
  Eigen::Map<Eigen::Quaterniond> out(q);
  out = quaternion;
}

void set_initial_unknowns(FrameBundle& b) {
  FrameUnknowns& x = b.x;
  x.allocate(b.rests.size(), b.acc_bias_drifts ? b.rests.size() : 1);
  for (std::size_t i = 0; i < b.rests.size(); ++i)
    x.b_a_blocks.push_back(x.b_a[b.acc_bias_drifts ? i : 0]);
  set_quaternion(x.q_W_R, b.init.T_R_W.linear().transpose());
  set_quaternion(x.q_S_H, b.init.T_S_H.linear());
  Eigen::Map<Eigen::Vector3d>(x.p_S_H) = b.init.T_S_H.translation();
  x.dt[0] = b.init.time_offset_s;
  x.rests = &b.input.rests;
}

// The reported blocks, in the covariance's order; only the estimated joints of a deflection
// scale (a SubsetManifold's tangent space leaves out the fixed ones).
void declare_parameter_layout(FrameBundle& b) {
  FrameUnknowns& x = b.x;
  FrameParameterLayout& layout = b.layout;
  layout.add_quaternion("R_W_R", x.q_W_R, {"east", "north", "up"});
  layout.add_quaternion("R_S_H", x.q_S_H, {"x", "y", "z"});
  layout.add("p_S_H", x.p_S_H, {"x", "y", "z"});
  layout.add("gyro_bias", x.b_g, {"x", "y", "z"});
  layout.add("acc_bias", x.b_a_blocks.front(), {"x", "y", "z"});
  if (b.time_offset_observed) layout.add("time_offset", x.dt, {"dt"});
  if (b.options.estimate_scale_factors) {
    layout.add("gyro_scale_factor", x.s_g, {"x", "y", "z"});
    layout.add("acc_scale_factor", x.s_a, {"x", "y", "z"});
  }
  for (auto [name, block, fixed] :
       {std::tuple{"windup_scale_deviation", x.m_w, &b.deflection.fixed_windup},
        std::tuple{"play_scale_deviation", x.m_p, &b.deflection.fixed_play}}) {
    std::vector<std::string> joints;
    std::vector<int> indices;
    for (int k = 0; k < kJointCount; ++k) {
      if (std::find(fixed->begin(), fixed->end(), k) != fixed->end()) continue;
      joints.push_back(fmt::format("A{}", k + 1));
      indices.push_back(k);
    }
    if (!joints.empty()) layout.add(name, block, joints, indices);
  }
  if (b.link_share_estimated) layout.add("link_share", x.link_share, {"s"});
}

}  // namespace

void check_heading_reference(const std::optional<HeadingReference>& heading,
                             const std::optional<KnownFrames>& known_frames,
                             const std::string& source) {
  if (!heading) return;
  if (known_frames)
    throw InputError(source, 0, "heading_reference",
                     "a heading reference (" + heading->source + ") with the frames held at " +
                         known_frames->source +
                         ": the base's heading is that session's, not estimated here");
  if (!(heading->sigma_rad > 0.0) || !std::isfinite(heading->sigma_rad) ||
      !std::isfinite(heading->yaw_rad))
    throw InputError(source, 0, "heading_reference",
                     fmt::format("{}: expected a finite yaw and a sigma > 0, got {} +- {} rad",
                                 heading->source, heading->yaw_rad, heading->sigma_rad));
}

namespace {

// The named blocks of FrameUnknowns in their buffer order, with their sizes: the one list the
// buffer's size and its layout both come from.
struct NamedBlock {
  double* FrameUnknowns::*block;
  std::size_t size;
};
constexpr NamedBlock kNamedBlocks[] = {{&FrameUnknowns::q_W_R, 4}, {&FrameUnknowns::q_S_H, 4},
                                       {&FrameUnknowns::p_S_H, 3}, {&FrameUnknowns::b_g, 3},
                                       {&FrameUnknowns::dt, 1},    {&FrameUnknowns::link_share, 1},
                                       {&FrameUnknowns::s_g, 3},   {&FrameUnknowns::s_a, 3},
                                       {&FrameUnknowns::m_w, 6},   {&FrameUnknowns::m_p, 6}};
constexpr std::size_t named_blocks_size() {
  std::size_t size = 0;
  for (const NamedBlock& b : kNamedBlocks) size += b.size;
  return size;
}

}  // namespace

void FrameUnknowns::allocate(std::size_t rest_count, std::size_t acc_bias_count) {
  storage_.assign(6 * rest_count + 3 * acc_bias_count + named_blocks_size(), 0.0);
  double* next = storage_.data();
  const auto take = [&next](std::size_t size) {
    double* block = next;
    next += size;
    return block;
  };
  dq.clear();
  b_a.clear();
  b_a_blocks.clear();
  for (std::size_t i = 0; i < acc_bias_count; ++i) b_a.push_back(take(3));
  for (std::size_t i = 0; i < rest_count; ++i) dq.push_back(take(6));
  for (const NamedBlock& b : kNamedBlocks) this->*b.block = take(b.size);
  q_W_R[3] = 1.0;  // identity, Eigen order x, y, z, w
  q_S_H[3] = 1.0;
}

Eigen::Matrix3d FrameUnknowns::R_W_R() const {
  return Eigen::Map<const Eigen::Quaterniond>(q_W_R).toRotationMatrix();
}

Eigen::Matrix3d FrameUnknowns::R_S_H() const {
  return Eigen::Map<const Eigen::Quaterniond>(q_S_H).toRotationMatrix();
}

ImuBiases FrameUnknowns::biases() const {
  ImuBiases b;
  b.gyro_rad_s = Eigen::Map<const Eigen::Vector3d>(b_g);
  b.acc_m_s2 = Eigen::Map<const Eigen::Vector3d>(b_a_blocks.front());
  return b;
}

JointVector FrameUnknowns::joint_deviation(std::size_t i) const {
  const RestObservation& r = (*rests)[i];
  return rest_deviation<double>(dq[i], m_w, m_p, r.q_windup_rad, r.q_play_rad);
}

FrameBundle::FrameBundle(const FrameCalibrationInput& input_,
                         const FrameCalibrationOptions& options_)
    : input(input_),
      options(options_),
      source(input_.source.empty() ? std::string("frame calibration") : input_.source),
      earth(checked_site(input_, source)) {
  frames_known = input.known_frames.has_value();
  rests = cut_rest_windows(input, source);
  chain_motions = integrate_motions(*input.imu, rests, ImuBiases{});
  init = initial_values(*this);
  acc_bias_drifts = input.noise.acc_bias_drift_psd > 0.0;
  set_initial_unknowns(*this);
  set_up_deflection_scale(*this);
  set_up_time_offset(*this);
  declare_parameter_layout(*this);
}

}  // namespace imscal::calib
