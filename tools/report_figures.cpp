#include "tools/report_figures.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/units.hpp"
#include "ident/arx_frequency_response.hpp"

namespace imscal::tools {

namespace ident = imscal::ident;

std::vector<std::pair<double, double>> reduce_min_max(std::span<const double> x,
                                                      std::span<const double> y, int max_points) {
  std::vector<std::pair<double, double>> out;
  const std::size_t n = std::min(x.size(), y.size());
  if (n <= static_cast<std::size_t>(std::max(2, max_points))) {
    for (std::size_t i = 0; i < n; ++i) out.emplace_back(x[i], y[i]);
    return out;
  }
  const std::size_t bins = static_cast<std::size_t>(std::max(1, max_points / 2));
  for (std::size_t b = 0; b < bins; ++b) {
    const std::size_t begin = b * n / bins, end = (b + 1) * n / bins;
    if (begin >= end) continue;
    std::size_t lo = begin, hi = begin;
    for (std::size_t i = begin; i < end; ++i) {
      if (y[i] < y[lo]) lo = i;
      if (y[i] > y[hi]) hi = i;
    }
    const std::size_t first = std::min(lo, hi), second = std::max(lo, hi);
    out.emplace_back(x[first], y[first]);
    if (second != first) out.emplace_back(x[second], y[second]);
  }
  return out;
}

namespace {
constexpr double kMdegPerRad = kDegPerRad * 1000.0;

// Data block of one curve, segments separated by a blank line (gnuplot does not join them).
std::string curve_data(const ident::JointErrorLog& log, const std::vector<double>& value,
                       int max_points_total) {
  std::string text;
  const auto segments = log.segments();
  for (const auto& [begin, end] : segments) {
    const int share =
        std::max<int>(10, static_cast<int>(double(max_points_total) * double(end - begin) /
                                           double(std::max<std::size_t>(1, log.sample_count()))));
    const auto points = reduce_min_max(std::span(log.time_s).subspan(begin, end - begin),
                                       std::span(value).subspan(begin, end - begin), share);
    for (const auto& [t, v] : points) text += fmt::format("{:.6f} {:.6g}\n", t, v);
    text += "\n";
  }
  return text;
}
}  // namespace

std::string joint_errors_figure(GnuplotRenderer& gnuplot, const ident::JointErrorLog& log,
                                int max_points_per_curve) {
  const std::size_t joints = log.joint_count();
  const std::size_t rows = (joints + 1) / 2;
  std::string script = fmt::format(
      "set encoding utf8\n"
      "set multiplot layout {},{} title 'Joint angle errors Δq = q_d - q' "
      "font 'sans,13'\n"
      "set grid\nset key top right font 'sans,9'\nset xlabel 't [s]'\n"
      "set ylabel 'Δq [mdeg]'\n",
      rows, joints > 1 ? 2 : 1);
  for (std::size_t j = 0; j < joints; ++j) {
    std::vector<double> ims(log.sample_count()), internal(log.sample_count());
    for (std::size_t k = 0; k < log.sample_count(); ++k) {
      ims[k] = (log.q_desired_rad[j][k] - log.q_measured_rad[j][k]) * kMdegPerRad;
      if (log.has_q_internal())
        internal[k] = (log.q_desired_rad[j][k] - log.q_internal_rad[j][k]) * kMdegPerRad;
    }
    const std::string ims_file = gnuplot.data_file(fmt::format("dq-ims-{}.dat", j),
                                                   curve_data(log, ims, max_points_per_curve));
    script += fmt::format(
        "set title '{}' noenhanced\n"
        "plot {} using 1:2 with lines lw 1.2 lc rgb '#1f5fbf' title 'IMS: q_d - q_{{measured}}'",
        log.joint_names[j], ims_file);
    // Without the encoders' block (one position sensor per joint) the IMS curve alone.
    if (log.has_q_internal())
      script += fmt::format(
          ", {} using 1:2 with lines lw 1.2 lc rgb '#d0402b' title 'internal sensors: q_d - "
          "q_{{internal}}'",
          gnuplot.data_file(fmt::format("dq-internal-{}.dat", j),
                            curve_data(log, internal, max_points_per_curve)));
    script += "\n";
  }
  script += "unset multiplot\n";
  const int height = static_cast<int>(280 * rows + 60);
  return gnuplot.render("fig-joint-errors", "Joint angle errors (paper Fig. 2 style)", script, 1000,
                        height);
}

std::string frequency_response_figure(GnuplotRenderer& gnuplot, const ident::JointParameters& joint,
                                      double sample_time_s) {
  const double nyquist_hz = 0.5 / sample_time_s;
  const auto frequencies = ident::log_spaced_frequencies_hz(0.1, nyquist_hz, 300);
  const ident::CellGrid grid = joint.grid();
  std::string gain_plot, phase_plot, error_plot;
  const char* colors[] = {"#1f5fbf", "#d0402b", "#2a9d3a", "#8e44ad", "#e08a00",
                          "#17a2b8", "#7f7f7f", "#b5651d", "#000000"};
  int curve = 0;
  for (std::size_t c = 0; c < joint.cells.size(); ++c) {
    const ident::CellParameters& cell = joint.cells[c];
    if (cell.status != ident::CellStatus::kIdentified) continue;  // filled cells are copies
    const auto response = ident::frequency_response(cell.model(sample_time_s), frequencies);
    std::string data;
    double previous_phase = 0.0, phase_offset = 0.0;
    for (std::size_t i = 0; i < frequencies.size(); ++i) {
      double phase = std::arg(response.joint[i]);
      // Unwrap: the phase of a delay keeps falling past -180 deg.
      if (i > 0) {
        while (phase + phase_offset - previous_phase > std::numbers::pi)
          phase_offset -= 2 * std::numbers::pi;
        while (phase + phase_offset - previous_phase < -std::numbers::pi)
          phase_offset += 2 * std::numbers::pi;
      }
      previous_phase = phase + phase_offset;
      data += fmt::format("{:.6g} {:.6g} {:.6g} {:.6g}\n", frequencies[i],
                          20.0 * std::log10(std::abs(response.joint[i])),
                          previous_phase * 180.0 / std::numbers::pi,
                          20.0 * std::log10(std::max(1e-12, std::abs(response.joint_error[i]))));
    }
    const std::string file = gnuplot.data_file(fmt::format("fr-{}-{}.dat", joint.name, c), data);
    const std::string label =
        fmt::format("cell {} {} (na {}, nb {}, d {})", c, grid.label(int(c)), cell.structure.na,
                    cell.structure.nb, cell.structure.dead_time);
    const std::string style = fmt::format("with lines lw 1.3 lc rgb '{}' title '{}' noenhanced",
                                          colors[curve % 9], label);
    const std::string separator = curve == 0 ? "plot " : ", ";
    gain_plot += separator + file + " using 1:2 " + style;
    phase_plot += separator + file + " using 1:3 " + style;
    error_plot += separator + file + " using 1:4 " + style;
    ++curve;
  }
  if (curve == 0) return "";
  const std::string script = fmt::format(
      "set encoding utf8\nset multiplot layout 3,1 title 'Joint {} : identified models' noenhanced "
      "font 'sans,13'\n"
      "set grid\nset logscale x\nset xrange [0.1:{}]\nset key outside right font 'sans,9'\n"
      "set xlabel 'f [Hz]'\n"
      "set title 'q_d to q: gain'\nset ylabel '|G| [dB]'\n{}\n"
      "set title 'q_d to q: phase'\nset ylabel 'arg G [deg]'\n{}\n"
      "set title 'q_d to joint error Δq: gain'\nset ylabel '|E| [dB]'\n{}\n"
      "unset multiplot\n",
      joint.name, nyquist_hz, gain_plot, phase_plot, error_plot);
  return gnuplot.render("fig-frequency-response-" + joint.name,
                        "Frequency response of joint " + joint.name, script, 1000, 900);
}

}  // namespace imscal::tools
