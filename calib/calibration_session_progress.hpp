#pragma once
// The share of `imscal calibrate` done, from the steps of its session
// (calib/calibration_session.hpp, SessionProgress), for a parent that shows one figure per
// command (`imscal run`'s stages through core/progress_channel.hpp): reading the files up to 0.1,
// the rests 0.1-0.15, the initial clock offset 0.15-0.2, the bundle with the mounting validation
// after it 0.2-0.7 (about half of the work), the joint errors 0.7-0.95, writing the outputs
// (stage "write") 0.95-1. A step not listed (the validation's "halves" and "segments") counts as
// 0.1.
#include <string>

#include "calib/calibration_session.hpp"
#include "core/progress_channel.hpp"

namespace imscal::calib {

// The share of the whole command when `stage` is `fraction` (in [0, 1]) through.
double calibrate_command_share(const std::string& stage, double fraction);

// A callback for the session's steps (and "write") that hands `report` the command's share. The
// share reported never goes back: the session comes back to a step (the rests are refined after
// the clock offset). Keep one copy: each copy keeps its own highest share.
SessionProgress command_share_progress(ProgressCallback report);

}  // namespace imscal::calib
