#include "tools/report_gnuplot.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <stdlib.h>

#include <fstream>
#include <sstream>
#include <stdexcept>

#include "core/atomic_file.hpp"
#include "core/subprocess.hpp"

namespace imscal::tools {

namespace fs = std::filesystem;

std::string html_escape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string gnuplot_quoted(const fs::path& path) {
  std::string out = "'";
  for (char c : path.string()) out += c == '\'' ? std::string("''") : std::string(1, c);
  return out + "'";
}

namespace {
void replace_all(std::string& text, const std::string& from, const std::string& to) {
  for (std::size_t at = 0; (at = text.find(from, at)) != std::string::npos; at += to.size())
    text.replace(at, from.size(), to);
}
}  // namespace

GnuplotRenderer::GnuplotRenderer(double timeout_s) : timeout_s_(timeout_s) {
  std::string pattern = (fs::temp_directory_path() / "imscal-report-XXXXXX").string();
  if (::mkdtemp(pattern.data()) == nullptr)
    throw std::runtime_error("report: cannot create a temporary folder for the figure data");
  folder_ = pattern;
}

GnuplotRenderer::~GnuplotRenderer() {
  std::error_code ignored;
  fs::remove_all(folder_, ignored);
}

std::string GnuplotRenderer::data_file(const std::string& name, const std::string& content) {
  const fs::path path = folder_ / name;
  write_file_atomically(path, content);
  return gnuplot_quoted(path);
}

std::string GnuplotRenderer::render(const std::string& id_prefix, const std::string& title,
                                    const std::string& script, int width_px, int height_px) {
  const int number = ++figure_count_;
  const fs::path svg_path = folder_ / fmt::format("figure-{}.svg", number);
  const fs::path script_path = folder_ / fmt::format("figure-{}.gp", number);
  const std::string full_script = fmt::format(
      "set terminal svg size {},{} dynamic enhanced font 'sans,11' background '#ffffff'\n"
      "set output {}\n{}\nunset output\n",
      width_px, height_px, gnuplot_quoted(svg_path), script);
  write_file_atomically(script_path, full_script);
  SubprocessOptions options;
  options.timeout_s = timeout_s_;
  const SubprocessResult result = run_subprocess({"gnuplot", script_path.string()}, options);
  if (result.timed_out)
    throw std::runtime_error(fmt::format(
        "report: gnuplot did not finish figure '{}' within report.gnuplot_timeout_s = {} s", title,
        timeout_s_));
  if (result.exit_code == 127)
    throw std::runtime_error(
        fmt::format("report: cannot run gnuplot for figure '{}' ({}); install gnuplot-nox", title,
                    result.output));
  if (result.exit_code != 0)
    throw std::runtime_error(fmt::format("report: gnuplot failed on figure '{}' (exit {}): {}",
                                         title, result.exit_code, result.output));
  if (!result.output.empty())
    spdlog::warn("report: gnuplot on figure '{}' said: {}", title, result.output);
  std::ifstream in(svg_path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  std::string svg = text.str();
  const std::size_t start = svg.find("<svg");
  if (start == std::string::npos || svg.find("<path") == std::string::npos)
    throw std::runtime_error(fmt::format("report: gnuplot wrote no drawing for figure '{}' ({})",
                                         title, svg_path.string()));
  svg.erase(0, start);
  // Unique ids per figure: gnuplot names its point symbols and plots the same in every file.
  for (const char* quote : {"\"", "'"}) {
    replace_all(svg, std::string("id=") + quote, std::string("id=") + quote + id_prefix + "-");
    replace_all(svg, std::string("href=") + quote + "#",
                std::string("href=") + quote + "#" + id_prefix + "-");
  }
  replace_all(svg, "url(#", "url(#" + id_prefix + "-");
  replace_all(svg, "<title>Gnuplot</title>", "<title>" + html_escape(title) + "</title>");
  return svg;
}

}  // namespace imscal::tools
