#pragma once
// The SVG figures of `imscal diagnose --figures`, drawn by gnuplot (tools/report_gnuplot.hpp):
// the gap's spectrum per joint, where the gap lies (by joint and motion phase), and the
// model-error model's frequency response with its confidence band.
#include <string>

#include "eval/gap_diagnosis.hpp"
#include "eval/gap_signals.hpp"
#include "tools/report_gnuplot.hpp"

namespace imscal::tools {

// Welch spectrum of every joint's gap, log-log [rad²/Hz].
std::string spectrum_figure(GnuplotRenderer& gnuplot, const eval::GapSignals& s);
// Share of the gap energy by joint, split by motion phase (stacked bars).
std::string where_figure(GnuplotRenderer& gnuplot, const eval::Diagnosis& d);
// |G| of the model-error model per joint with its confidence band.
std::string model_error_figure(GnuplotRenderer& gnuplot, const eval::GapSignals& s,
                               const eval::Diagnosis& d);

}  // namespace imscal::tools
