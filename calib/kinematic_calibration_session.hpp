#pragma once
// A kinematic calibration session as `imscal calibrate-kinematics` runs it: an arm's DH
// deviations, the tracker <- base transform and the target on the flange fitted on laser-tracker
// positions (calib/kinematic_calibration.hpp; without a held-out file: the 1st, 3rd, 5th ... row
// fitted, the others held out) and judged on the held-out poses against the nominal model with
// its own best base and target fit on the same rows. Its report (JSON: both models' position
// errors in mm on the fitted and held-out poses, every parameter with 1 sigma or the reason it
// was not estimated; datasets/FORMAT.md) and a text summary. Poses that cannot give a
// calibration are an InputError naming the pose file.
#include <nlohmann/json.hpp>
#include <string>

namespace imscal::calib {

struct KinematicSessionOptions {
  std::string robot;     // robot file (YAML or URDF)
  std::string poses;     // tracker poses CSV to fit
  std::string held_out;  // tracker poses CSV to judge on; empty: alternate rows of `poses`
  double min_independence = 1e-2;
};

struct KinematicSession {
  nlohmann::json report;
  std::string text;
  bool calibrated_beats_nominal = false;  // on the held-out poses (RMS)
};

KinematicSession calibrate_kinematics_session(const KinematicSessionOptions& options);

}  // namespace imscal::calib
