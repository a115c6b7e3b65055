#pragma once
// A gap diagnosis session as `imscal diagnose` runs it: "real" a joint_errors.csv (the joint
// errors measured through the IMS chain), "sim" the identified error model (parameters.json, run
// on the desired joints) or a second joint_errors.csv (e.g. the simulator with a given set of
// effects, same time stamps), checked against each other and the robot, then the gap's signals
// (eval/gap_signals.hpp) and its diagnosis (eval/gap_diagnosis.hpp); its report files are
// eval/gap_report.hpp's. InputError naming file, line and field on inputs that do not match.
#include <string>

#include "eval/gap_diagnosis.hpp"
#include "eval/gap_signals.hpp"

namespace imscal::eval {

struct GapSessionOptions {
  std::string joint_errors;      // real
  std::string table;             // sim: parameters.json; or
  std::string sim_joint_errors;  // sim: joint_errors.csv
  std::string robot;             // robot description
};

struct GapSession {
  GapSignals signals;
  Diagnosis diagnosis;
};

GapSession diagnose_gap_session(const GapSessionOptions& options);

}  // namespace imscal::eval
