// The analysed windows of a long record (eval/gap_windows.hpp), against their closed form: a
// record longer than max_s keeps windows of max_s / count spread evenly, first and last included,
// each its own segment; a shorter one is kept whole.
#include <gtest/gtest.h>

#include <algorithm>

#include "eval/gap_windows.hpp"

namespace {
using imscal::eval::analysed_samples;
using imscal::eval::AnalysisWindows;
using imscal::eval::keep_samples;

constexpr double kCycleS = 0.002;

imscal::ident::JointErrorLog log_of(double duration_s, std::size_t gap_at = 0) {
  imscal::ident::JointErrorLog log;
  log.joint_names = {"A1", "A2"};
  const auto n = std::size_t(duration_s / kCycleS) + 1;
  log.q_desired_rad.resize(2);
  log.q_measured_rad.resize(2);
  log.q_internal_rad.resize(2);
  for (std::size_t k = 0; k < n; ++k) {
    log.time_s.push_back(double(k) * kCycleS + (gap_at > 0 && k >= gap_at ? 1.0 : 0.0));
    log.payload_kg.push_back(5.0);
    for (std::size_t j = 0; j < 2; ++j) {
      log.q_desired_rad[j].push_back(double(k));
      log.q_measured_rad[j].push_back(double(k) + 0.5);
      log.q_internal_rad[j].push_back(-double(k));
    }
  }
  if (gap_at > 0) log.segment_starts = {0, gap_at};
  return log;
}

TEST(GapWindows, AShortRecordIsKeptWhole) {
  const auto log = log_of(70.0);
  const auto keep = analysed_samples(log.time_s, AnalysisWindows{});
  EXPECT_TRUE(std::all_of(keep.begin(), keep.end(), [](bool b) { return b; }));
  AnalysisWindows whole;
  whole.max_s = 0.0;  // 0: the whole record, however long
  const auto long_keep = analysed_samples(log_of(600.0).time_s, whole);
  EXPECT_TRUE(std::all_of(long_keep.begin(), long_keep.end(), [](bool b) { return b; }));
}

TEST(GapWindows, ALongRecordKeepsThreeSpreadWindowsOfThirtySeconds) {
  const auto log = log_of(600.0);
  const auto keep = analysed_samples(log.time_s, AnalysisWindows{});  // 90 s in 30 s windows
  const auto kept = keep_samples(log, keep);
  // 3 x 30 s of 2 ms samples: 15000 each (each window [start, start + 30 s)); one sample more
  // or less per window where a start falls on a sample within rounding.
  EXPECT_NEAR(double(kept.sample_count()), 3.0 * 15000.0, 3.0);
  ASSERT_EQ(kept.segment_starts.size(), 3u);
  // Starts every (600 - 30) / 2 = 285 s: 0, 285, 570 s, to a sample.
  for (std::size_t i = 0; i < 3; ++i)
    EXPECT_NEAR(kept.time_s[kept.segment_starts[i]], 285.0 * double(i), 1.01 * kCycleS);
  EXPECT_NEAR(kept.time_s.back(), 600.0 - kCycleS, 1e-9);
  // The series follow their samples: q_desired is the original index.
  const std::size_t second = kept.segment_starts[1];
  const double index = kept.q_desired_rad[1][second];
  EXPECT_NEAR(kept.time_s[second], index * kCycleS, 1e-9);
  EXPECT_EQ(kept.q_measured_rad[0][second], index + 0.5);
  EXPECT_EQ(kept.q_internal_rad[1][second], -index);
  EXPECT_EQ(kept.payload_kg.size(), kept.sample_count());
  const auto series = keep_samples(log.q_desired_rad, keep);
  EXPECT_EQ(series[0], kept.q_desired_rad[0]);
}

TEST(GapWindows, ASegmentBoundaryInsideAWindowStaysOne) {
  // A 1 s gap at 300 s (sample 150000): inside the second window (285.5 .. 315.5 s).
  const auto log = log_of(600.0, 150000);
  const auto kept = keep_samples(log, analysed_samples(log.time_s, AnalysisWindows{}));
  EXPECT_EQ(kept.segment_starts.size(), 4u);
  const auto segments = kept.segments();
  ASSERT_EQ(segments.size(), 4u);
  EXPECT_NEAR(kept.time_s[segments[2].first], 301.0, 1e-9);  // the sample after the gap
}

}  // namespace
