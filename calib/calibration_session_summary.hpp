#pragma once
// summary.txt of a calibration session (datasets/FORMAT.md §16): the verdict with its reasons,
// the rests used, the initial clock offset, the solver, the estimates with their 1-sigma, the
// weak directions, the mounting checks, the residuals per rest and motion, and the joint errors'
// figures, in plain text for a person.
#include <string>

#include "calib/calibration_session.hpp"

namespace imscal::calib {

// What the summary names as the session's sources.
struct SessionSummarySources {
  std::string imu;        // the IMS record
  std::string robot_log;  // the robot log
  std::string frames;     // an earlier session's frames.json (held); empty: none
};

std::string session_summary_text(const SessionSummarySources& sources,
                                 const SessionResult& session);

}  // namespace imscal::calib
