#include "eval/gap_refinement.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/parallel_tasks.hpp"
#include "eval/gap_bounds.hpp"

namespace imscal::eval {
namespace {

using Signal = std::vector<std::vector<double>>;  // [joint][sample]

constexpr int kMaxGaussNewtonSteps = 4;
constexpr double kConvergedFractionOfStep = 0.01;

struct Problem {
  const GapSignals& s;
  const NominalPlant& plant;
  const std::vector<bool>& training;
  const std::vector<std::size_t>& heldout;
  std::vector<NominalParameter> parameters;
  std::vector<Eigen::MatrixXd> others;  // the other members' linear columns, joined
  std::vector<LevelBound> bounds;       // theirs, indexed into `others`
  Signal q_nominal;
  int simulations = 0;

  Eigen::Index size() const {
    Eigen::Index n = 0;
    for (const auto& p : parameters) n += p.size();
    return n;
  }
};

// The modelled gap m(p) of the file's head.
Signal modelled_gap(const Problem& x, const Eigen::VectorXd& p) {
  Signal q = simulate_links(x.plant, x.parameters, p);
  for (std::size_t j = 0; j < q.size(); ++j)
    for (std::size_t k = 0; k < q[j].size(); ++k) q[j][k] = x.q_nominal[j][k] - q[j][k];
  return q;
}

struct Evaluated {
  Signal residual;
  double training_energy = 0.0, heldout_energy = 0.0;
};

// The gap less m, less the other members fitted to what m leaves (within their bounds).
Evaluated evaluate(const Problem& x, const Signal& m) {
  Evaluated e{x.s.gap_rad};
  for (std::size_t j = 0; j < m.size(); ++j)
    for (std::size_t k = 0; k < m[j].size(); ++k) e.residual[j][k] -= m[j][k];
  if (!x.others.empty()) {
    LinearFit fit = fit_joint_columns(x.others, e.residual, x.training);
    apply_level_bounds(x.others, e.residual, x.training, x.bounds, fit);
    const Signal prediction = predict_joint_columns(x.others, fit.parameters);
    for (std::size_t j = 0; j < prediction.size(); ++j)
      for (std::size_t k = 0; k < prediction[j].size(); ++k) e.residual[j][k] -= prediction[j][k];
  }
  for (const auto& r : e.residual)
    for (std::size_t k = 0; k < r.size(); ++k)
      (x.training[k] ? e.training_energy : e.heldout_energy) += r[k] * r[k];
  return e;
}

// One Gauss-Newton step at p (modelled gap m): the parameters' change, the others' coefficients
// fitted beside it, and the linearised model's residual RMS on the training rows.
struct Step {
  Eigen::VectorXd delta;
  double rms = 0.0;
};

Step gauss_newton_step(Problem& x, const Eigen::VectorXd& p, const Signal& m) {
  const Eigen::Index np = p.size();
  const Eigen::VectorXd step = nominal_steps(x.plant, x.parameters, p);
  std::vector<Signal> moved(static_cast<std::size_t>(np));
  run_parallel_tasks(std::size_t(np), [&](std::size_t i) {
    Eigen::VectorXd q = p;
    q[Eigen::Index(i)] += step[Eigen::Index(i)];
    moved[i] = modelled_gap(x, q);
  });
  x.simulations += int(np);
  const std::size_t n = x.s.sample_count();
  std::vector<Eigen::MatrixXd> jacobian(m.size(), Eigen::MatrixXd(Eigen::Index(n), np));
  for (std::size_t j = 0; j < m.size(); ++j)
    for (Eigen::Index i = 0; i < np; ++i)
      for (std::size_t k = 0; k < n; ++k)
        jacobian[j](Eigen::Index(k), i) = (moved[std::size_t(i)][j][k] - m[j][k]) / step[i];
  const std::vector<Eigen::MatrixXd> columns =
      x.others.empty() ? jacobian : join_columns(jacobian, x.others, n);
  std::vector<LevelBound> bounds = x.bounds;
  for (LevelBound& b : bounds) b.first += np;
  Signal target = x.s.gap_rad;
  for (std::size_t j = 0; j < m.size(); ++j)
    for (std::size_t k = 0; k < n; ++k) target[j][k] -= m[j][k];
  LinearFit fit = fit_joint_columns(columns, target, x.training);
  apply_level_bounds(columns, target, x.training, bounds, fit);
  return {fit.parameters.head(np), fit.rms};
}

// How many of the orders the raw ripple fits best are tried by simulation: the link's response
// to a high order is filtered and delayed by the loop, so the raw ripple's best is not always it.
constexpr std::size_t kOrdersSimulated = 3;

// What the drive member i may stand for: each drive effect of its joint that no other member
// holds, a transmission error at the orders whose raw ripple best fits the member's residual.
std::vector<NominalParameter> drive_alternatives(const Problem& x, std::size_t i,
                                                 const Signal& residual) {
  const std::size_t joint = x.parameters[i].joint;
  std::vector<NominalParameter> out;
  // The effects of a joint's drive that the nominal model has as parameters
  // (NominalParameterDefinition::of_drive), one of which a member may stand for: the linear
  // candidates confuse them (a Coulomb friction raised looks like a play on a joint whose torque
  // and velocity change sign together), the simulated ones less.
  for (const EffectDefinition* effect : kEffectDefinitions) {
    if (!effect->nominal || !effect->nominal->of_drive) continue;
    const EffectKind kind = effect->kind;
    bool present = false;
    for (std::size_t k = 0; k < x.parameters.size(); ++k)
      present |= k != i && x.parameters[k].kind == kind && x.parameters[k].joint == joint;
    if (present || !has_nominal_parameter(x.plant, kind, joint)) continue;
    if (!effect->nominal->per_motor_order) {
      out.push_back({kind, joint, 1.0});
      continue;
    }
    const std::vector<double> orders =
        transmission_orders_by_fit(x.s, joint, residual[joint], x.training);
    for (std::size_t o = 0; o < std::min(kOrdersSimulated, orders.size()); ++o)
      out.push_back({kind, joint, orders[o]});
  }
  return out;
}

// Each drive member replaced by the alternative whose linearised fit (the first Gauss-Newton
// step, at the nominal model) leaves the least training residual.
void choose_drive_effects(Problem& x, const Signal& zero, const Signal& residual) {
  for (std::size_t i = 0; i < x.parameters.size(); ++i) {
    if (!effect_definition(x.parameters[i].kind).nominal->of_drive) continue;
    double best = std::numeric_limits<double>::infinity();
    NominalParameter chosen = x.parameters[i];
    for (const NominalParameter& alternative : drive_alternatives(x, i, residual)) {
      x.parameters[i] = alternative;
      const double rms = gauss_newton_step(x, Eigen::VectorXd::Zero(x.size()), zero).rms;
      if (rms < best) best = rms, chosen = alternative;
    }
    x.parameters[i] = chosen;
  }
}

// The members split: those with a parameter of the nominal model, the others' columns and bounds.
void split_members(Problem& x, const std::vector<CandidateFit>& members, NominalRefinement& out) {
  const std::size_t n = x.s.sample_count();
  for (std::size_t i = 0; i < members.size(); ++i) {
    const CandidateFit& f = members[i];
    bool repeated = false;
    for (const NominalParameter& p : x.parameters)
      repeated |= p.kind == f.kind && (p.joint == f.joint || f.spans_joints);
    if (!repeated && has_nominal_parameter(x.plant, f.kind, f.joint)) {
      x.parameters.push_back({f.kind, f.joint, 1.0});
      out.members.push_back(i);
      continue;
    }
    Eigen::Index offset = 0;
    for (const Eigen::MatrixXd& c : x.others) offset = std::max(offset, c.cols());
    if (f.bound.count > 0) {
      LevelBound b = f.bound;
      b.first += offset;
      x.bounds.push_back(std::move(b));
    }
    x.others = x.others.empty() ? f.columns : join_columns(x.others, f.columns, n);
  }
}

}  // namespace

NominalRefinement refine_on_nominal_plant(const GapSignals& s, const NominalPlant& plant,
                                          const std::vector<CandidateFit>& members,
                                          const std::vector<bool>& training,
                                          const std::vector<std::size_t>& heldout,
                                          double linear_heldout_energy) {
  NominalRefinement out;
  const std::size_t rows = plant.samples.empty() ? plant.path.samples.size() : plant.samples.size();
  if (s.sample_count() != rows || s.q_internal_rad.empty()) return out;
  Problem x{s, plant, training, heldout, {}, {}, {}, {}, 0};
  split_members(x, members, out);
  if (x.parameters.empty()) return out;
  x.q_nominal = simulate_links(plant, {}, Eigen::VectorXd());
  x.simulations = 1;
  const Signal zero(s.joint_count(), std::vector<double>(s.sample_count(), 0.0));
  Evaluated current = evaluate(x, zero);
  choose_drive_effects(x, zero, current.residual);
  Eigen::VectorXd p = Eigen::VectorXd::Zero(x.size());
  Signal m = zero;
  for (int it = 0; it < kMaxGaussNewtonSteps; ++it) {
    const Eigen::VectorXd delta = gauss_newton_step(x, p, m).delta;
    const Eigen::VectorXd step = nominal_steps(plant, x.parameters, p);
    bool accepted = false;
    for (double fraction : {1.0, 0.5}) {
      const Eigen::VectorXd trial = physical_parameters(plant, x.parameters, p + fraction * delta);
      Signal m_trial = modelled_gap(x, trial);
      ++x.simulations;
      Evaluated e = evaluate(x, m_trial);
      if (e.training_energy >= current.training_energy) continue;
      p = trial, m = std::move(m_trial), current = std::move(e), accepted = true;
      break;
    }
    if (!accepted || (delta.cwiseAbs().array() < kConvergedFractionOfStep * step.array()).all())
      break;
  }
  double e0 = 0.0;
  for (const auto& g : s.gap_rad)
    for (std::size_t k : heldout) e0 += g[k] * g[k];
  out.heldout_energy = current.heldout_energy;
  out.shrinkage_percent = e0 > 0.0 ? 100.0 * (1.0 - std::sqrt(current.heldout_energy / e0)) : 0.0;
  out.applied = current.heldout_energy < linear_heldout_energy;
  out.simulations = x.simulations;
  Eigen::Index i = 0;
  for (const NominalParameter& parameter : x.parameters) {
    out.parameters.push_back(parameter);
    out.values.push_back(p.segment(i, parameter.size()));
    out.changes.push_back(
        describe_nominal_change(plant, parameter, p.segment(i, parameter.size())));
    i += parameter.size();
  }
  return out;
}

}  // namespace imscal::eval
