#include "eval/gap_diagnosis.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <random>

#include "core/parallel_tasks.hpp"
#include "eval/gap_refinement.hpp"
#include "eval/gap_selection.hpp"
#include "eval/gap_verdict.hpp"

namespace imscal::eval {
namespace {

struct Rows {
  std::vector<std::size_t> heldout;
};

double heldout_energy(const std::vector<std::vector<double>>& residual, const Rows& rows) {
  double e = 0.0;
  for (const auto& r : residual)
    for (std::size_t k : rows.heldout) e += r[k] * r[k];
  return e;
}

// Ranking charge per parameter [percentage points of shrinkage]: of two candidates that explain
// the same (a drift that nests an offset), the simpler first.
constexpr double kParsimonyPercentPerParameter = 0.5;

// The ambiguity groups of the ranked candidates that explain something on the held-out rows
// (supported on all joints or on their own), on all joints.
void group_ambiguous(const GapSignals& s, const std::vector<std::size_t>& heldout, Diagnosis& d) {
  std::vector<const CandidateFit*> ranked;
  std::vector<bool> eligible;
  for (const auto& c : d.candidates) {
    ranked.push_back(&c.fit);
    eligible.push_back(c.supported || c.joint_supported);
  }
  d.ambiguity_groups = ambiguity_groups(s, ranked, eligible, heldout);
  for (std::size_t g = 0; g < d.ambiguity_groups.size(); ++g)
    for (std::size_t m : d.ambiguity_groups[g].members) d.candidates[m].ambiguity_group = int(g);
}

// Per joint: its candidates ranked by their own-joint held-out shrinkage less the parsimony charge
// on their own parameters, the leader and those ambiguous with it on that joint (among those that
// explain at least min_shrinkage_percent of it: no groups of noise fits).
void find_per_joint(const GapSignals& s, const DiagnosisOptions& o,
                    const std::vector<std::size_t>& heldout, Diagnosis& d) {
  for (std::size_t j = 0; j < s.joint_count(); ++j) {
    std::vector<std::size_t> on_joint;
    for (std::size_t c = 0; c < d.candidates.size(); ++c)
      if (d.candidates[c].fit.joint == j) on_joint.push_back(c);
    if (on_joint.empty()) continue;
    const auto score = [&](std::size_t c) {
      const CandidateResult& r = d.candidates[c];
      const double own = double(r.fit.parameters.size() - r.fit.coupling_parameter_count);
      return r.joint_shrinkage_percent - kParsimonyPercentPerParameter * own;
    };
    const auto one_flank = [&](std::size_t c) {
      return d.candidates[c].fit.shape == kOneFlankShape;
    };
    std::stable_sort(on_joint.begin(), on_joint.end(), [&](std::size_t a, std::size_t b) {
      if (score(a) != score(b)) return score(a) > score(b);
      return !one_flank(a) && one_flank(b);
    });
    JointFinding f;
    f.joint = j;
    f.leading = {on_joint.front()};
    f.supported = d.candidates[on_joint.front()].joint_supported;
    std::vector<const CandidateFit*> ranked;
    std::vector<bool> eligible;
    for (std::size_t c : on_joint) {
      ranked.push_back(&d.candidates[c].fit);
      eligible.push_back(d.candidates[c].joint_shrinkage_percent >= o.min_shrinkage_percent);
    }
    const auto groups = ambiguity_groups(s, ranked, eligible, heldout, j);
    if (!groups.empty() && groups.front().members.front() == 0) {
      f.leading.clear();
      for (std::size_t m : groups.front().members) f.leading.push_back(on_joint[m]);
      f.separate_by = groups.front().separate_by;
    }
    d.joint_findings.push_back(std::move(f));
  }
}

// Per held-out row the reduction of the squared gap of a candidate's own joint.
std::vector<double> own_joint_gains(const GapSignals& s, const CandidateFit& f,
                                    const std::vector<std::size_t>& heldout) {
  std::vector<double> d(heldout.size(), 0.0);
  const auto& p = f.prediction[f.joint];
  const auto& g = s.gap_rad[f.joint];
  if (p.empty()) return d;
  for (std::size_t i = 0; i < heldout.size(); ++i) {
    const std::size_t k = heldout[i];
    d[i] = g[k] * g[k] - (g[k] - p[k]) * (g[k] - p[k]);
  }
  return d;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const auto mid = v.begin() + std::ptrdiff_t(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  if (v.size() % 2 == 1) return *mid;
  return 0.5 * (*mid + *std::max_element(v.begin(), mid));
}

// How far a joint's gap stands above its noise reference (eval/gap_joint_significance.hpp).
void place_above_noise(const GapSignals& s, const DiagnosisOptions& o, std::size_t j,
                       JointSignificance& js, const Diagnosis& d) {
  std::vector<double> others;
  for (std::size_t i = 0; i < d.where.joints.size(); ++i)
    if (i != j) others.push_back(d.where.joints[i].rms_rad);
  js.rms_rad = d.where.joints[j].rms_rad;
  js.noise_floor_rad = high_frequency_noise_floor(s.gap_rad[j], s.runs);
  js.noise_reference_rad = std::max(js.noise_floor_rad, median(others));
  js.excess = js.noise_reference_rad > 0.0 ? js.rms_rad / js.noise_reference_rad
              : js.rms_rad > 0.0           ? std::numeric_limits<double>::infinity()
                                           : 0.0;
  js.far_above_noise = js.excess >= o.far_above_noise_factor;
}

// Each joint's own test (eval/gap_joint_significance.hpp): its leading candidate at the Šidák
// level over the joints, with enough resamples that the bootstrap's floor lies below it.
void test_joints(const GapSignals& s, const DiagnosisOptions& o,
                 const std::vector<std::size_t>& heldout, std::size_t block, std::uint64_t seed,
                 Diagnosis& d) {
  const double alpha_j = sidak_alpha(o.alpha, s.joint_count());
  const int resamples = std::max(o.bootstrap_resamples, int(std::ceil(4.0 / alpha_j)));
  for (std::size_t j = 0; j < s.joint_count(); ++j) {
    JointSignificance js;
    js.joint = j;
    js.corrected_alpha = alpha_j;
    place_above_noise(s, o, j, js, d);
    for (const JointFinding& f : d.joint_findings) {
      if (f.joint != j) continue;
      const CandidateResult& leader = d.candidates[f.leading.front()];
      js.leader_shrinkage_percent = leader.joint_shrinkage_percent;
      if (leader.joint_shrinkage_percent < o.min_shrinkage_percent) continue;
      js.leader_p_value = block_bootstrap_p_value(own_joint_gains(s, leader.fit, heldout), block,
                                                  resamples, seed + j);
      js.by_candidate = js.leader_p_value < alpha_j;
    }
    d.joint_significance.push_back(js);
  }
}

// A fitted candidate's held-out figures: per held-out row the reduction of the squared gap summed
// over the joints it acts on (and on its own joint), their shrinkage and block-bootstrap p-values.
CandidateResult score_candidate(const GapSignals& s, const DiagnosisOptions& o, CandidateFit fit,
                                const Rows& rows, std::size_t block, std::uint64_t seed) {
  const double e0 = heldout_energy(s.gap_rad, rows);
  CandidateResult r;
  std::vector<double> d(rows.heldout.size(), 0.0), d_joint(rows.heldout.size(), 0.0);
  double gain = 0.0, ej0 = 0.0, joint_gain = 0.0;
  for (std::size_t jj = 0; jj < s.joint_count(); ++jj) {
    const auto& p = fit.prediction[jj];
    if (p.empty()) continue;
    const auto& g = s.gap_rad[jj];
    for (std::size_t i = 0; i < rows.heldout.size(); ++i) {
      const std::size_t k = rows.heldout[i];
      const double res = g[k] - p[k];
      const double di = g[k] * g[k] - res * res;
      d[i] += di;
      gain += di;
      if (jj == fit.joint) joint_gain += di, d_joint[i] += di;
    }
  }
  for (std::size_t k : rows.heldout) ej0 += s.gap_rad[fit.joint][k] * s.gap_rad[fit.joint][k];
  const double e = e0 - gain;
  r.shrinkage_percent = e0 > 0.0 ? 100.0 * (1.0 - std::sqrt(std::max(e, 0.0) / e0)) : 0.0;
  r.joint_shrinkage_percent =
      ej0 > 0.0 ? 100.0 * (1.0 - std::sqrt(std::max(ej0 - joint_gain, 0.0) / ej0)) : 0.0;
  r.p_value = block_bootstrap_p_value(d, block, o.bootstrap_resamples, seed);
  r.supported = r.p_value < o.alpha && r.shrinkage_percent >= o.min_shrinkage_percent;
  r.joint_p_value = block_bootstrap_p_value(d_joint, block, o.bootstrap_resamples, seed + 1);
  r.joint_supported =
      r.joint_p_value < o.alpha && r.joint_shrinkage_percent >= o.min_shrinkage_percent;
  r.fit = std::move(fit);
  return r;
}

// Every candidate on every joint, in (kind, joint) order: the fits and their figures are
// independent tasks on the cores (core/parallel_tasks.hpp); the bootstrap seeds are dealt in that
// order, two per fitted candidate, as one thread would, so the result does not depend on the
// threads.
std::vector<CandidateResult> fit_every_candidate(const GapSignals& s, const DiagnosisOptions& o,
                                                 const std::vector<bool>& training,
                                                 const Rows& rows, std::size_t block,
                                                 std::uint64_t& seed) {
  const std::size_t nj = s.joint_count();
  std::vector<std::optional<CandidateFit>> fits(std::size_t(kEffectKindCount) * nj);
  run_parallel_tasks(fits.size(), [&](std::size_t i) {
    fits[i] = fit_candidate(effect_kind_from_index(int(i / nj)), s, i % nj, training);
  });
  std::vector<std::uint64_t> seeds(fits.size(), 0);
  for (std::size_t i = 0; i < fits.size(); ++i)
    if (fits[i]) seeds[i] = seed, seed += 2;
  std::vector<std::optional<CandidateResult>> scored(fits.size());
  run_parallel_tasks(fits.size(), [&](std::size_t i) {
    if (fits[i]) scored[i] = score_candidate(s, o, std::move(*fits[i]), rows, block, seeds[i]);
    fits[i].reset();
  });
  std::vector<CandidateResult> out;
  for (auto& r : scored)
    if (r) out.push_back(std::move(*r));
  return out;
}

// The joint model refined on the nominal model's simulator; applied when it predicts the held-out
// gap better.
void refine_joint_model(const GapSignals& s, const NominalPlant& nominal,
                        const std::vector<bool>& training, const std::vector<std::size_t>& heldout,
                        double linear_heldout_energy, Diagnosis& out) {
  std::vector<CandidateFit> members;
  for (const CombinationStep& step : out.combination) members.push_back(step.fit);
  out.refinement =
      refine_on_nominal_plant(s, nominal, members, training, heldout, linear_heldout_energy);
  if (!out.refinement.applied) return;
  out.combination.back().shrinkage_percent = out.refinement.shrinkage_percent;
  out.heldout_rms_modelled_rad =
      std::sqrt(out.refinement.heldout_energy / double(std::max<std::size_t>(heldout.size(), 1)));
  for (std::size_t i = 0; i < out.refinement.members.size(); ++i) {
    CombinationStep& step = out.combination[out.refinement.members[i]];
    step.fit.kind = out.refinement.parameters[i].kind;
    step.fit.shape = "the nominal model re-simulated";
    step.fit.size_text = out.refinement.changes[i];
    step.label = candidate_label(s, step.fit);
  }
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
  // Every block's sum, once: a resample is then `blocks` additions, not m.
  std::vector<double> block_sum(m - block + 1, 0.0);
  for (std::size_t s0 = 0; s0 < block_sum.size(); ++s0)
    for (std::size_t i = 0; i < block; ++i) block_sum[s0] += d[s0 + i];
  int not_positive = 0;
  for (int r = 0; r < resamples; ++r) {
    double sum = 0.0;
    for (std::size_t b = 0; b < blocks; ++b) sum += block_sum[start(rng)];
    if (sum <= 0.0) ++not_positive;
  }
  return (1.0 + not_positive) / (1.0 + resamples);
}

Diagnosis diagnose_gap(const GapSignals& s, const DiagnosisOptions& o,
                       const NominalPlant* nominal) {
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
  out.measurement = measurement_budget(s, training, o.block_s, o.alpha);

  // Every candidate on every joint.
  std::uint64_t seed = o.seed;
  out.candidates = fit_every_candidate(s, o, training, rows, block, seed);
  // Ranked by held-out shrinkage less a parsimony charge of 0.5 percentage points per own
  // parameter: of two candidates that explain the same (a drift that nests an offset), the simpler
  // first. The coupling's parameters are left aside, as in the per-joint ranking and the joint
  // model's selection: they carry the effect's known reach into the other joints through the
  // inertia, not a further explanation (charged, they put a drift on the joint ahead of the
  // elastic gear that moves it and its neighbours).
  const auto score = [](const CandidateResult& c) {
    const double own = double(c.fit.parameters.size() - c.fit.coupling_parameter_count);
    return c.shrinkage_percent - kParsimonyPercentPerParameter * own;
  };
  // Equal scores (the same modelled gap): a backlash held on one flank after the plain
  // explanation it cannot be told from (a zero offset); eval/gap_ambiguity.hpp groups them.
  const auto one_flank = [](const CandidateResult& c) { return c.fit.shape == kOneFlankShape; };
  std::stable_sort(out.candidates.begin(), out.candidates.end(),
                   [&](const CandidateResult& a, const CandidateResult& b) {
                     if (score(a) != score(b)) return score(a) > score(b);
                     return !one_flank(a) && one_flank(b);
                   });
  out.significant_gap =
      !out.candidates.empty() && out.candidates.front().supported && !out.measurement.within;
  group_ambiguous(s, rows.heldout, out);

  // The joint model: candidates fitted together, chosen by forward-backward selection on the
  // held-out rows (eval/gap_selection.hpp), starting from the cause ranked first.
  if (out.significant_gap) {
    const JointModel model =
        select_joint_model(s, o, out.candidates, training, rows.heldout, block, seed);
    out.combination = model.steps;
    out.heldout_rms_modelled_rad = std::sqrt(std::max(model.heldout_energy, 0.0) / m);
    if (nominal) refine_joint_model(s, *nominal, training, rows.heldout, model.heldout_energy, out);
  }

  find_per_joint(s, o, rows.heldout, out);
  test_joints(s, o, rows.heldout, block, seed, out);
  for (const JointSignificance& js : out.joint_significance)
    out.significant_gap = out.significant_gap || (js.significant() && !out.measurement.within);
  write_verdict(s, o, out);
  if (out.measurement.known && !out.measurement.within)
    out.verdict += " " + measurement_in_words(s, out.measurement);
  return out;
}

std::vector<std::size_t> leading_group(const Diagnosis& d) {
  if (!d.significant_gap || d.candidates.empty()) return {};
  if (d.candidates.front().supported) {
    const int g = d.candidates.front().ambiguity_group;
    return g >= 0 ? d.ambiguity_groups[std::size_t(g)].members : std::vector<std::size_t>{0};
  }
  const JointSignificance* best = nullptr;
  for (const JointSignificance& js : d.joint_significance)
    if (js.by_candidate && (!best || js.excess > best->excess)) best = &js;
  if (best)
    for (const JointFinding& f : d.joint_findings)
      if (f.joint == best->joint) return f.leading;
  return {};
}

}  // namespace imscal::eval
