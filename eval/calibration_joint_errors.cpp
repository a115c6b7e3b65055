#include "eval/calibration_joint_errors.hpp"

#include <fmt/format.h>

#include <span>

#include "eval/gap_measurement_prior.hpp"
#include "ident/joint_error_io.hpp"

namespace imscal::eval {

void write_calibration_joint_errors_csv(const std::filesystem::path& file,
                                        const calib::JointSpaceErrors& errors,
                                        const calib::RobotLog& log, const std::string& source,
                                        Overwrite overwrite) {
  ident::JointErrorLog header;
  header.robot = errors.robot.empty() ? log.robot_name : errors.robot;
  header.cycle_s = errors.cycle_s;
  header.source = source;
  header.joint_names.assign(log.joint_names.begin(), log.joint_names.end());
  if (!errors.q_measured_sigma_rad.empty()) {
    const calib::JointVector floor_rad = calib::q_measured_sigma_rms_rad(errors);
    std::string value;
    for (int j = 0; j < calib::kJointCount; ++j)
      value += fmt::format("{}{:.6g}", j ? "," : "", floor_rad[j]);
    header.metadata.emplace_back(kNoiseFloorKey, value);
  }
  ident::JointErrorsCsvWriter out(file, header, true, overwrite);
  const auto values = [](const calib::JointVector& q) {
    return std::span<const double>(q.data(), std::size_t(q.size()));
  };
  for (std::size_t k = 0; k < errors.t_s.size(); ++k)
    out.add(errors.t_s[k], errors.payload_kg[k], values(errors.q_desired_rad[k]),
            values(errors.q_measured_rad[k]), values(errors.q_internal_rad[k]));
  out.commit();
}

}  // namespace imscal::eval
