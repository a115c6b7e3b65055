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

#include "core/subprocess.hpp"
#include "tests/support/scratch_dir.hpp"
#include "tests/tools/run_campaign.hpp"

namespace {
namespace fs = std::filesystem;
using imscal::test_support::read_file_text;

std::string find_chromium() {
  for (const char* candidate : {"/usr/bin/chromium", "/usr/bin/chromium-browser"})
    if (fs::exists(candidate)) return candidate;
  return "";
}

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = 0; (at = text.find(what, at)) != std::string::npos; at += what.size()) ++n;
  return n;
}

class ReportBrowser : public imscal::test_support::ScratchDirTest {
 protected:
  // Loads `page` headless; returns the DOM after load, console and load errors in `errors`.
  imscal::SubprocessResult load(const std::string& chromium, const fs::path& page, std::string& dom,
                                std::string& errors) {
    const std::vector<std::string> argv = {chromium,
                                           "--headless",
                                           "--disable-gpu",
                                           "--no-sandbox",
                                           "--disable-dev-shm-usage",
                                           "--no-first-run",
                                           "--user-data-dir=" + (dir_ / "profile").string(),
                                           "--enable-logging=stderr",
                                           "--v=0",
                                           "--virtual-time-budget=10000",
                                           "--dump-dom",
                                           "file://" + page.string()};
    imscal::SubprocessOptions options;
    options.timeout_s = 120.0;  // a cold Chromium start under load can take many seconds
    const auto result = imscal::run_subprocess(argv, options);
    // stdout and stderr are merged: the DOM is the <html>...</html> part; console messages are
    // logged as CONSOLE lines, failed loads as "Failed to load" / net::ERR.
    const auto begin = result.output.find("<html");
    const auto end = result.output.rfind("</html>");
    if (begin != std::string::npos && end != std::string::npos)
      dom = result.output.substr(begin, end + 7 - begin);
    std::istringstream lines(result.output);
    for (std::string line; std::getline(lines, line);)
      if (line.find("CONSOLE") != std::string::npos || line.find("Uncaught") != std::string::npos ||
          line.find("Failed to load") != std::string::npos ||
          line.find("net::ERR_") != std::string::npos)
        errors += line + "\n";
    return result;
  }
};

TEST_F(ReportBrowser, LoadsWithoutErrorsAndEveryFigureIsDrawn) {
  const std::string chromium = find_chromium();
  if (chromium.empty()) {
    std::cerr << "\n*** chromium IS NOT INSTALLED: the report was NOT checked in a browser. ***\n"
                 "*** Install it: apt-get install -y --no-install-recommends chromium    ***\n\n";
    GTEST_SKIP() << "chromium not installed (scripts/install-deps.sh installs it)";
  }
  const fs::path config = imscal::test_support::write_campaign(dir_);
  ASSERT_EQ(imscal::test_support::run_imscal(
                "run " + config.string() + " --out " + (dir_ / "out").string(), dir_ / "log.txt"),
            0)
      << read_file_text(dir_ / "log.txt");
  const fs::path report = dir_ / "out" / "report" / "report.html";
  const std::string html = read_file_text(report);
  // Self-contained: no script, no external resource.
  EXPECT_EQ(html.find("<script"), std::string::npos);
  EXPECT_EQ(html.find("src="), std::string::npos);
  // Figures: the joint errors (1) and one frequency response per joint (2).
  const std::size_t figures = count(html, "<svg");
  EXPECT_EQ(figures, 3u);
  // Stages that are not in the chain say so and draw nothing.
  EXPECT_EQ(count(html, "Not run:"), 3u);  // mounting, paths/ISO 9283, gap diagnosis

  std::string dom, errors;
  const auto plain = load(chromium, report, dom, errors);
  ASSERT_EQ(plain.exit_code, 0) << plain.output;
  EXPECT_TRUE(errors.empty()) << errors;
  ASSERT_FALSE(dom.empty()) << plain.output;
  EXPECT_NE(dom.find("<h1>Test campaign</h1>"), std::string::npos);
  EXPECT_EQ(count(dom, "<svg"), figures);  // every figure survived HTML parsing

  // The same page with a probe appended: after layout it writes, per <svg>, its rendered size,
  // the number of drawn paths and their total length into the DOM.
  const fs::path probe = dir_ / "out" / "report" / "probe.html";
  std::string probed = html;
  probed.insert(probed.rfind("</body>"),
                "<script>const r=[...document.querySelectorAll('body > section svg')].map(s=>{"
                "const b=s.getBoundingClientRect();let n=0,len=0;"
                "for(const p of s.querySelectorAll('path')){const l=p.getTotalLength();"
                "if(l>0){n++;len+=l;}}return {w:b.width,h:b.height,paths:n,length:len};});"
                "const e=document.createElement('pre');e.id='probe';"
                "e.textContent=JSON.stringify(r);document.body.appendChild(e);</script>");
  std::ofstream(probe) << probed;
  std::string probe_dom, probe_errors;
  const auto probed_run = load(chromium, probe, probe_dom, probe_errors);
  ASSERT_EQ(probed_run.exit_code, 0) << probed_run.output;
  EXPECT_TRUE(probe_errors.empty()) << probe_errors;
  // The probe's JSON between <pre id="probe"> and </pre> (found by hand: std::regex trips GCC
  // 12's -Wmaybe-uninitialized in the sanitizer build).
  const std::string open_tag = "<pre id=\"probe\">";
  const auto begin = probe_dom.find(open_tag);
  ASSERT_NE(begin, std::string::npos) << probe_dom.substr(0, 2000);
  const auto end = probe_dom.find("</pre>", begin);
  ASSERT_NE(end, std::string::npos) << probe_dom.substr(0, 2000);
  const auto result = nlohmann::json::parse(
      probe_dom.substr(begin + open_tag.size(), end - begin - open_tag.size()));
  ASSERT_EQ(result.size(), figures);
  for (const auto& svg : result) {
    // Laid out at the page width (about 1000 px) with the gnuplot aspect ratio.
    EXPECT_GT(svg["w"].get<double>(), 300.0) << svg;
    EXPECT_GT(svg["h"].get<double>(), 200.0) << svg;
    // Axes, grid, curves: a plotted figure has dozens of paths of visible total length.
    EXPECT_GT(svg["paths"].get<int>(), 20) << svg;
    EXPECT_GT(svg["length"].get<double>(), 5000.0) << svg;
  }
}

}  // namespace
