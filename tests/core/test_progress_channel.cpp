// The progress channel's line: written and read back, other lines refused, fractions clamped.
#include "core/progress_channel.hpp"

#include <gtest/gtest.h>

namespace {

TEST(ProgressChannel, LineRoundTripsStageAndFraction) {
  const auto report = imscal::parse_progress_line(imscal::progress_line("seed-line", 0.25));
  ASSERT_TRUE(report);
  EXPECT_EQ(report->stage, "seed-line");
  EXPECT_EQ(report->fraction, 0.25);  // 0.25 is exact in the line's 4 decimals
  // Stage names with spaces survive: the stage is the rest of the line.
  EXPECT_EQ(imscal::parse_progress_line(imscal::progress_line("joint A1 done", 1.0))->stage,
            "joint A1 done");
}

TEST(ProgressChannel, FractionsAreClampedToTheUnitInterval) {
  EXPECT_EQ(imscal::parse_progress_line(imscal::progress_line("s", 1.5))->fraction, 1.0);
  EXPECT_EQ(imscal::parse_progress_line(imscal::progress_line("s", -0.5))->fraction, 0.0);
  EXPECT_EQ(imscal::parse_progress_line("imscal-progress 7 s")->fraction, 1.0);
}

TEST(ProgressChannel, OtherLinesAreNotProgress) {
  for (const char* line : {"", "[info] joint A2 (2/6) done", "imscal-progress",
                           "imscal-progress x s", "imscal-progress 0.5", " imscal-progress 0.5 s"})
    EXPECT_FALSE(imscal::parse_progress_line(line)) << line;
}

}  // namespace
