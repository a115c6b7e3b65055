// The share of `imscal calibrate` reported from its session's steps
// (calib/calibration_session_progress.hpp) against the spans its header states.
#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

#include "calib/calibration_session_progress.hpp"

namespace {

using imscal::calib::calibrate_command_share;
using imscal::calib::command_share_progress;

TEST(CalibrationSessionProgress, StepsMapOntoTheirSpans) {
  // Exact in binary up to one rounding of begin + fraction * (end - begin): 1e-15.
  EXPECT_NEAR(calibrate_command_share("rests", 0.0), 0.1, 1e-15);
  EXPECT_NEAR(calibrate_command_share("time offset", 0.5), 0.175, 1e-15);
  EXPECT_NEAR(calibrate_command_share("bundle", 1.0), 0.7, 1e-15);
  EXPECT_NEAR(calibrate_command_share("joint errors", 0.5), 0.825, 1e-15);
  EXPECT_EQ(calibrate_command_share("write", 0.0), 0.95);
  EXPECT_EQ(calibrate_command_share("write", 1.0), 1.0);   // the last report is exactly done
  EXPECT_EQ(calibrate_command_share("halves", 0.7), 0.1);  // not listed: 0.1
}

TEST(CalibrationSessionProgress, ShareNeverGoesBack) {
  std::vector<std::pair<std::string, double>> reports;
  const auto share = command_share_progress([&reports](const std::string& stage, double fraction) {
    reports.emplace_back(stage, fraction);
  });
  // The session's order (calib/calibration_session.hpp): the rests come back after the offset.
  share("rests", 1.0);
  share("time offset", 1.0);
  share("rests", 0.5);
  share("bundle", 0.0);
  share("halves", 0.0);
  share("write", 1.0);
  ASSERT_EQ(reports.size(), 6u);
  EXPECT_EQ(reports[2].first, "rests");
  EXPECT_NEAR(reports[2].second, 0.2, 1e-15);  // held at the time offset's end, not 0.125
  EXPECT_NEAR(reports[4].second, 0.2, 1e-15);  // "halves" maps to 0.1: held
  for (std::size_t k = 1; k < reports.size(); ++k)
    EXPECT_GE(reports[k].second, reports[k - 1].second) << reports[k].first;
  EXPECT_EQ(reports.back().second, 1.0);
}

}  // namespace
