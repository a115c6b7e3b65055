#pragma once
// The report's figures (gnuplot SVG, tools/report_gnuplot.hpp) from the stages' results.
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "ident/joint_error_io.hpp"
#include "ident/parameter_table.hpp"
#include "tools/report_gnuplot.hpp"

namespace imscal::tools {

// Reduces the curve (x increasing) to at most about max_points points: per bin of equal sample
// count the smallest and the largest y in x order, so that peaks stay visible.
std::vector<std::pair<double, double>> reduce_min_max(std::span<const double> x,
                                                      std::span<const double> y, int max_points);

// Paper Fig. 2: per joint, Δq = q_desired - q_measured (IMS) and q_desired - q_internal (the
// robot's motor encoders) over time, in mdeg.
std::string joint_errors_figure(GnuplotRenderer& gnuplot, const ident::JointErrorLog& log,
                                int max_points_per_curve);

// Frequency response of every identified cell model of one joint: |G| [dB] and phase [deg] of
// q_d -> q̂, and |E| [dB] of q_d -> Δq̂, from 0.1 Hz to the Nyquist frequency.
std::string frequency_response_figure(GnuplotRenderer& gnuplot, const ident::JointParameters& joint,
                                      double sample_time_s);

}  // namespace imscal::tools
