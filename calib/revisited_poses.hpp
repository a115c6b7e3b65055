#pragma once
// The robot's pose repeatability as an aid to the smoothed sensor trajectory (calib/
// joint_space_errors.hpp). Zero-velocity and creep updates make the smoother's velocity, attitude
// and biases observable, but not its position: each move leaves a position error of its own
// (sensor noise, in-run bias changes, creep velocities a few 1e-6 m/s off) and these add up over
// the record. Measured on the identification program with the true frames, biases and clock: the
// attitude stays within 0.02 mrad, the position walks off by 0.3-0.7 mm, and the joint angles by
// inverse kinematics take 0.2-0.8 mrad RMS from it. A robot that returns to a commanded pose with
// the same payload stands there again to its repeatability (ISO 9283 RP: ~0.05 mm for a KR 16
// class arm); what differs between the visits, the motors' remaining position error, its readings
// show. So at the end of every commanded standstill at the first rest's pose and payload
//   e_k = (p_IMS - p_FK(q_internal))_k - (p_IMS - p_FK(q_internal))_first rest
// is the smoothed position's error there (the gear deflection, equal at every visit, cancels).
// Generalised to every pose the robot returns to: each settled standstill i gets an
// error e_i, found by least squares (per axis) from
//   e_first = 0                           the first rest defines W_T_S's position (its FK);
//   e_k - e_j = d_k - d_j                 consecutive visits j, k of one pose with one payload,
//                                         d = p_IMS - p_FK(q_internal), 1-sigma the repeatability;
//   e_k - e_j = 0                         a payload change at rest (no move between j and k: the
//                                         IMS's error does not change while the arm stands,
//                                         though the gears' deflection does);
//   e_{i+1} - e_i ~ N(0, q (t_{i+1} - t_i)) the position's random walk between standstills.
// Where only the first rest's pose is revisited this is the linear interpolation in time between
// its visits; a pose revisited elsewhere (the line start of seed-line, before and after the
// lines) adds the change of the error between its visits. The smoothed positions are corrected
// by e(t), linear in time between the standstills and held beyond the first and last. The first
// rest is the first settled standstill inside the smoothed record (where the smoothing starts
// from its forward kinematics; a later one when the record starts later: the corrections are
// then relative to its error).
#include <Eigen/Core>
#include <span>
#include <vector>

#include <Eigen/Geometry>

#include "ims/zupt_smoother.hpp"
#include "robot/robot_description.hpp"
#include "robot/robot_log.hpp"

namespace imscal::calib {

struct RevisitedPoseOptions {
  // The settled end of a standstill: its readings from this long before its last sample on.
  // At least this long, too: shorter standstills are not used.
  double settle_s = 1.5;
  double average_s = 0.1;  // readings and positions averaged over the standstill's last 0.1 s
  // Commanded poses this close per joint are the same (1e-6 rad: 1 um at a metre; an
  // interpolator may round a taught point differently on the way back).
  double same_pose_tolerance_rad = 1e-6;
  // 1-sigma of a return to a pose [m] (the robot's repeatability, per axis; ISO 9283 RP of a
  // KR 16 class arm ~0.05 mm as a band, 0.01 mm as a sigma) and the position's random walk
  // between standstills [m^2/s] (0.5 mm over 170 s on the identification record: 1.5e-9).
  // Their ratio sets how far a return pulls: visits 10 s apart keep ~0.7 % of the walk.
  double repeatability_m = 1e-5;
  double position_walk_m2_per_s = 1.5e-9;
};

// The smoothed position's error at one visit (IMS clock, in W).
struct PositionErrorSample {
  double t_s = 0.0;
  Eigen::Vector3d error_W = Eigen::Vector3d::Zero();
  // A return to a pose stood at before with the same payload (or the standstill after a payload
  // change at rest): the error here is measured, not interpolated.
  bool revisit = false;
};

// A commanded standstill (one pose, one payload) of at least settle_s: its robot log samples
// [first, last], of which [first_averaged, last] are averaged (the last average_s).
struct StandstillWindow {
  std::size_t first = 0, first_averaged = 0, last = 0;
};
std::vector<StandstillWindow> settled_standstill_windows(const RobotLog& log,
                                                         const RevisitedPoseOptions& options = {});

// The errors at every settled standstill, sorted by time; the first is zero by definition.
// The trajectory is interpolated only at the robot samples [first_averaged, last] of
// settled_standstill_windows (t_ims = t_robot + time_offset_s): the states around those times
// alone give the same errors.
// trajectory: the smoothed sensor poses (IMS clock, sorted); T_W_R the robot base in W, p_H_S the
// sensor's origin in the flange frame, t_ims = t_robot + time_offset_s.
std::vector<PositionErrorSample> position_errors_at_revisited_poses(
    const std::vector<ims::SmoothedState>& trajectory, const RobotLog& log,
    const KinematicModel& kinematics, const Eigen::Isometry3d& T_W_R, const Eigen::Vector3d& p_H_S,
    double time_offset_s, const RevisitedPoseOptions& options = {});

// p_W(t) -= e(t): linear between the samples, held before the first and after the last.
void remove_position_errors(std::span<ims::SmoothedState> trajectory,
                            const std::vector<PositionErrorSample>& errors);

}  // namespace imscal::calib
