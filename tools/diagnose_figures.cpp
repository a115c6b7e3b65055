#include "tools/diagnose_figures.hpp"

#include <fmt/format.h>

#include <algorithm>

namespace imscal::tools {

namespace {

constexpr const char* kColors[] = {"#1f5fbf", "#d0402b", "#2a9d3a",
                                   "#8e44ad", "#e08a00", "#17a2b8"};

}  // namespace

// Welch spectrum of every joint's gap, log-log [rad²/Hz].
std::string spectrum_figure(GnuplotRenderer& gnuplot, const eval::GapSignals& s) {
  std::string plot;
  for (std::size_t j = 0; j < s.joint_count(); ++j) {
    std::size_t longest = 0;
    for (const auto& [b, e] : s.runs) longest = std::max(longest, e - b);
    std::size_t window = 512;
    while (window > 16 && window > longest) window /= 2;
    const eval::Spectrum sp = eval::welch_spectrum(s.gap_rad[j], s.runs, s.cycle_s, window);
    std::string data;
    for (std::size_t i = 1; i < sp.frequency_hz.size(); ++i)  // without DC (log axis)
      data += fmt::format("{:.6g} {:.6g}\n", sp.frequency_hz[i], std::max(sp.density[i], 1e-30));
    const std::string file = gnuplot.data_file(fmt::format("psd-{}.dat", j), data);
    plot += fmt::format("{}{} using 1:2 with lines lw 1.3 lc rgb '{}' title '{}' noenhanced",
                        j == 0 ? "plot " : ", ", file, kColors[j % 6], s.joint_names[j]);
  }
  const std::string script =
      "set grid\nset logscale xy\nset format y '%.0e'\nset xlabel 'f [Hz]'\n"
      "set ylabel 'PSD of the gap [rad²/Hz]'\nset key outside right\n" +
      plot + "\n";
  return gnuplot.render("gap-spectrum", "Spectrum of the sim-to-real gap per joint", script, 900,
                        450);
}

// Share of the gap energy by joint, split by motion phase (stacked bars).
std::string where_figure(GnuplotRenderer& gnuplot, const eval::Diagnosis& d) {
  std::string data = "joint";
  for (int p = 0; p < eval::kMotionPhaseCount; ++p)
    data += std::string(" ") + eval::to_string(eval::MotionPhase(p));
  data += "\n";
  for (const auto& j : d.where.joints) {
    data += j.joint;
    for (const auto& ph : j.by_phase)
      data += fmt::format(" {:.6g}", 100.0 * j.energy_share * ph.energy_share);
    data += "\n";
  }
  const std::string file = gnuplot.data_file("where.dat", data);
  std::string plot = "plot ";
  for (int p = 0; p < eval::kMotionPhaseCount; ++p)
    plot += fmt::format("{}{} using {}:xtic(1) title columnheader({}) lc rgb '{}'",
                        p == 0 ? "" : ", ", file, p + 2, p + 2, kColors[p]);
  const std::string script =
      "set style data histograms\nset style histogram rowstacked\nset style fill solid 0.8 "
      "border -1\nset boxwidth 0.7\nset grid y\nset ylabel 'share of the gap energy [%]'\n"
      "set key outside right noenhanced\nset yrange [0:*]\n" +
      plot + "\n";
  return gnuplot.render("gap-where", "Where the gap lies: by joint and motion phase", script, 900,
                        450);
}

// |G| of the model-error model per joint with its confidence band.
std::string model_error_figure(GnuplotRenderer& gnuplot, const eval::GapSignals& s,
                               const eval::Diagnosis& d) {
  std::string script =
      "set multiplot layout 2,3 title 'Model-error model: gap from q_d, |G| with its 2-sigma band' "
      "noenhanced\nset grid\nset logscale x\nset xlabel 'f [Hz]'\nset ylabel '|G| [rad/rad]'\n"
      "set style fill transparent solid 0.3 noborder\nunset key\n";
  for (std::size_t j = 0; j < d.model_error.size(); ++j) {
    std::string data;
    for (const auto& p : d.model_error[j].response)
      data += fmt::format("{:.6g} {:.6g} {:.6g} {:.6g}\n", p.frequency_hz, p.magnitude, p.lower,
                          p.upper);
    if (data.empty()) continue;
    const std::string file = gnuplot.data_file(fmt::format("mem-{}.dat", j), data);
    script += fmt::format(
        "set title '{} (held-out explained {:.0f} %)' noenhanced\n"
        "plot {} using 1:3:4 with filledcurves lc rgb '{}', {} using 1:2 with linespoints pt 7 "
        "ps 0.4 lw 1.3 lc rgb '{}'\n",
        s.joint_names[j], d.model_error[j].heldout_explained_percent, file, kColors[j % 6], file,
        kColors[j % 6]);
  }
  script += "unset multiplot\n";
  return gnuplot.render("gap-model-error", "Model-error model frequency response", script, 1100,
                        650);
}

}  // namespace imscal::tools
