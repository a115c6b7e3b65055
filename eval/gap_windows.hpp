#pragma once
// The part of a long record the gap diagnosis analyses. Its candidate fits hold regressor columns
// over every analysed sample (eval/gap_candidates.hpp; 19-31 kB per sample at the 2 ms cycle), so
// its memory grows with the record. A record longer than `max_s` is analysed on windows of
// `window_s` spread evenly over it, first and last included, `max_s` in all: the effects the
// diagnosis looks for are stationary over a session (their parameters are constants) except the
// thermal drift, whose time span the spread windows keep. 90 s of 2 ms samples are 45 000 rows,
// more than the shipped 70 s campaign's 34 650 that the diagnosis' headline figures come from; a
// window's 30 s hold the longest time scale of a candidate's filters (0.3 s) a hundredfold. Each
// window is its own run (the filters restart at its start, as at a gap in the record).
#include <cstddef>
#include <vector>

#include "ident/joint_error_io.hpp"

namespace imscal::eval {

struct AnalysisWindows {
  double max_s = 90.0;     // analysed in all; 0: the whole record
  double window_s = 30.0;  // each window's length
};

// Per sample of the record (time stamps [s]): whether it lies in an analysed window.
std::vector<bool> analysed_samples(const std::vector<double>& time_s, const AnalysisWindows& w);

// The log's samples flagged `keep`, a new segment wherever a kept sample does not follow a kept
// one of the same segment.
ident::JointErrorLog keep_samples(const ident::JointErrorLog& log, const std::vector<bool>& keep);
// [joint][sample] series: the samples flagged `keep`.
std::vector<std::vector<double>> keep_samples(const std::vector<std::vector<double>>& series,
                                              const std::vector<bool>& keep);

}  // namespace imscal::eval
