#pragma once
// A tool-mounted IMU record: one CSV per sensor with the sensor's rates and the robot's tool pose
// on the same time stamps, as in the "IMU_dataset" of Rasteiro et al. (MEMS IMUs on an ABB robot):
//   t_s, gyro_x_dps, gyro_y_dps, gyro_z_dps, acc_x_g, acc_y_g, acc_z_g,
//   robot_x_mm, robot_y_mm, robot_z_mm, robot_qw, robot_qx, robot_qy, robot_qz
// or, for a commercial AHRS's own orientation output (XSENS MTi-30),
//   t_s, sens_q0, sens_q1, sens_q2, sens_q3, robot_x_mm, ..., robot_qz.
// Units are converted to SI here, at the boundary. Real data carry defects; the reader and
// the checks detect and REPORT each one as a finding (kind, where, size, words) instead of using
// it silently:
//   - rows with NaN (dropped, lines named), irregular and jittered time steps (statistics, gaps),
//     robot quaternions that are not unit (component-wise interpolation across a sign flip);
//   - gyro flat tops near the largest reading of an axis (a rail), compared with the robot's rate;
//   - a gyro scale/unit mismatch (|gyro| against the robot's angular rate from the pose);
//   - the time offset sensor vs robot (cross-correlation of rate magnitudes, calib/time_offset);
//   - sensor axes far from the tool axes (rotation fitted to the rate vectors).
// Unusable input (missing/unknown columns, empty file, truncated row, text that is not a number,
// time not increasing) is refused with InputError(file, line, field).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

namespace imscal::calib {

enum class ToolImuFindingKind {
  kNanRows,
  kIrregularTimeSteps,
  kRobotQuaternionNotUnit,
  kGyroNearRail,
  kGyroScaleMismatch,
  kTimeOffset,
  kAxisMisalignment,
  kRobotQuaternionConvention,
  kSensorMissedMotion,
};

const char* to_string(ToolImuFindingKind kind);

struct ToolImuFinding {
  ToolImuFindingKind kind;
  std::string where;      // file and lines, or axis
  double size = 0.0;      // the defect's size in `unit`
  std::string unit;       // of `size` ("rows", "s", "deg", "deg/s", "ratio")
  std::string message;    // plain words
  bool is_defect = true;  // false: looked for, found harmless (message says why)
};

struct ToolImuRecord {
  std::string file;
  bool has_raw_imu = false;                 // gyro and accelerometer columns
  bool has_sensor_orientation = false;      // sens_q0..3 (an AHRS's own filter output)
  std::vector<std::size_t> lines;           // 1-based file line of every kept row
  std::vector<double> t_s;                  // strictly increasing
  std::vector<Eigen::Vector3d> gyro_rad_s;  // as labelled in the file (deg/s -> rad/s)
  std::vector<Eigen::Vector3d> acc_m_s2;    // as labelled (g -> m/s^2, g = 9.80665)
  // AHRS orientation: sensor frame X in the AHRS's own navigation frame N (normalised).
  std::vector<Eigen::Quaterniond> q_N_X;
  std::vector<Eigen::Vector3d> robot_position_m;
  // Tool T in the robot base B (normalised). See
  // ToolImuReadOptions::robot_quaternion_is_base_in_tool.
  std::vector<Eigen::Quaterniond> q_B_T;
  bool robot_quaternion_conjugated = false;   // q_B_T is the conjugate of the file's quaternion
  std::vector<double> robot_quaternion_norm;  // as read
  std::vector<bool> robot_pose_valid;         // false: quaternion too far from unit to be used
  std::vector<ToolImuFinding> findings;       // from reading (NaN rows, time steps, quaternions)
};

struct ToolImuReadOptions {
  // A robot quaternion whose norm is off by more than this is reported; below
  // min_robot_quaternion_norm its direction is meaningless (lerp through q and -q) and the pose is
  // marked invalid.
  // not used (the robot's own poses at ~15 Hz are unit; a lerp between neighbours stays within
  // 1e-3 of unit, one across a sign flip does not and points in a wrong direction).
  double robot_quaternion_norm_tolerance = 0.01;
  // The IMU_dataset's robot_qw..qz hold the base in the tool frame (q_T_B), not the tool in the
  // base: only their conjugate has a body rate that matches the gyros (checked on every record by
  // check_tool_imu_record, which reports the convention that fits).
  bool robot_quaternion_is_base_in_tool = true;
  // Time steps further than this fraction from the median step are counted as irregular; steps
  // longer than gap_factor x median are listed as gaps.
  double irregular_step_fraction = 0.5;
  double gap_factor = 5.0;
};

ToolImuRecord read_tool_imu_record(const std::filesystem::path& file,
                                   const ToolImuReadOptions& options = {});

// Slerp of the valid robot orientations at time t [s, file clock]; false when t lies outside the
// valid poses or between valid poses further apart than max_gap_s.
bool robot_orientation_at(const ToolImuRecord& record, double t_s, Eigen::Quaterniond& q_B_T,
                          double max_gap_s = 0.2);

// The robot tool's angular rate in T [rad/s] on a uniform grid, from the valid poses (slerp onto
// the grid, central differences over +-one step). Empty grid points (gaps) are left out.
struct RobotRateSeries {
  std::vector<double> t_s;
  std::vector<Eigen::Vector3d> omega_T_rad_s;
};
// The difference spans +-half_span_s: the poses carry timing jitter of a few ms, which ruins
// differences over neighbouring samples.
RobotRateSeries robot_tool_rate(const ToolImuRecord& record, double step_s = 0.01,
                                double half_span_s = 0.05);

// Linear interpolation of the robot rate series at t; false outside it.
bool robot_rate_at(const RobotRateSeries& series, double t_s, Eigen::Vector3d& omega_T_rad_s);

// A span of robot motion between two stops: the robot's |omega| stays above a threshold.
struct MotionSegment {
  double begin_s = 0.0;  // sensor clock, with a 0.15 s margin on both sides
  double end_s = 0.0;
  double robot_angle_rad = 0.0;     // integral of the robot's |omega| over the span
  double gyro_angle_raw_rad = 0.0;  // integral of |gyro| as labelled (not scaled)
  std::size_t first_line = 0;       // file lines of the first and last sensor sample inside
  std::size_t last_line = 0;
};

// Segments of robot motion (|omega| above rate_threshold_rad_s) turning more than
// min_angle_rad, with the robot's turned angle and the gyro's integrated |rate| over the same
// span of the sensor clock (t_sensor = t_robot + offset_s).
std::vector<MotionSegment> motion_segments(const ToolImuRecord& record,
                                           const RobotRateSeries& robot, double offset_s,
                                           double rate_threshold_rad_s, double min_angle_rad);

struct ToolImuCheckOptions {
  double max_abs_time_offset_s = 0.5;
  // Only samples where the robot turns faster than this enter the scale and axis fits [rad/s].
  double min_rate_for_fit_rad_s = 0.2;
  // Near-rail test: readings within this fraction of the axis's largest |reading| ...
  double rail_fraction = 0.01;
  // ... for at least this many consecutive samples form a flat top.
  std::size_t min_flat_top_samples = 5;
  // Every flat top is reported; it is called confirmed clipping (samples then left out of the
  // fits) when the robot (scaled like the gyro) turns faster than the gyro reads by more than
  // this fraction during it: the robot's rate from the jittered poses scatters by ~10 %.
  double clipping_excess_fraction = 0.15;
  // Motion segments (robot rate above segment_rate_rad_s) turning more than
  // min_segment_angle_rad, whose gyro-integrated angle (scaled) differs from the robot's by more
  // than missed_motion_fraction, are reported: the sensor stream lost or garbled that motion.
  double segment_rate_rad_s = 0.05;
  double min_segment_angle_rad = 10.0 * M_PI / 180.0;
  double missed_motion_fraction = 0.25;
  // A scale ratio further than this from 1 is reported as a unit/scale mismatch.
  double scale_tolerance = 0.10;
  // An axis misalignment larger than this is reported [rad].
  double misalignment_threshold_rad = 5.0 * M_PI / 180.0;
};

struct ToolImuAnalysis {
  std::vector<ToolImuFinding> findings;  // the record's findings, then the checks'
  double time_offset_s = 0.0;            // t_sensor = t_robot + offset
  double time_offset_peak_correlation = 0.0;
  // |gyro as labelled| / |robot rate|: 1 when the labelled unit is right.
  double gyro_scale_ratio = 1.0;
  Eigen::Matrix3d R_T_S = Eigen::Matrix3d::Identity();  // rate-vector fit (after the offset)
  double misalignment_rad = 0.0;                        // angle of R_T_S
  // Unexplained fraction of the robot's rate after the fit (sqrt of residual over total sum of
  // squares), with the robot quaternion as read and with it conjugated.
  double rate_fit_residual = 0.0;
  double conjugate_rate_fit_residual = 0.0;
  std::size_t fit_sample_count = 0;
  // Axes with a flat top that the robot confirms as clipping, and the largest reading of each
  // such axis [rad/s] (as labelled): samples at or above 0.99 x this are unusable.
  std::vector<int> clipped_axes;
  std::vector<double> clipped_axis_rail_rad_s;
  // Sensor-clock spans [begin, end] of motion segments the sensor did not record faithfully
  // (kSensorMissedMotion): no gyro integration can bridge them.
  std::vector<std::pair<double, double>> missed_motion_spans_s;
};

// Checks a raw-IMU record (has_raw_imu) against its robot poses. InputError when the record
// has no raw IMU columns or too little motion to time.
ToolImuAnalysis check_tool_imu_record(const ToolImuRecord& record,
                                      const ToolImuCheckOptions& options = {});

// Rotation R minimising sum |R a_k - b_k|^2 (Kabsch, det +1).
Eigen::Matrix3d fit_rotation(const std::vector<Eigen::Vector3d>& a,
                             const std::vector<Eigen::Vector3d>& b);

}  // namespace imscal::calib
