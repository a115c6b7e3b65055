#include "eval/gap_selection.hpp"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <optional>

#include "core/parallel_tasks.hpp"
#include "eval/gap_bounds.hpp"

namespace imscal::eval {
namespace {

// Of the joint refits of a forward step, the best held-out shrinkage less this charge per own
// parameter, its coupling's left aside [pp] (the per-joint ranking's, eval/gap_diagnosis.cpp): a
// drift does not displace the offset it nests for a sliver of noise.
constexpr double kParsimonyPercentPerParameter = 0.5;
// A member kept by its own joint's gain must still add this much to the whole gap [pp]: not the
// remaining coloured noise of a joint already explained.
constexpr double kJointRouteMinWholePercent = 0.5;

// A joint refit of a set of candidates: the residual of every joint and its held-out energy.
struct Refit {
  std::vector<std::vector<double>> residual;
  double energy = 0.0;
};

double heldout_energy(const std::vector<double>& r, const std::vector<std::size_t>& heldout) {
  double e = 0.0;
  for (std::size_t k : heldout) e += r[k] * r[k];
  return e;
}

Refit refit(const GapSignals& s, const std::vector<CandidateFit>& set,
            const std::vector<bool>& training, const std::vector<std::size_t>& heldout) {
  std::vector<Eigen::MatrixXd> columns(s.joint_count());
  std::vector<LevelBound> bounds;
  Eigen::Index offset = 0;
  for (const CandidateFit& f : set) {
    if (f.bound.count > 0) {
      LevelBound b = f.bound;
      b.first += offset;
      bounds.push_back(std::move(b));
    }
    columns = join_columns(columns, f.columns, s.sample_count());
    offset += f.parameters.size();
  }
  LinearFit fit = fit_joint_columns(columns, s.gap_rad, training);
  apply_level_bounds(columns, s.gap_rad, training, bounds, fit);
  const auto prediction = predict_joint_columns(columns, fit.parameters);
  Refit r{s.gap_rad, 0.0};
  for (std::size_t j = 0; j < r.residual.size(); ++j) {
    for (std::size_t k = 0; k < prediction[j].size(); ++k) r.residual[j][k] -= prediction[j][k];
    r.energy += heldout_energy(r.residual[j], heldout);
  }
  return r;
}

// What a member adds to a model: its further shrinkage of the whole held-out gap [pp of the
// original gap] and of its own joint's remaining gap [%], with their bootstrap p-values.
struct Gain {
  double whole_pp = 0.0, joint_percent = 0.0, p = 1.0, joint_p = 1.0;
};

struct Context {
  const GapSignals& s;
  const DiagnosisOptions& o;
  const std::vector<CandidateResult>& candidates;
  const std::vector<bool>& training;
  const std::vector<std::size_t>& heldout;
  std::size_t block;
  std::uint64_t& seed;
  double e0;  // held-out energy of the gap itself

  double shrink(double e) const {
    return e0 > 0.0 ? 100.0 * (1.0 - std::sqrt(std::max(e, 0.0) / e0)) : 0.0;
  }

  Gain gain(const Refit& without, const Refit& with, std::size_t joint) const {
    std::vector<double> d(heldout.size(), 0.0), dj(heldout.size(), 0.0);
    for (std::size_t j = 0; j < s.joint_count(); ++j)
      for (std::size_t i = 0; i < heldout.size(); ++i) {
        const std::size_t k = heldout[i];
        const double di = without.residual[j][k] * without.residual[j][k] -
                          with.residual[j][k] * with.residual[j][k];
        d[i] += di;
        if (j == joint) dj[i] = di;
      }
    Gain g;
    g.whole_pp = shrink(with.energy) - shrink(without.energy);
    const double ej_without = heldout_energy(without.residual[joint], heldout);
    const double ej_with = heldout_energy(with.residual[joint], heldout);
    g.joint_percent =
        ej_without > 0.0 ? 100.0 * (1.0 - std::sqrt(std::max(ej_with, 0.0) / ej_without)) : 0.0;
    g.p = block_bootstrap_p_value(d, block, o.bootstrap_resamples, seed++);
    const double alpha_j = sidak_alpha(o.alpha, s.joint_count());
    const int resamples = std::max(o.bootstrap_resamples, int(std::ceil(4.0 / alpha_j)));
    g.joint_p = block_bootstrap_p_value(dj, block, resamples, seed++);
    return g;
  }

  // The rule of the header: significant on the whole gap, or on its own joint.
  bool significant(const Gain& g) const {
    const double alpha_j = sidak_alpha(o.alpha, s.joint_count());
    return (g.p < o.alpha && g.whole_pp >= o.min_combination_gain_percent) ||
           (g.joint_p < alpha_j && g.joint_percent >= o.min_shrinkage_percent &&
            g.whole_pp >= kJointRouteMinWholePercent);
  }
};

// Every candidate but the first: each is fitted again to the gap the model leaves, so an effect
// hidden behind a larger one, whose fit to the whole gap explains nothing of it, still competes.
std::vector<std::size_t> selection_pool(const std::vector<CandidateResult>& candidates) {
  std::vector<std::size_t> pool;
  for (std::size_t c = 1; c < candidates.size(); ++c) pool.push_back(c);
  return pool;
}

// Held-out energy left when a candidate's own columns are fitted to the model's residual (the
// cheap forward score; the best few are then refitted jointly).
double residual_score(const Context& x, std::size_t c, const Refit& model) {
  const CandidateFit& f = x.candidates[c].fit;
  const LinearFit fit = fit_joint_columns(f.columns, model.residual, x.training);
  const auto prediction = predict_joint_columns(f.columns, fit.parameters);
  double e = model.energy;
  for (std::size_t j = 0; j < prediction.size(); ++j)
    for (std::size_t k : x.heldout) {
      if (prediction[j].empty()) break;
      const double r = model.residual[j][k];
      e += (r - prediction[j][k]) * (r - prediction[j][k]) - r * r;
    }
  return e;
}

// How many of the best residual scores are refitted jointly per forward step.
constexpr std::size_t kJointRefitsPerStep = 5;

// The member (not the first) whose loss is least, when that loss is not significant; -1: none.
int weakest_member(const Context& x, const std::vector<CandidateFit>& set, const Refit& full) {
  int weakest = -1;
  double least = 0.0;
  // The refits without each member on the cores; their gains (and seeds) in order.
  std::vector<Refit> without(set.size());
  run_parallel_tasks(set.size() - 1, [&](std::size_t m) {
    std::vector<CandidateFit> rest = set;
    rest.erase(rest.begin() + std::ptrdiff_t(m + 1));
    without[m + 1] = refit(x.s, rest, x.training, x.heldout);
  });
  for (std::size_t i = 1; i < set.size(); ++i) {
    const Gain g = x.gain(without[i], full, set[i].joint);
    if (x.significant(g)) continue;
    if (weakest < 0 || g.whole_pp < least) weakest = int(i), least = g.whole_pp;
  }
  return weakest;
}

// A candidate fitted again, shape and size, to the gap the model leaves (`on_residual`: the
// signals with the model's residual as their gap); the candidate's own fit when it does not apply.
CandidateFit refined(const Context& x, std::size_t c, const GapSignals& on_residual) {
  const CandidateFit& f = x.candidates[c].fit;
  auto fit = fit_candidate(f.kind, on_residual, f.spans_joints ? 0 : f.joint, x.training);
  return fit ? std::move(*fit) : f;
}

// A forward step's trial: the model grown by one candidate (fitted again to the model's
// residual), its joint refit, and the p-value of its further gain once tested.
struct Trial {
  double score = 0.0;
  std::size_t candidate = 0;
  std::vector<CandidateFit> set;
  Refit refit;
  double p_value = 1.0;
};

double own_parameters(const Trial& t) {
  const CandidateFit& added = t.set.back();
  return double(added.parameters.size() - added.coupling_parameter_count);
}

// Whether every column of `small` lies in the span of `big`'s columns on the same joint (to 1e-6
// of its norm): an offset in a drift, a play held on one flank in a drift.
bool nested_in(const CandidateFit& small, const CandidateFit& big) {
  if (small.columns.size() != big.columns.size()) return false;
  for (std::size_t j = 0; j < small.columns.size(); ++j) {
    const Eigen::MatrixXd& a = small.columns[j];
    if (a.cols() == 0) continue;
    const Eigen::MatrixXd& b = big.columns[j];
    if (b.cols() == 0) return false;
    const Eigen::MatrixXd coefficients = b.colPivHouseholderQr().solve(a);
    if ((a - b * coefficients).norm() > 1e-6 * a.norm()) return false;
  }
  return true;
}

// Of the trials on the joint of trials[best] (the forward step's choice) nested in it, the one
// with the fewest own parameters that adds significantly to the model and that trials[best] does
// not improve on significantly (the same rule): the extra columns explain nothing the data can
// show (a drift's slope and curvature, fitted to the chain's slow noise, displaced the offset it
// nests). trials[best] itself when none is.
std::size_t fewest_parameters_alike(const Context& x_in, const Refit& model,
                                    std::vector<Trial>& trials, std::size_t best) {
  // Its own bootstrap seeds: the selection's other tests draw the same as without this check.
  std::uint64_t seed = x_in.seed;
  const Context x{x_in.s,     x_in.o, x_in.candidates, x_in.training, x_in.heldout,
                  x_in.block, seed,   x_in.e0};
  const std::size_t joint = x.candidates[trials[best].candidate].fit.joint;
  std::size_t chosen = best;
  for (std::size_t i = 0; i < trials.size(); ++i) {
    Trial& u = trials[i];
    if (i == best || x.candidates[u.candidate].fit.joint != joint ||
        own_parameters(u) >= own_parameters(trials[chosen]) ||
        !nested_in(u.set.back(), trials[best].set.back()))
      continue;
    const Gain alone = x.gain(model, u.refit, joint);
    if (!x.significant(alone) || x.significant(x.gain(u.refit, trials[best].refit, joint)))
      continue;
    u.p_value = std::min(alone.p, alone.joint_p);
    chosen = i;
  }
  return chosen;
}

// The five candidates whose own columns best explain the model's residual, fitted again to it and
// refitted jointly with the model, tried in the order of their held-out shrinkage less the
// parsimony charge: the first whose gain is significant, or none.
std::optional<Trial> forward_step(const Context& x, const std::vector<std::size_t>& pool,
                                  const std::vector<CandidateFit>& set, const Refit& model,
                                  const GapSignals& on_residual, std::vector<bool>& tried) {
  // The scores and the trials are independent tasks (core/parallel_tasks.hpp), each writing its
  // own slot; the order they are then used in is the serial one.
  std::vector<std::pair<double, std::size_t>> scored;
  for (std::size_t c : pool)
    if (!tried[c]) scored.emplace_back(0.0, c);
  run_parallel_tasks(scored.size(), [&](std::size_t i) {
    scored[i].first = residual_score(x, scored[i].second, model);
  });
  std::sort(scored.begin(), scored.end());
  if (scored.size() > kJointRefitsPerStep) scored.resize(kJointRefitsPerStep);
  std::vector<Trial> trials(scored.size());
  run_parallel_tasks(scored.size(), [&](std::size_t i) {
    Trial& t = trials[i];
    t.candidate = scored[i].second;
    t.set = set;
    t.set.push_back(refined(x, t.candidate, on_residual));
    t.refit = refit(x.s, t.set, x.training, x.heldout);
    t.score = x.shrink(t.refit.energy) - kParsimonyPercentPerParameter * own_parameters(t);
  });
  std::stable_sort(trials.begin(), trials.end(),
                   [](const Trial& a, const Trial& b) { return a.score > b.score; });
  for (std::size_t i = 0; i < trials.size(); ++i) {
    Trial& t = trials[i];
    tried[t.candidate] = true;
    const Gain g = x.gain(model, t.refit, x.candidates[t.candidate].fit.joint);
    if (!x.significant(g)) continue;
    t.p_value = std::min(g.p, g.joint_p);
    const std::size_t chosen = fewest_parameters_alike(x, model, trials, i);
    tried[trials[chosen].candidate] = true;
    return std::move(trials[chosen]);
  }
  return std::nullopt;
}

}  // namespace

JointModel select_joint_model(const GapSignals& s, const DiagnosisOptions& o,
                              const std::vector<CandidateResult>& candidates,
                              const std::vector<bool>& training,
                              const std::vector<std::size_t>& heldout, std::size_t block,
                              std::uint64_t& seed) {
  double e0 = 0.0;
  for (const auto& g : s.gap_rad) e0 += heldout_energy(g, heldout);
  const Context x{s, o, candidates, training, heldout, block, seed, e0};
  std::vector<CandidateFit> set = {candidates.front().fit};
  std::vector<std::size_t> index = {0};
  Refit model = refit(s, set, training, heldout);
  std::vector<double> p_of = {candidates.front().p_value};
  const std::vector<std::size_t> pool = selection_pool(candidates);
  std::vector<bool> tried(candidates.size(), false);
  std::vector<std::size_t> dropped;
  GapSignals on_residual = s;
  while (int(set.size()) < o.max_combination) {
    on_residual.gap_rad = model.residual;
    std::optional<Trial> added = forward_step(x, pool, set, model, on_residual, tried);
    if (!added) break;
    set = std::move(added->set);
    index.push_back(added->candidate);
    p_of.push_back(added->p_value);
    model = std::move(added->refit);
    // Against the grown model's residual, a candidate tried before may now add significantly;
    // members and those dropped stay out (no cycle).
    std::fill(tried.begin(), tried.end(), false);
    for (std::size_t c : index) tried[c] = true;
    for (std::size_t c : dropped) tried[c] = true;
    const int weakest = weakest_member(x, set, model);
    if (weakest > 0) {
      dropped.push_back(index[std::size_t(weakest)]);
      tried[dropped.back()] = true;
      set.erase(set.begin() + weakest);
      index.erase(index.begin() + weakest);
      p_of.erase(p_of.begin() + weakest);
      model = refit(s, set, training, heldout);
    }
  }
  JointModel out;
  out.heldout_energy = model.energy;
  // The cumulative shrinkage of each prefix of the final set, jointly refitted.
  for (std::size_t i = 0; i < set.size(); ++i) {
    const std::vector<CandidateFit> prefix(set.begin(), set.begin() + std::ptrdiff_t(i) + 1);
    const double e =
        i + 1 == set.size() ? model.energy : refit(s, prefix, training, heldout).energy;
    out.steps.push_back({candidate_label(s, set[i]), x.shrink(e), p_of[i], index[i], set[i]});
  }
  return out;
}

}  // namespace imscal::eval
