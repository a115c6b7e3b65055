#pragma once
// A report page in a real browser: headless Chromium (Debian's `chromium`) loads it; the DOM
// after load, console and load errors, and, through a probe script appended to a copy of the
// page, the laid-out size and drawn paths of every figure (<svg> in a <section>).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "core/subprocess.hpp"
#include "tests/support/run_imscal.hpp"
#include "tests/support/text_file.hpp"

namespace imscal::test_support {

// The Chromium binary, or "" (the caller then skips loudly: never a silent pass).
inline std::string find_chromium() {
  for (const char* candidate : {"/usr/bin/chromium", "/usr/bin/chromium-browser"})
    if (std::filesystem::exists(candidate)) return candidate;
  return "";
}

inline void warn_chromium_missing() {
  std::cerr << "\n*** chromium IS NOT INSTALLED: the report was NOT checked in a browser. ***\n"
               "*** Install it: apt-get install -y --no-install-recommends chromium    ***\n\n";
}

struct BrowserLoad {
  SubprocessResult run;
  std::string dom;     // <html>...</html> after load
  std::string errors;  // console messages and failed loads, one per line
};

// Loads `page` headless with a fresh profile in `profile_dir`.
inline BrowserLoad load_in_chromium(const std::string& chromium, const std::filesystem::path& page,
                                    const std::filesystem::path& profile_dir) {
  const std::vector<std::string> argv = {chromium,
                                         "--headless",
                                         "--disable-gpu",
                                         "--no-sandbox",
                                         "--disable-dev-shm-usage",
                                         "--no-first-run",
                                         "--user-data-dir=" + profile_dir.string(),
                                         "--enable-logging=stderr",
                                         "--v=0",
                                         "--virtual-time-budget=10000",
                                         "--dump-dom",
                                         "file://" + page.string()};
  SubprocessOptions options;
  options.timeout_s = 120.0;  // a cold Chromium start under load can take many seconds
  BrowserLoad load;
  load.run = run_subprocess(argv, options);
  // stdout and stderr are merged: the DOM is the <html>...</html> part; console messages are
  // logged as CONSOLE lines, failed loads as "Failed to load" / net::ERR.
  const std::string& out = load.run.output;
  const auto begin = out.find("<html");
  const auto end = out.rfind("</html>");
  if (begin != std::string::npos && end != std::string::npos)
    load.dom = out.substr(begin, end + 7 - begin);
  std::istringstream lines(out);
  for (std::string line; std::getline(lines, line);)
    if (line.find("CONSOLE") != std::string::npos || line.find("Uncaught") != std::string::npos ||
        line.find("Failed to load") != std::string::npos ||
        line.find("net::ERR_") != std::string::npos)
      load.errors += line + "\n";
  return load;
}

// Loads `report` and a probed copy of it (written next to it as probe.html); checks that the page
// loads without errors, that every <svg> of the file survives HTML parsing, and returns per
// figure {w, h, paths, length}: rendered size [px], drawn <path> elements of non-zero length and
// their total length [px]. Failures are reported through gtest; an empty array then.
inline nlohmann::json figures_in_chromium(const std::string& chromium,
                                          const std::filesystem::path& report,
                                          const std::filesystem::path& profile_dir) {
  const std::string html = read_text(report);
  const std::size_t svg_count = count_of(html, "<svg");

  const BrowserLoad plain = load_in_chromium(chromium, report, profile_dir);
  EXPECT_EQ(plain.run.exit_code, 0) << plain.run.output;
  EXPECT_TRUE(plain.errors.empty()) << plain.errors;
  EXPECT_FALSE(plain.dom.empty()) << plain.run.output;
  EXPECT_EQ(count_of(plain.dom, "<svg"), svg_count) << "every figure survives HTML parsing";

  // The probe: after layout it writes, per <svg>, its rendered size, the number of drawn paths
  // and their total length into the DOM.
  std::string probed = html;
  probed.insert(probed.rfind("</body>"),
                "<script>const r=[...document.querySelectorAll('body > section svg')].map(s=>{"
                "const b=s.getBoundingClientRect();let n=0,len=0;"
                "for(const p of s.querySelectorAll('path')){const l=p.getTotalLength();"
                "if(l>0){n++;len+=l;}}return {w:b.width,h:b.height,paths:n,length:len};});"
                "const e=document.createElement('pre');e.id='probe';"
                "e.textContent=JSON.stringify(r);document.body.appendChild(e);</script>");
  const std::filesystem::path probe = report.parent_path() / "probe.html";
  std::ofstream(probe) << probed;
  const BrowserLoad probed_load = load_in_chromium(chromium, probe, profile_dir);
  EXPECT_EQ(probed_load.run.exit_code, 0) << probed_load.run.output;
  EXPECT_TRUE(probed_load.errors.empty()) << probed_load.errors;
  // The probe's JSON between <pre id="probe"> and </pre> (found by hand: std::regex trips GCC
  // 12's -Wmaybe-uninitialized in the sanitizer build).
  const std::string open_tag = "<pre id=\"probe\">";
  const auto begin = probed_load.dom.find(open_tag);
  const auto end = probed_load.dom.find("</pre>", begin == std::string::npos ? 0 : begin);
  if (begin == std::string::npos || end == std::string::npos) {
    ADD_FAILURE() << "no probe output in the DOM: " << probed_load.dom.substr(0, 2000);
    return nlohmann::json::array();
  }
  auto figures = nlohmann::json::parse(
      probed_load.dom.substr(begin + open_tag.size(), end - begin - open_tag.size()));
  EXPECT_EQ(figures.size(), svg_count);
  return figures;
}

// Every figure as figures_in_chromium measured it is laid out and plotted.
inline void expect_every_figure_drawn(const nlohmann::json& figures) {
  for (const auto& svg : figures) {
    // Laid out at the page width (about 1000 px) with the gnuplot aspect ratio.
    EXPECT_GT(svg["w"].get<double>(), 300.0) << svg;
    EXPECT_GT(svg["h"].get<double>(), 200.0) << svg;
    // Axes, grid, curves: a plotted figure has dozens of paths of visible total length.
    EXPECT_GT(svg["paths"].get<int>(), 20) << svg;
    EXPECT_GT(svg["length"].get<double>(), 5000.0) << svg;
  }
}

}  // namespace imscal::test_support
