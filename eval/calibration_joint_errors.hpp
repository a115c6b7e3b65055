#pragma once
// joint_errors.csv of a calibration (ident/joint_error_io.hpp, datasets/FORMAT.md section 10)
// from its joint-space errors (calib/joint_space_errors.hpp): the step from calib's rows to
// ident's file lives here because calib may not use ident. The rows are written one at a time
// (ident::JointErrorsCsvWriter), not copied into an ident::JointErrorLog. The header carries the
// IMS noise floor in joint space (kNoiseFloorKey, eval/gap_measurement_prior.hpp) for diagnose's
// measurement budget.
#include <filesystem>
#include <string>

#include "calib/joint_space_errors.hpp"
#include "core/atomic_file.hpp"
#include "ident/joint_error_io.hpp"
#include "robot/robot_log.hpp"

namespace imscal::eval {

// The robot's name from `errors` (from `log` when empty), its joint names from `log`; `source`
// is the header's source line. Throws std::invalid_argument for non-finite values.
void write_calibration_joint_errors_csv(const std::filesystem::path& file,
                                        const calib::JointSpaceErrors& errors,
                                        const calib::RobotLog& log, const std::string& source,
                                        Overwrite overwrite = Overwrite::kAllow);

// The same file written as the rows are computed (calib::SessionOptions::joint_error_rows), so
// that they are never held: the header, whose noise floor is over all rows, is written at commit
// (the rows wait in a file beside it; ident::JointErrorsCsvWriter). The same bytes.
class CalibrationJointErrorsCsv {
 public:
  // `log`'s joints make the columns. Throws std::runtime_error when the file cannot be made.
  CalibrationJointErrorsCsv(const std::filesystem::path& file, const calib::RobotLog& log,
                            Overwrite overwrite = Overwrite::kAllow);
  // Throws std::invalid_argument for non-finite values.
  void add(const calib::JointErrorRow& row);
  // `errors`: the joint-space step's result (its sums give the noise floor), as for
  // write_calibration_joint_errors_csv.
  void commit(const calib::JointSpaceErrors& errors, const calib::RobotLog& log,
              const std::string& source);

 private:
  ident::JointErrorsCsvWriter out_;
};

}  // namespace imscal::eval
