#pragma once
// A motion of the sensor frame S relative to W given in closed form, so that IMS signals can be
// synthesised from it exactly and every other step of the chain checked against it.
//
// Position:  p_W(t) = p0_W + sum_j d_W_j * s_j(t)
// Attitude:  q_W_S(t) = q0_W_S * exp(u_1 theta_1(t)) * exp(u_2 theta_2(t)) * ...   (in the
//            order the rotations were added; u_k is a unit axis in the sensor frame as it is
//            after the rotations before k, i.e. for rotations that follow one another in time,
//            the axis in S at the start of rotation k), theta_k(t) = angle_k * s_k(t).
// Body rate: omega_WS_S = sum_k (R_{k+1} ... R_n)^T u_k dtheta_k/dt   (R_k = exp(u_k theta_k)),
//            which follows from R^T dR/dt = sum_k (R_{k+1..n})^T [u_k]x (R_{k+1..n}) dtheta_k/dt.
//
// s(t) is the degree-9 smooth step from 0 to 1 over [t_begin, t_end]: its first four
// derivatives vanish at both ends, so the motion is C^4 everywhere and C^infinity between the
// ends of the steps. Peak values: ds/du = 630/256 = 2.461 at the middle, |d2s/du2| <= 9.372.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <filesystem>
#include <memory>
#include <utility>
#include <vector>

#include "core/config_node.hpp"
#include "ims/imu_synthesis.hpp"
#include "ims/trajectory.hpp"

namespace imscal::ims {

// Degree-9 smooth step from 0 (t <= t_begin_s) to 1 (t >= t_end_s).
struct SmoothStep {
  double t_begin_s = 0.0;
  double t_end_s = 1.0;
  struct Value {
    double s = 0.0;        // [1]
    double ds_dt = 0.0;    // [1/s]
    double d2s_dt2 = 0.0;  // [1/s^2]
  };
  Value at(double t_s) const;
  static constexpr double kPeakSlope = 630.0 / 256.0;  // max ds/du, u = normalised time
  static constexpr double kPeakCurvature = 9.3723;     // max |d2s/du2| (rounded up)
};

class AnalyticTrajectory final : public Trajectory, public PiecewiseSmooth {
 public:
  AnalyticTrajectory(double begin_s, double end_s,
                     const Eigen::Quaterniond& q_W_S_start = Eigen::Quaterniond::Identity(),
                     const Eigen::Vector3d& p_W_start = Eigen::Vector3d::Zero());

  // Rotation by angle_rad about axis_S (normalised here) over [t_begin_s, t_end_s]; composed
  // after the rotations added before (see above). Throws std::invalid_argument on a zero axis
  // or an empty or reversed window.
  void add_rotation(double t_begin_s, double t_end_s, const Eigen::Vector3d& axis_S,
                    double angle_rad);
  // Displacement of the S origin by displacement_W [m] over [t_begin_s, t_end_s].
  void add_translation(double t_begin_s, double t_end_s, const Eigen::Vector3d& displacement_W);

  double begin_s() const override { return begin_s_; }
  double end_s() const override { return end_s_; }
  KinematicState at(double t_s) const override;
  // Begin and end times of all steps (where the signals' higher derivatives jump), sorted.
  const std::vector<double>& joints_s() const override { return joints_s_; }

  // Maximal intervals within [begin_s, end_s] in which S is exactly at rest relative to W (no
  // step active), as (start, end) pairs in time order; truth for zero-velocity detection.
  std::vector<std::pair<double, double>> rest_intervals() const;

 private:
  struct RotationStep {
    SmoothStep step;
    Eigen::Vector3d axis_S;
    double angle_rad;
  };
  struct TranslationStep {
    SmoothStep step;
    Eigen::Vector3d displacement_W;
  };
  double begin_s_;
  double end_s_;
  Eigen::Quaterniond q_W_S_start_;
  Eigen::Vector3d p_W_start_;
  std::vector<RotationStep> rotations_;
  std::vector<TranslationStep> translations_;
  std::vector<double> joints_s_;
  void add_joints(double t_begin_s, double t_end_s);
};

// 60 s: rest 3 s; +-pi rad about x, y and z of S in turn (2.6 s each way, peak 2.97 rad/s);
// +-1 m along x, y and z of W (2.2 s each way, peak 1.94 m/s^2); rotation and translation at the
// same time (partly overlapping windows) and back; rest >= 5 s to the end. Ends at the start
// pose. Starts at identity attitude at the W origin.
std::unique_ptr<AnalyticTrajectory> make_roundtrip_test_motion();

// Random robot-like moves (concurrent rotation about a random axis by up to 2 rad, peak rate
// <= ~3 rad/s, and translation by up to 1 m, peak acceleration <= 2 m/s^2, staying within a
// box of +-0.5 m horizontally and +-0.3 m vertically) separated by rests of 0.5..1 s, such that
// every window of max_move_s seconds holds a whole rest of >= 0.5 s (moves last
// 1 .. max_move_s - 1 s). Rest of 2 s at the start, >= 1 s at the end.
// The same seed gives the same motion on every platform (own uniform draws on mt19937_64).
// Requires duration_s >= 4 and max_move_s >= 2; throws std::invalid_argument otherwise.
std::unique_ptr<AnalyticTrajectory> make_motion_with_pauses(double duration_s, double max_move_s,
                                                            unsigned seed);

// A motion from YAML (datasets/motions/*.yaml), one of
//   kind: roundtrip_test
//   kind: random_with_pauses   + duration_s, max_move_s, seed
//   kind: segments             + optional start {position_m: [..], rotation_vector_deg: [..]}
//                                (q_W_S at the start as a rotation vector in W) and segments:
//                                a list of {duration_s, optional rotation_axis_S: [..],
//                                rotation_angle_deg, translation_W_m: [..]}; a segment with
//                                neither rotation nor translation is a rest.
// Bad input -> InputError naming file, line and key.
std::unique_ptr<AnalyticTrajectory> load_motion(const ConfigNode& config);
std::unique_ptr<AnalyticTrajectory> load_motion_file(const std::filesystem::path& file);

}  // namespace imscal::ims
