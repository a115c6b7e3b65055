#include "eval/gap_analysis.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <complex>

#include "ident/operating_point.hpp"

namespace imscal::eval {
namespace {

// In-place radix-2 FFT (size a power of two).
void fft(std::vector<std::complex<double>>& a) {
  const std::size_t n = a.size();
  for (std::size_t i = 1, j = 0; i < n; ++i) {
    std::size_t bit = n >> 1;
    for (; j & bit; bit >>= 1) j ^= bit;
    j ^= bit;
    if (i < j) std::swap(a[i], a[j]);
  }
  for (std::size_t len = 2; len <= n; len <<= 1) {
    const double ang = -2.0 * M_PI / double(len);
    const std::complex<double> wl(std::cos(ang), std::sin(ang));
    for (std::size_t i = 0; i < n; i += len) {
      std::complex<double> w(1.0, 0.0);
      for (std::size_t k = 0; k < len / 2; ++k) {
        const auto u = a[i + k], v = a[i + k + len / 2] * w;
        a[i + k] = u + v;
        a[i + k + len / 2] = u - v;
        w *= wl;
      }
    }
  }
}

// Energy shares of the groups given per sample (group index, -1 = none).
std::vector<GapShare> shares(const std::vector<double>& g, const std::vector<int>& group,
                             const std::vector<std::string>& labels) {
  std::vector<GapShare> out(labels.size());
  std::vector<std::size_t> count(labels.size(), 0);
  double total = 0.0;
  for (std::size_t k = 0; k < g.size(); ++k) {
    total += g[k] * g[k];
    if (group[k] < 0) continue;
    out[std::size_t(group[k])].energy_share += g[k] * g[k];
    ++count[std::size_t(group[k])];
  }
  for (std::size_t i = 0; i < labels.size(); ++i) {
    out[i].label = labels[i];
    const double e = out[i].energy_share;
    out[i].rms_rad = count[i] ? std::sqrt(e / double(count[i])) : 0.0;
    out[i].energy_share = total > 0.0 ? e / total : 0.0;
    out[i].time_share = g.empty() ? 0.0 : double(count[i]) / double(g.size());
  }
  return out;
}

}  // namespace

const char* to_string(MotionPhase phase) {
  switch (phase) {
    case MotionPhase::kRest:
      return "rest";
    case MotionPhase::kAcceleration:
      return "acceleration";
    case MotionPhase::kConstantVelocity:
      return "constant_velocity";
    case MotionPhase::kDeceleration:
      return "deceleration";
    case MotionPhase::kReversal:
      return "reversal";
  }
  return "?";
}

std::vector<MotionPhase> motion_phases(const GapSignals& s, std::size_t joint) {
  const auto& v = s.qd_desired_rad_s[joint];
  const auto& a = s.qdd_desired_rad_s2[joint];
  const std::size_t n = v.size();
  double v_peak = 0.0, a_peak = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    v_peak = std::max(v_peak, std::abs(v[k]));
    a_peak = std::max(a_peak, std::abs(a[k]));
  }
  const double v_rest = std::max(0.005 * v_peak, 1e-6), a_flat = 0.02 * a_peak;
  std::vector<MotionPhase> phase(n, MotionPhase::kRest);
  for (std::size_t k = 0; k < n; ++k) {
    if (std::abs(v[k]) < v_rest && std::abs(a[k]) <= a_flat) continue;
    if (std::abs(a[k]) <= a_flat)
      phase[k] = MotionPhase::kConstantVelocity;
    else
      phase[k] = v[k] * a[k] > 0.0 ? MotionPhase::kAcceleration : MotionPhase::kDeceleration;
  }
  // Reversals: the velocity changes sign between two moving samples less than 0.2 s apart
  // (a stop longer than that is a rest between two moves); mark 0.1 s either side.
  const long half = long(std::lround(0.1 / s.cycle_s));
  long last_moving = -1;
  for (std::size_t k = 0; k < n; ++k) {
    if (std::abs(v[k]) < v_rest) continue;
    if (last_moving >= 0 && v[std::size_t(last_moving)] * v[k] < 0.0 &&
        double(long(k) - last_moving) * s.cycle_s < 0.2) {
      const long mid = (last_moving + long(k)) / 2;
      for (long i = std::max(0L, mid - half); i <= std::min(long(n) - 1, mid + half); ++i)
        phase[std::size_t(i)] = MotionPhase::kReversal;
    }
    last_moving = long(k);
  }
  return phase;
}

Spectrum welch_spectrum(const std::vector<double>& x,
                        const std::vector<std::pair<std::size_t, std::size_t>>& runs,
                        double cycle_s, std::size_t window) {
  Spectrum sp;
  const std::size_t bins = window / 2 + 1;
  sp.frequency_hz.resize(bins);
  sp.density.assign(bins, 0.0);
  for (std::size_t i = 0; i < bins; ++i)
    sp.frequency_hz[i] = double(i) / (double(window) * cycle_s);
  std::vector<double> hann(window);
  double u = 0.0;
  for (std::size_t i = 0; i < window; ++i) {
    hann[i] = 0.5 - 0.5 * std::cos(2.0 * M_PI * double(i) / double(window));
    u += hann[i] * hann[i];
  }
  int segments = 0;
  std::vector<std::complex<double>> buf(window);
  for (const auto& [b, e] : runs)
    for (std::size_t start = b; start + window <= e; start += window / 2) {
      for (std::size_t i = 0; i < window; ++i) buf[i] = x[start + i] * hann[i];
      fft(buf);
      for (std::size_t i = 0; i < bins; ++i) {
        const double one_sided = (i == 0 || i == window / 2) ? 1.0 : 2.0;
        sp.density[i] += one_sided * std::norm(buf[i]) * cycle_s / u;
      }
      ++segments;
    }
  if (segments > 0)
    for (double& d : sp.density) d /= segments;
  return sp;
}

GapAnalysis analyse_gap(const GapSignals& s) {
  GapAnalysis out;
  const double nyquist = 0.5 / s.cycle_s;
  out.band_edges_hz = {0.0, 0.5, 2.0, 8.0, 32.0};
  if (nyquist > 32.0) out.band_edges_hz.push_back(nyquist);
  double total = 0.0;
  std::vector<double> energy(s.joint_count(), 0.0);
  for (std::size_t j = 0; j < s.joint_count(); ++j) {
    for (double g : s.gap_rad[j]) energy[j] += g * g;
    total += energy[j];
  }
  const double n = double(std::max<std::size_t>(s.sample_count(), 1));
  out.rms_rad = std::sqrt(total / n);
  for (std::size_t j = 0; j < s.joint_count(); ++j) {
    JointGapAnalysis ja;
    const auto& g = s.gap_rad[j];
    ja.joint = s.joint_names[j];
    ja.rms_rad = std::sqrt(energy[j] / n);
    ja.energy_share = total > 0.0 ? energy[j] / total : 0.0;

    const auto phase = motion_phases(s, j);
    std::vector<int> group(phase.size());
    std::vector<std::string> labels;
    for (int p = 0; p < kMotionPhaseCount; ++p) labels.push_back(to_string(MotionPhase(p)));
    for (std::size_t k = 0; k < phase.size(); ++k) group[k] = int(phase[k]);
    ja.by_phase = shares(g, group, labels);

    // Direction of motion (rest as in the phases).
    double sum_plus = 0.0, sum_minus = 0.0;
    std::size_t n_plus = 0, n_minus = 0;
    for (std::size_t k = 0; k < phase.size(); ++k) {
      const double v = s.qd_desired_rad_s[j][k];
      group[k] = phase[k] == MotionPhase::kRest ? 2 : (v > 0.0 ? 0 : 1);
      if (group[k] == 0) sum_plus += g[k], ++n_plus;
      if (group[k] == 1) sum_minus += g[k], ++n_minus;
    }
    ja.by_direction = shares(g, group, {"moving +", "moving -", "rest"});
    if (n_plus && n_minus)
      ja.direction_offset_rad = 0.5 * (sum_plus / double(n_plus) - sum_minus / double(n_minus));

    // Frequency bands from the Welch spectrum (window 512 samples = 1 s at 2 ms; shorter runs
    // take the largest power of two that fits).
    std::size_t longest = 0;
    for (const auto& [b, e] : s.runs) longest = std::max(longest, e - b);
    std::size_t window = 512;
    while (window > 16 && window > longest) window /= 2;
    const Spectrum sp = welch_spectrum(g, s.runs, s.cycle_s, window);
    double sp_total = 0.0;
    std::vector<double> band(out.band_edges_hz.size() - 1, 0.0);
    for (std::size_t i = 0; i < sp.frequency_hz.size(); ++i) {
      sp_total += sp.density[i];
      for (std::size_t b = 0; b + 1 < out.band_edges_hz.size(); ++b)
        if (sp.frequency_hz[i] >= out.band_edges_hz[b] &&
            (sp.frequency_hz[i] < out.band_edges_hz[b + 1] || b + 2 == out.band_edges_hz.size()))
          band[b] += sp.density[i];
    }
    for (std::size_t b = 0; b < band.size(); ++b) {
      GapShare sh;
      sh.label = fmt::format("{:g}-{:g} Hz", out.band_edges_hz[b], out.band_edges_hz[b + 1]);
      sh.energy_share = sp_total > 0.0 ? band[b] / sp_total : 0.0;
      sh.time_share = 1.0;
      sh.rms_rad = std::sqrt(std::max(sh.energy_share, 0.0) * energy[j] / n);
      ja.by_band.push_back(sh);
    }

    // Operating-point cells: the table's grid (cells not identified = outside the identified
    // range), else the paper's speed bands 0 / 20 / 80 / 100 % of the joint's top speed (beyond
    // the top speed: outside).
    std::vector<ident::CellDimension> dims;
    std::vector<bool> identified;
    if (j < s.table_dimensions.size()) {
      dims = s.table_dimensions[j];
      identified = s.table_cell_identified[j];
    } else {
      const double vmax = s.max_speed_rad_s[j];
      dims.push_back({ident::OperatingQuantity::kSpeed, {0.0, 0.2 * vmax, 0.8 * vmax, vmax}});
      identified.assign(3, true);
    }
    const ident::CellGrid grid(dims);
    const ident::OperatingSignals ops =
        ident::operating_signals(s.q_desired_rad[j], s.runs, s.cycle_s);
    const std::vector<int> cell = ident::assign_cells(grid, s.q_desired_rad[j], s.payload_kg, ops);
    labels.clear();
    for (int c = 0; c < grid.cell_count(); ++c) labels.push_back(grid.label(c));
    ja.by_cell = shares(g, cell, labels);
    for (int c = 0; c < grid.cell_count(); ++c)
      ja.by_cell[std::size_t(c)].outside_identified_range = !identified[std::size_t(c)];
    out.joints.push_back(std::move(ja));
  }
  return out;
}

}  // namespace imscal::eval
