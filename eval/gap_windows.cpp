#include "eval/gap_windows.hpp"

#include <algorithm>
#include <cmath>

namespace imscal::eval {

std::vector<bool> analysed_samples(const std::vector<double>& time_s, const AnalysisWindows& w) {
  std::vector<bool> keep(time_s.size(), true);
  if (time_s.empty() || w.max_s <= 0.0) return keep;
  const double t0 = time_s.front(), span = time_s.back() - t0;
  if (span <= w.max_s) return keep;
  const double window = std::min(w.window_s, w.max_s);
  const std::size_t count = std::max<std::size_t>(2, std::size_t(std::ceil(w.max_s / window)));
  const double length = w.max_s / double(count);  // count windows of `length`, max_s in all
  const double step = (span - length) / double(count - 1);
  for (std::size_t k = 0; k < time_s.size(); ++k) {
    const double t = time_s[k] - t0;
    // The window that starts at or before t (the last one for t past the last start).
    const std::size_t i = std::min(count - 1, std::size_t(std::floor(t / step)));
    keep[k] = t - double(i) * step < length;
  }
  return keep;
}

std::vector<std::vector<double>> keep_samples(const std::vector<std::vector<double>>& series,
                                              const std::vector<bool>& keep) {
  std::vector<std::vector<double>> out(series.size());
  for (std::size_t j = 0; j < series.size(); ++j) {
    if (series[j].empty()) continue;
    for (std::size_t k = 0; k < keep.size(); ++k)
      if (keep[k]) out[j].push_back(series[j][k]);
  }
  return out;
}

ident::JointErrorLog keep_samples(const ident::JointErrorLog& log, const std::vector<bool>& keep) {
  ident::JointErrorLog out = log;
  const auto kept = [&](const std::vector<double>& v) {
    std::vector<double> r;
    for (std::size_t k = 0; k < keep.size(); ++k)
      if (keep[k]) r.push_back(v[k]);
    return r;
  };
  out.time_s = kept(log.time_s);
  out.payload_kg = kept(log.payload_kg);
  out.q_desired_rad = keep_samples(log.q_desired_rad, keep);
  out.q_measured_rad = keep_samples(log.q_measured_rad, keep);
  out.q_internal_rad = keep_samples(log.q_internal_rad, keep);
  out.model_torque_nm = keep_samples(log.model_torque_nm, keep);
  out.segment_starts.clear();
  std::size_t segment = 0, written = 0;
  bool previous_kept = false;
  for (std::size_t k = 0; k < keep.size(); ++k) {
    const bool starts_segment =
        segment < log.segment_starts.size() && log.segment_starts[segment] == k;
    if (starts_segment) ++segment;
    if (keep[k] && (starts_segment || !previous_kept)) out.segment_starts.push_back(written);
    if (keep[k]) ++written;
    previous_kept = keep[k];
  }
  if (out.segment_starts.empty()) out.segment_starts.push_back(0);
  out.first_data_line = 0;  // rows no longer follow the file's lines
  return out;
}

}  // namespace imscal::eval
