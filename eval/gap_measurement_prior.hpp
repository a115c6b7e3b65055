#pragma once
// What the gap diagnosis knows of the IMS chain's own error, the inputs of its measurement budget
// (eval/gap_measurement_budget.hpp):
//   noise floor  per joint the 1-sigma of q_measured that the chain's zero-velocity smoother gives
//                (its position and attitude sigmas through the inverse Jacobian,
//                calib/joint_space_errors.hpp), RMS over the samples [rad]; `imscal calibrate`
//                writes it into joint_errors.csv as the header key `q_measured_sigma_rms_rad`
//   frames       the covariance of the chain's frames and sensor errors (calibrate's
//                frames.json, `covariance_si`), mapped onto the parameters whose joint-space
//                signatures the diagnosis knows (GapSignals::ImsChainColumns):
//     mount_t_{x,y,z}_m, mount_r_{x,y,z}_rad  T_S_H's error in flange axes (p_S_H, R_S_H rotated
//                                            by R_H_S; the lever arm's rotation cross term left
//                                            out)
//     gyro_bias_{x,y,z}_rad_s                the gyro biases in flange axes
//     world_rate_{x,y,z}_rad_s               R_W_R enters the chain twice (the smoother's initial
//                                            attitude and T_R_W) and cancels to first order; what
//                                            remains is the Earth rate resolved through the wrong
//                                            rotation, a world-fixed rate error delta x omega_ie.
//                                            frames.json has no latitude, so it is taken isotropic
//                                            with the same energy: sigma^2 = Omega^2 tr(P_R_W_R)/3
//     clock_offset_s                         the clock offset's error (time_offset.dt)
//     windup_scale_A1..6, play_scale_A1..6   the first rest's gear wind-up and backlash play,
//                                            scaled by the factors the calibration fitted
//                                            (windup_scale_deviation.*, play_scale_deviation.*;
//                                            0 where it fitted none): the chain starts its
//                                            smoothing from that rest's angles, so their error
//                                            dq0_j = dk_w w_j + dk_p p_j (w_j = tau_g / k_j,
//                                            p_j = +-half the play, at the first sample) stays in
//                                            every later pose. One rest sees only its tilt, not
//                                            how the deflection splits over A2, A3, A5: there
//                                            the factors keep most of their prior (1-sigma 1).
//                                            Taken only when the frames say the record had one
//                                            rest (rests.used); zero otherwise
//   The accelerometer biases are left out: the smoother's rest updates bound the position they
//   would drive, and its sigmas (the floor) hold what remains.
#include <Eigen/Core>
#include <array>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

namespace imscal::ident {
struct JointErrorLog;
}

namespace imscal::eval {

inline constexpr const char* kNoiseFloorKey = "q_measured_sigma_rms_rad";
inline constexpr int kMeasurementParameterCount = 25;
// The first of the 6 wind-up and 6 play scale deviations.
inline constexpr int kFirstDeflectionParameter = 13;
extern const std::array<const char*, kMeasurementParameterCount> kMeasurementParameterNames;

struct MeasurementPrior {
  std::vector<double> noise_floor_rad;  // per joint; empty: not known (no budget)
  // Of the parameters kMeasurementParameterNames [SI]; empty: not known (the floor alone).
  Eigen::MatrixXd covariance_si;
  std::string source;  // where it came from, in words
  bool known() const { return !noise_floor_rad.empty(); }
};

// The floor from a joint_errors.csv's header key kNoiseFloorKey (one number per joint, comma
// separated, > 0); empty when the log has no such key. InputError naming `file` and the key when
// it is not one finite positive number per joint.
std::vector<double> noise_floor_from_log(const ident::JointErrorLog& log, const std::string& file);

// The header value of kNoiseFloorKey that noise_floor_from_log reads: the floors [rad], comma
// separated, 6 significant digits (the floor is an RMS of sigmas; more digits carry no meaning).
std::string noise_floor_header_value(std::span<const double> floor_rad);

// The frames' covariance in the budget's parameters, from calibrate's frames.json; the deflection
// scales of the joints `joint_names` (windup_scale_deviation.<name>, play_scale_deviation.<name>)
// where the frames have them. InputError naming the file and the field when a parameter, the
// covariance or T_S_H is missing or invalid.
Eigen::MatrixXd chain_covariance_from_frames(const std::filesystem::path& frames_json,
                                             const std::vector<std::string>& joint_names);

}  // namespace imscal::eval
