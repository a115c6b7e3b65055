#include "eval/gap_diagnosis.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <random>

namespace imscal::eval {
namespace {

const char* what_to_measure(EffectKind kind) {
  switch (kind) {
    case EffectKind::kBacklash:
      return "slow reversals of the joint and static poses approached from both sides (play does "
             "not depend on speed)";
    case EffectKind::kCoulombFriction:
      return "reversals of the joint at several speeds (friction transients follow the "
             "controller, not the play)";
    case EffectKind::kGearCompliance:
      return "the same path at two accelerations and with two payloads (deflection scales with "
             "the torque)";
    case EffectKind::kTransmissionError:
      return "a slow constant-speed move of the joint over several motor revolutions (the error "
             "is periodic in the motor angle)";
    case EffectKind::kResonance:
      return "fast stops of the joint recorded by the IMS at its full rate (ring-down frequency "
             "and damping)";
    case EffectKind::kTimeOffset:
      return "sharp starts and stops with both streams stamped by one clock";
    case EffectKind::kPayloadMismatch:
      return "the path with and without a known extra mass";
    case EffectKind::kZeroOffset:
      return "static poses of the joint (a constant error does not depend on the motion)";
    case EffectKind::kThermalDrift:
      return "a repeat of the path after a warm-up and the drive temperatures";
    case EffectKind::kOperatingPoint:
      return "identification runs at the speeds and joint positions of this path";
    case EffectKind::kKinematicParameters:
      return "static poses spread over the workspace with an external reference (laser tracker), "
             "or a kinematic calibration (the error depends on the pose, not on the motion)";
    case EffectKind::kSensorMounting:
      return "the frame calibration's rest poses again with larger wrist rotations (the mounting "
             "error grows with the rotation away from the first pose)";
    case EffectKind::kImsScaleFactor:
      return "turn tests of the IMS about each axis by a known angle (rotary table or joint 6) "
             "and a known linear displacement";
    case EffectKind::kImsBias:
      return "a longer rest of the IMS before and after the path, and rests during it (the "
             "rests bound the attitude drift)";
  }
  return "";
}

struct Rows {
  std::vector<std::size_t> heldout;
};

double heldout_energy(const std::vector<std::vector<double>>& residual, const Rows& rows) {
  double e = 0.0;
  for (const auto& r : residual)
    for (std::size_t k : rows.heldout) e += r[k] * r[k];
  return e;
}

// Residual of every joint after a joint LS fit of the given columns (training rows); joints
// without columns keep their gap.
std::vector<std::vector<double>> residual_after(const std::vector<Eigen::MatrixXd>& columns,
                                                const std::vector<std::vector<double>>& gap,
                                                const std::vector<bool>& training) {
  const LinearFit f = fit_joint_columns(columns, gap, training);
  const auto pred = predict_joint_columns(columns, f.parameters);
  std::vector<std::vector<double>> r = gap;
  for (std::size_t j = 0; j < r.size(); ++j)
    for (std::size_t k = 0; k < pred[j].size(); ++k) r[j][k] -= pred[j][k];
  return r;
}

}  // namespace

std::string candidate_label(const GapSignals& s, const CandidateFit& fit) {
  return fmt::format("{} {}", s.joint_names[fit.joint], to_string(fit.kind));
}

std::vector<bool> training_rows(const GapSignals& s, double block_s) {
  std::vector<bool> train(s.sample_count(), false);
  for (const auto& [b, e] : s.runs)
    for (std::size_t k = b; k < e; ++k) {
      const long block = long(std::floor((s.time_s[k] - s.time_s[b]) / block_s));
      train[k] = block % 2 == 0;
    }
  return train;
}

double block_bootstrap_p_value(const std::vector<double>& d, std::size_t block, int resamples,
                               std::uint64_t seed) {
  const std::size_t m = d.size();
  if (m == 0) return 1.0;
  block = std::clamp<std::size_t>(block, 1, m);
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<std::size_t> start(0, m - block);
  const std::size_t blocks = (m + block - 1) / block;
  int not_positive = 0;
  for (int r = 0; r < resamples; ++r) {
    double sum = 0.0;
    for (std::size_t b = 0; b < blocks; ++b) {
      const std::size_t s0 = start(rng);
      for (std::size_t i = 0; i < block; ++i) sum += d[s0 + i];
    }
    if (sum <= 0.0) ++not_positive;
  }
  return (1.0 + not_positive) / (1.0 + resamples);
}

Diagnosis diagnose_gap(const GapSignals& s, const DiagnosisOptions& o) {
  Diagnosis out;
  out.where = analyse_gap(s);
  const std::vector<bool> training = training_rows(s, o.block_s);
  Rows rows;
  for (std::size_t k = 0; k < training.size(); ++k)
    if (!training[k]) rows.heldout.push_back(k);
  const std::size_t block =
      std::max<std::size_t>(1, std::size_t(std::lround(o.bootstrap_block_s / s.cycle_s)));
  for (std::size_t j = 0; j < s.joint_count(); ++j)
    out.model_error.push_back(fit_model_error_model(s.q_desired_rad[j], s.gap_rad[j], s.runs,
                                                    s.cycle_s, training, o.model_error));
  const double e0 = heldout_energy(s.gap_rad, rows);
  const double m = double(std::max<std::size_t>(rows.heldout.size(), 1));
  out.heldout_rms_rad = std::sqrt(e0 / m);
  out.heldout_rms_modelled_rad = out.heldout_rms_rad;
  auto shrink = [&](double energy_after) {
    return e0 > 0.0 ? 100.0 * (1.0 - std::sqrt(std::max(energy_after, 0.0) / e0)) : 0.0;
  };

  // Every candidate on every joint.
  std::uint64_t seed = o.seed;
  for (int kind = 0; kind < kEffectKindCount; ++kind)
    for (std::size_t j = 0; j < s.joint_count(); ++j) {
      auto fit = fit_candidate(effect_kind_from_index(kind), s, j, training);
      if (!fit) continue;
      CandidateResult r;
      // Per held-out row the reduction of the squared gap summed over the joints it acts on.
      std::vector<double> d(rows.heldout.size(), 0.0);
      double gain = 0.0, ej0 = 0.0, joint_gain = 0.0;
      for (std::size_t jj = 0; jj < s.joint_count(); ++jj) {
        const auto& p = fit->prediction[jj];
        if (p.empty()) continue;
        const auto& g = s.gap_rad[jj];
        for (std::size_t i = 0; i < rows.heldout.size(); ++i) {
          const std::size_t k = rows.heldout[i];
          const double res = g[k] - p[k];
          const double di = g[k] * g[k] - res * res;
          d[i] += di;
          gain += di;
          if (jj == fit->joint) joint_gain += di;
        }
      }
      for (std::size_t k : rows.heldout) ej0 += s.gap_rad[fit->joint][k] * s.gap_rad[fit->joint][k];
      r.shrinkage_percent = shrink(e0 - gain);
      r.joint_shrinkage_percent =
          ej0 > 0.0 ? 100.0 * (1.0 - std::sqrt(std::max(ej0 - joint_gain, 0.0) / ej0)) : 0.0;
      r.p_value = block_bootstrap_p_value(d, block, o.bootstrap_resamples, seed++);
      r.supported = r.p_value < o.alpha && r.shrinkage_percent >= o.min_shrinkage_percent;
      r.fit = std::move(*fit);
      out.candidates.push_back(std::move(r));
    }
  // Ranked by held-out shrinkage less a parsimony charge of 0.5 percentage points per parameter:
  // of two candidates that explain the same (a drift that nests an offset), the simpler first.
  const auto score = [](const CandidateResult& c) {
    return c.shrinkage_percent - 0.5 * double(c.fit.parameters.size());
  };
  std::stable_sort(
      out.candidates.begin(), out.candidates.end(),
      [&](const CandidateResult& a, const CandidateResult& b) { return score(a) > score(b); });
  out.significant_gap = !out.candidates.empty() && out.candidates.front().supported;

  // Greedy combination of the supported candidates: each step adds the candidate whose columns,
  // fitted jointly with those already chosen (one stacked LS over the joints they act on), shrink
  // the held-out gap most. Only the best `combination_pool` supported candidates are tried.
  if (out.significant_gap) {
    std::vector<std::vector<double>> residual = s.gap_rad;
    std::vector<Eigen::MatrixXd> chosen_columns(s.joint_count());
    std::vector<std::size_t> pool;
    for (std::size_t c = 0; c < out.candidates.size() && int(pool.size()) < o.combination_pool; ++c)
      if (out.candidates[c].supported) pool.push_back(c);
    std::vector<bool> used(out.candidates.size(), false);
    double energy = e0;
    for (int step = 0; step < o.max_combination; ++step) {
      int best = -1;
      double best_energy = energy;
      std::vector<std::vector<double>> best_residual;
      std::vector<Eigen::MatrixXd> best_columns;
      for (std::size_t c : pool) {
        if (used[c]) continue;
        const CandidateFit& f = out.candidates[c].fit;
        std::vector<Eigen::MatrixXd> cols =
            join_columns(chosen_columns, f.columns, s.sample_count());
        std::vector<std::vector<double>> r = residual_after(cols, s.gap_rad, training);
        const double e = heldout_energy(r, rows);
        if (e < best_energy) {
          best_energy = e;
          best = int(c);
          best_residual = std::move(r);
          best_columns = std::move(cols);
        }
      }
      if (best < 0) break;
      const CandidateFit& f = out.candidates[std::size_t(best)].fit;
      std::vector<double> d(rows.heldout.size(), 0.0);
      for (std::size_t j = 0; j < s.joint_count(); ++j)
        for (std::size_t i = 0; i < rows.heldout.size(); ++i) {
          const std::size_t k = rows.heldout[i];
          d[i] += residual[j][k] * residual[j][k] - best_residual[j][k] * best_residual[j][k];
        }
      const double p = block_bootstrap_p_value(d, block, o.bootstrap_resamples, seed++);
      const double gain_pp = shrink(best_energy) - shrink(energy);
      if (step > 0 && (p >= o.alpha || gain_pp < o.min_combination_gain_percent)) break;
      used[std::size_t(best)] = true;
      chosen_columns = std::move(best_columns);
      residual = std::move(best_residual);
      energy = best_energy;
      out.combination.push_back({candidate_label(s, f), shrink(energy), p});
    }
    out.heldout_rms_modelled_rad = std::sqrt(std::max(energy, 0.0) / m);
  }

  // The verdict in plain words.
  const double arcsec = 180.0 / M_PI * 3600.0;
  std::size_t top_joint = 0;
  for (std::size_t j = 0; j < out.where.joints.size(); ++j)
    if (out.where.joints[j].energy_share > out.where.joints[top_joint].energy_share) top_joint = j;
  std::string where;
  if (!out.where.joints.empty()) {
    const auto& ja = out.where.joints[top_joint];
    auto top_of = [](const std::vector<GapShare>& v) {
      return *std::max_element(v.begin(), v.end(), [](const GapShare& a, const GapShare& b) {
        return a.energy_share < b.energy_share;
      });
    };
    const GapShare ph = top_of(ja.by_phase), band = top_of(ja.by_band);
    where = fmt::format(
        "The gap (RMS {:.3g} rad = {:.1f} arcsec over all joints) lies mostly in joint {} ({:.0f} "
        "% "
        "of its energy), there mostly during {} ({:.0f} % of the joint's gap energy in {:.0f} % of "
        "the time) and in the {} band ({:.0f} %).",
        out.where.rms_rad, out.where.rms_rad * arcsec, ja.joint, 100.0 * ja.energy_share, ph.label,
        100.0 * ph.energy_share, 100.0 * ph.time_share, band.label, 100.0 * band.energy_share);
    // Cells outside the identified range, on every joint that runs in them.
    std::vector<std::string> outside;
    for (const auto& jo : out.where.joints) {
      double time = 0.0, energy = 0.0;
      for (const auto& c : jo.by_cell)
        if (c.outside_identified_range) time += c.time_share, energy += c.energy_share;
      if (time > 0.0)
        outside.push_back(fmt::format("{} {:.0f} % of the time ({:.0f} % of its gap energy)",
                                      jo.joint, 100.0 * time, 100.0 * energy));
    }
    if (!outside.empty())
      where += fmt::format(
          " The path runs at operating points outside the identified range (cells of the error "
          "model not identified from data): {}.",
          fmt::join(outside, ", "));
  }
  if (!out.significant_gap) {
    out.verdict = fmt::format(
        "{} No significant structured gap: no candidate effect shrinks the held-out gap by at "
        "least {:.0f} % with p < {:g}; what remains looks like measurement noise or an effect "
        "outside the library.",
        where, o.min_shrinkage_percent, o.alpha);
    if (!out.candidates.empty())
      out.measure_next.push_back(
          fmt::format("if a gap of {:.3g} rad matters: longer records of the path, and {}",
                      out.heldout_rms_rad, what_to_measure(out.candidates.front().fit.kind)));
    return out;
  }
  const CandidateResult& top = out.candidates.front();
  out.verdict = fmt::format(
      "{} Most likely cause: {} on joint {} ({}; {}), which shrinks the held-out gap by {:.0f} % "
      "(p = {:.3f}). Modelled with {}, the held-out gap is expected to fall from {:.3g} rad to "
      "{:.3g} rad ({:.0f} % smaller).",
      where, to_string(top.fit.kind), s.joint_names[top.fit.joint], top.fit.shape,
      top.fit.size_text, top.shrinkage_percent, top.p_value,
      out.combination.empty() ? std::string("it")
                              : fmt::format("{}", fmt::join(
                                                      [&] {
                                                        std::vector<std::string> l;
                                                        for (const auto& c : out.combination)
                                                          l.push_back(c.label);
                                                        return l;
                                                      }(),
                                                      " + ")),
      out.heldout_rms_rad, out.heldout_rms_modelled_rad,
      100.0 * (1.0 - out.heldout_rms_modelled_rad / std::max(out.heldout_rms_rad, 1e-300)));
  std::vector<std::string> unsupported;
  for (const auto& c : out.candidates)
    if (!c.supported && c.fit.joint == top.fit.joint) unsupported.push_back(to_string(c.fit.kind));
  if (!unsupported.empty())
    out.verdict += fmt::format(" Not supported on joint {}: {}.", s.joint_names[top.fit.joint],
                               fmt::join(unsupported, ", "));
  // Weak evidence: a different effect explains nearly as much, or the best explains little.
  for (std::size_t c = 1; c < out.candidates.size(); ++c) {
    const auto& r = out.candidates[c];
    if (!r.supported) break;
    if (r.fit.kind == top.fit.kind && r.fit.joint == top.fit.joint) continue;
    if (top.shrinkage_percent - r.shrinkage_percent < 5.0) {
      out.measure_next.push_back(
          fmt::format("{} explains nearly as much ({:.0f} % vs {:.0f} %); to tell them apart "
                      "measure {}, and {}",
                      candidate_label(s, r.fit), r.shrinkage_percent, top.shrinkage_percent,
                      what_to_measure(top.fit.kind), what_to_measure(r.fit.kind)));
    }
  }
  if (top.shrinkage_percent < 30.0)
    out.measure_next.push_back(
        fmt::format("the best candidate explains only {:.0f} % of the gap: measure {}",
                    top.shrinkage_percent, what_to_measure(top.fit.kind)));
  return out;
}

}  // namespace imscal::eval
