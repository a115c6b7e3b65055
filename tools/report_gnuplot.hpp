#pragma once
// Figures of the HTML report, drawn by gnuplot (`set terminal svg`) as a child process with a
// time limit. The data go to temporary files; the SVG comes back as an element to inline in
// HTML, its ids prefixed so that several figures can live in one page.
#include <filesystem>
#include <string>

namespace imscal::tools {

class GnuplotRenderer {
 public:
  // Creates a private temporary folder for data, scripts and output (removed by the destructor).
  explicit GnuplotRenderer(double timeout_s);
  GnuplotRenderer(const GnuplotRenderer&) = delete;
  GnuplotRenderer& operator=(const GnuplotRenderer&) = delete;
  ~GnuplotRenderer();

  // Writes `content` to a data file and returns its path as a quoted gnuplot string.
  std::string data_file(const std::string& name, const std::string& content);

  // Runs `script` after setting the SVG terminal (width x height px) and the output, and
  // returns the <svg> element (XML prolog removed, ids prefixed with `id_prefix`, title set).
  // Throws std::runtime_error naming the figure with gnuplot's message when gnuplot is missing,
  // fails, runs past the time limit or draws nothing.
  std::string render(const std::string& id_prefix, const std::string& title,
                     const std::string& script, int width_px, int height_px);

 private:
  std::filesystem::path folder_;
  double timeout_s_;
  int figure_count_ = 0;
};

// A file name as a quoted gnuplot string ('' inside), for a script that reads the file.
std::string gnuplot_quoted(const std::filesystem::path& path);

// Text for an HTML element or attribute: & < > " ' escaped.
std::string html_escape(const std::string& text);

}  // namespace imscal::tools
