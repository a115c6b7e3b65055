// The report in a real browser: `imscal run` on the small campaign (tests/tools/run_campaign.hpp),
// then headless Chromium (Debian's `chromium`) loads report.html: no console or load errors,
// every figure is an inline <svg> that survives parsing, and, laid out by the browser, every
// figure has a visible size and drawn paths of non-zero length. The sections of stages that did
// not run say "Not run" and hold no figure.
//
// Needs chromium (scripts/install-deps.sh installs it; CI has it). Without it the test is
// SKIPPED with a loud message, never passed silently.
#include <gtest/gtest.h>

#include <iostream>
#include <nlohmann/json.hpp>

#include "tests/support/scratch_dir.hpp"
#include "tests/support/text_file.hpp"
#include "tests/tools/browser_check.hpp"
#include "tests/tools/run_campaign.hpp"

namespace {
namespace fs = std::filesystem;
using imscal::test_support::count_of;
using imscal::test_support::read_text;

using ReportBrowser = imscal::test_support::ScratchDirTest;

TEST_F(ReportBrowser, LoadsWithoutErrorsAndEveryFigureIsDrawn) {
  const std::string chromium = imscal::test_support::find_chromium();
  if (chromium.empty()) {
    imscal::test_support::warn_chromium_missing();
    GTEST_SKIP() << "chromium not installed (scripts/install-deps.sh installs it)";
  }
  const fs::path config = imscal::test_support::write_campaign(dir_);
  ASSERT_EQ(imscal::test_support::run_imscal(
                "run " + config.string() + " --out " + (dir_ / "out").string(), dir_ / "log.txt"),
            0)
      << read_text(dir_ / "log.txt");
  const fs::path report = dir_ / "out" / "report" / "report.html";
  const std::string html = read_text(report);
  // Self-contained: no script, no external resource.
  EXPECT_EQ(html.find("<script"), std::string::npos);
  EXPECT_EQ(html.find("src="), std::string::npos);
  // Figures: the joint errors (1) and one frequency response per joint (2).
  const std::size_t figures = count_of(html, "<svg");
  EXPECT_EQ(figures, 3u);
  // Stages that are not in the chain say so and draw nothing.
  EXPECT_EQ(count_of(html, "Not run:"), 3u);  // mounting, paths/ISO 9283, gap diagnosis

  EXPECT_NE(html.find("<h1>Test campaign</h1>"), std::string::npos);
  const auto drawn = imscal::test_support::figures_in_chromium(chromium, report, dir_ / "profile");
  ASSERT_EQ(drawn.size(), figures);
  imscal::test_support::expect_every_figure_drawn(drawn);
}

}  // namespace
