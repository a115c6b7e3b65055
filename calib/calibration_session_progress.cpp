// The share of `imscal calibrate` done (calib/calibration_session_progress.hpp).
#include "calib/calibration_session_progress.hpp"

#include <algorithm>
#include <utility>

namespace imscal::calib {

double calibrate_command_share(const std::string& stage, double fraction) {
  struct Span {
    const char* stage;
    double begin, end;
  };
  static constexpr Span kSpans[] = {{"rests", 0.1, 0.15},
                                    {"time offset", 0.15, 0.2},
                                    {"bundle", 0.2, 0.7},
                                    {"joint errors", 0.7, 0.95},
                                    {"write", 0.95, 1.0}};
  for (const Span& s : kSpans)
    if (stage == s.stage) return s.begin + fraction * (s.end - s.begin);
  return 0.1;
}

SessionProgress command_share_progress(ProgressCallback report) {
  return [report = std::move(report), reported = 0.0](const std::string& stage,
                                                      double fraction) mutable {
    reported = std::max(reported, calibrate_command_share(stage, fraction));
    report(stage, reported);
  };
}

}  // namespace imscal::calib
