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
#include "eval/gap_windows.hpp"

namespace imscal::eval {

struct GapSessionOptions {
  std::string joint_errors;      // real
  std::string table;             // sim: parameters.json; or
  std::string sim_joint_errors;  // sim: joint_errors.csv
  std::string robot;             // robot description
  // A record longer than this [s] is analysed on windows spread over it (eval/gap_windows.hpp);
  // 0: the whole record.
  double max_analysed_s = AnalysisWindows{}.max_s;
  // calibrate's frames.json of the record (optional): the covariance of the chain's frames in the
  // measurement budget (eval/gap_measurement_prior.hpp), beside the noise floor the real
  // joint_errors.csv carries.
  std::string frames;
  // The scenario (name or file) whose nominal model made sim_joint_errors (`imscal
  // model-joint-errors --scenario`), optional: the joint model is then refined by re-simulating
  // that nominal model (eval/gap_refinement.hpp). Only its nominal robot is read, never its plant.
  std::string scenario;
};

struct GapSession {
  GapSignals signals;
  Diagnosis diagnosis;
};

GapSession diagnose_gap_session(const GapSessionOptions& options);

}  // namespace imscal::eval
