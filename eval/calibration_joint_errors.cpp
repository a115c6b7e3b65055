#include "eval/calibration_joint_errors.hpp"

#include <span>

#include "eval/gap_measurement_prior.hpp"
#include "ident/joint_error_io.hpp"

namespace imscal::eval {

namespace {

std::span<const double> values(const calib::JointVector& q) {
  return {q.data(), std::size_t(q.size())};
}

// The header of a calibration's joint_errors.csv, with the IMS noise floor in joint space.
ident::JointErrorLog calibration_header(const calib::JointSpaceErrors& errors,
                                        const calib::RobotLog& log, const std::string& source) {
  ident::JointErrorLog header;
  header.robot = errors.robot.empty() ? log.robot_name : errors.robot;
  header.cycle_s = errors.cycle_s;
  header.source = source;
  header.joint_names.assign(log.joint_names.begin(), log.joint_names.end());
  if (!errors.q_measured_sigma_rad.empty() || errors.sums.rows > 0) {
    const calib::JointVector floor_rad = calib::q_measured_sigma_rms_rad(errors);
    header.metadata.emplace_back(kNoiseFloorKey, noise_floor_header_value(values(floor_rad)));
  }
  return header;
}

}  // namespace

void write_calibration_joint_errors_csv(const std::filesystem::path& file,
                                        const calib::JointSpaceErrors& errors,
                                        const calib::RobotLog& log, const std::string& source,
                                        Overwrite overwrite) {
  ident::JointErrorsCsvWriter out(file, calibration_header(errors, log, source), true, overwrite);
  for (std::size_t k = 0; k < errors.t_s.size(); ++k)
    out.add(errors.t_s[k], errors.payload_kg[k], values(errors.q_desired_rad[k]),
            values(errors.q_measured_rad[k]), values(errors.q_internal_rad[k]));
  out.commit();
}

CalibrationJointErrorsCsv::CalibrationJointErrorsCsv(const std::filesystem::path& file,
                                                     const calib::RobotLog& log,
                                                     Overwrite overwrite)
    : out_(file, log.joint_names.size(), true, overwrite) {}

void CalibrationJointErrorsCsv::add(const calib::JointErrorRow& row) {
  out_.add(row.t_s, row.payload_kg, values(row.q_desired_rad), values(row.q_measured_rad),
           values(row.q_internal_rad));
}

void CalibrationJointErrorsCsv::commit(const calib::JointSpaceErrors& errors,
                                       const calib::RobotLog& log, const std::string& source) {
  out_.commit(calibration_header(errors, log, source));
}

}  // namespace imscal::eval
