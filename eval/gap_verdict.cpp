#include "eval/gap_verdict.hpp"
#include "core/units.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace imscal::eval {
namespace {

// Where the gap lies, and the cells outside the identified range on every joint that runs there.
std::string where_in_words(const Diagnosis& d) {
  if (d.where.joints.empty()) return {};
  std::size_t top_joint = 0;
  for (std::size_t j = 0; j < d.where.joints.size(); ++j)
    if (d.where.joints[j].energy_share > d.where.joints[top_joint].energy_share) top_joint = j;
  const auto& ja = d.where.joints[top_joint];
  const auto top_of = [](const std::vector<GapShare>& v) {
    return *std::max_element(v.begin(), v.end(), [](const GapShare& a, const GapShare& b) {
      return a.energy_share < b.energy_share;
    });
  };
  const GapShare ph = top_of(ja.by_phase), band = top_of(ja.by_band);
  std::vector<std::string> per_joint;
  for (const auto& jo : d.where.joints)
    per_joint.push_back(fmt::format("{} {:.1f}", jo.joint, jo.rms_rad * kArcsecPerRad));
  std::string where = fmt::format(
      "The gap (RMS {:.3g} rad = {:.1f} arcsec over all joints; per joint {} arcsec) lies mostly "
      "in joint {} ({:.0f} % of its energy), there mostly during {} ({:.0f} % of the joint's gap "
      "energy in {:.0f} % of the time) and in the {} band ({:.0f} %).",
      d.where.rms_rad, d.where.rms_rad * kArcsecPerRad, fmt::join(per_joint, ", "), ja.joint,
      100.0 * ja.energy_share, ph.label, 100.0 * ph.energy_share, 100.0 * ph.time_share, band.label,
      100.0 * band.energy_share);
  std::vector<std::string> outside;
  for (const auto& jo : d.where.joints) {
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
  return where;
}

// "X, or indistinguishable on these data: Y, Z" for a list of candidate indices.
std::string members_in_words(const GapSignals& s, const Diagnosis& d,
                             const std::vector<std::size_t>& members) {
  std::string t = candidate_in_words(s, d.candidates[members.front()].fit);
  if (members.size() > 1) {
    std::vector<std::string> others;
    for (std::size_t i = 1; i < members.size(); ++i)
      others.push_back(candidate_in_words(s, d.candidates[members[i]].fit));
    t += fmt::format(", or, indistinguishable from it on these data, {}", fmt::join(others, "; "));
  }
  return t;
}

std::string labels_of(const GapSignals& s, const Diagnosis& d,
                      const std::vector<std::size_t>& members) {
  std::vector<std::string> l;
  for (std::size_t m : members) l.push_back(candidate_label(s, d.candidates[m].fit));
  return fmt::format("{}", fmt::join(l, " / "));
}

const JointFinding* finding_of(const Diagnosis& d, std::size_t joint) {
  for (const JointFinding& f : d.joint_findings)
    if (f.joint == joint) return &f;
  return nullptr;
}

// One joint significant on its own: its most likely cause when its leading candidate is
// significant at the joints' corrected level, else that nothing carries over and what to record.
void joint_in_words(const GapSignals& s, const JointSignificance& js, Diagnosis& out) {
  const JointFinding* f = finding_of(out, js.joint);
  const std::string& name = s.joint_names[js.joint];
  if (js.by_candidate && f) {
    out.verdict += fmt::format(
        " On joint {} the most likely cause: {}, which shrinks that joint's held-out gap by "
        "{:.0f} % (p = {:.4f}, below the level {:.4f} of each of the {} joints' tests).",
        name, members_in_words(s, out, f->leading), js.leader_shrinkage_percent, js.leader_p_value,
        js.corrected_alpha, s.joint_count());
    return;
  }
  const CandidateResult* leader = f ? &out.candidates[f->leading.front()] : nullptr;
  out.verdict += fmt::format(
      " On joint {} no candidate effect fitted on the training blocks carries over to the "
      "held-out ones{}: an effect outside the library, or a record too short for the candidates "
      "to be judged.",
      name,
      leader ? fmt::format(" (the best, {}, shrinks its held-out gap by {:.0f} %)",
                           candidate_label(s, leader->fit), js.leader_shrinkage_percent)
             : std::string());
  out.measure_next.push_back(fmt::format(
      "on joint {}: a longer record that repeats each kind of motion (so that the training and "
      "the held-out blocks both see it){}",
      name, leader ? std::string(", and ") + what_to_measure(leader->fit.kind) : std::string()));
}

// The gap is significant per joint only (eval/gap_joint_significance.hpp): which joints, how far
// above their noise, and per joint its cause or what to record.
void write_joint_verdict(const GapSignals& s, const DiagnosisOptions& o, const std::string& where,
                         Diagnosis& out) {
  std::vector<std::string> joints;
  for (const JointSignificance& js : out.joint_significance)
    if (js.significant())
      joints.push_back(
          fmt::format("{} (RMS {:.1f} arcsec, {:.0f} times its noise reference of "
                      "{:.2g} arcsec)",
                      s.joint_names[js.joint], js.rms_rad * kArcsecPerRad, js.excess,
                      js.noise_reference_rad * kArcsecPerRad));
  out.verdict = fmt::format(
      "{} A significant structured gap on joint{} {}, though no candidate effect shrinks the gap "
      "of all joints by at least {:.0f} % with p < {:g}.",
      where, joints.size() > 1 ? "s" : "", fmt::join(joints, "; "), o.min_shrinkage_percent,
      o.alpha);
  for (const JointSignificance& js : out.joint_significance)
    if (js.significant()) joint_in_words(s, js, out);
}

// The causes the model holds beside the first (the combination's further steps), each with the
// further shrinkage it adds.
std::string further_causes_in_words(const GapSignals& s, const Diagnosis& d) {
  std::vector<std::string> further;
  for (std::size_t i = 1; i < d.combination.size(); ++i)
    further.push_back(fmt::format(
        "{}, a further {:.0f} % (p = {:.3f})", candidate_in_words(s, d.combination[i].fit),
        d.combination[i].shrinkage_percent - d.combination[i - 1].shrinkage_percent,
        d.combination[i].p_value));
  if (further.empty()) return {};
  return fmt::format(" Together with it, also causes: {}.", fmt::join(further, "; "));
}

// The model whose shrinkage is predicted: the cause named first, and the further ones.
std::string model_in_words(const Diagnosis& d) {
  if (d.combination.size() < 2) return "it";
  std::vector<std::string> labels;
  for (const auto& c : d.combination) labels.push_back(c.label);
  return fmt::format("these ({})", fmt::join(labels, " + "));
}

// The gap within what the IMS chain's own error explains (eval/gap_measurement_budget.hpp): no
// cause is raised; the candidate ranked first is still named, with its evidence, since the
// floor bounds the chain's error from above (a robot effect near the floor is called within) and
// it is what to look at once the measurement is better.
void write_within_measurement_verdict(const GapSignals& s, const std::string& where,
                                      Diagnosis& out) {
  out.verdict = fmt::format(
      "{} {} No robot cause is raised: at this level the candidates fit the IMS chain's own "
      "error.",
      where, measurement_in_words(s, out.measurement));
  if (!out.candidates.empty()) {
    const CandidateResult& first = out.candidates.front();
    out.verdict += fmt::format(
        " Should part of it lie in the robot, the cause ranked first is {}, which shrinks the "
        "held-out gap by {:.0f} % (p = {:.3f}{}).",
        candidate_in_words(s, first.fit), first.shrinkage_percent, first.p_value,
        first.supported ? "" : ", not significant on its own");
  }
  if (!out.candidates.empty())
    out.measure_next.push_back(fmt::format(
        "if a gap of {:.3g} rad matters: a better measurement (the floor is the IMS smoother's "
        "sigma), then the candidate ranked first, {} ({:.0f} % of the held-out gap)",
        out.heldout_rms_rad, candidate_label(s, out.candidates.front().fit),
        out.candidates.front().shrinkage_percent));
}

}  // namespace

std::string candidate_in_words(const GapSignals& s, const CandidateFit& f) {
  return fmt::format("{} on joint {} ({}; {}{})", to_string(f.kind), s.joint_names[f.joint],
                     f.shape, f.size_text, f.coupling.empty() ? "" : "; coupled " + f.coupling);
}

void write_verdict(const GapSignals& s, const DiagnosisOptions& o, Diagnosis& out) {
  const std::string where = where_in_words(out);
  if (out.measurement.within) return write_within_measurement_verdict(s, where, out);
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
    return;
  }
  if (out.candidates.empty() || !out.candidates.front().supported) {
    write_joint_verdict(s, o, where, out);
    return;
  }
  const CandidateResult& top = out.candidates.front();
  const std::vector<std::size_t> lead = leading_group(out);
  out.verdict = fmt::format(
      "{} Most likely cause: {}, which shrinks the held-out gap by {:.0f} % (p = {:.3f}).{} "
      "Modelled with {}, the held-out gap is expected to fall from {:.3g} rad to {:.3g} rad "
      "({:.0f} % smaller).",
      where, members_in_words(s, out, lead), top.shrinkage_percent, top.p_value,
      further_causes_in_words(s, out), model_in_words(out), out.heldout_rms_rad,
      out.heldout_rms_modelled_rad,
      100.0 * (1.0 - out.heldout_rms_modelled_rad / std::max(out.heldout_rms_rad, 1e-300)));
  if (lead.size() > 1) {
    const AmbiguityGroup& g = out.ambiguity_groups[std::size_t(top.ambiguity_group)];
    out.measure_next.push_back(fmt::format(
        "to tell {} apart (their modelled gaps differ by {:.2g} "
        "rad RMS, {:.0f} % of what they leave): {}",
        labels_of(s, out, lead), g.difference_rms_rad,
        100.0 * g.difference_rms_rad / std::max(g.residual_rms_rad, 1e-300), g.separate_by));
  }
  // A joint whose own gap's leading explanation is ambiguous (and explains at least
  // min_shrinkage_percent of it): named with its alternatives and what would separate them, with
  // the evidence's strength (the leading cause overall may hide it, e.g. a constant offset that a
  // multi-joint candidate also absorbs).
  for (const JointFinding& f : out.joint_findings) {
    const CandidateResult& leader = out.candidates[f.leading.front()];
    if (f.leading.size() < 2 || f.leading == lead ||
        leader.joint_shrinkage_percent < o.min_shrinkage_percent)
      continue;
    out.verdict += fmt::format(
        " On joint {} alone, its gap's leading explanation ({:.0f} % of its held-out gap, p = "
        "{:.3f}{}) is ambiguous: {}.",
        s.joint_names[f.joint], leader.joint_shrinkage_percent, leader.joint_p_value,
        f.supported ? "" : ", weak evidence", members_in_words(s, out, f.leading));
    out.measure_next.push_back(
        fmt::format("to tell {} apart: {}", labels_of(s, out, f.leading), f.separate_by));
  }
  std::vector<std::string> unsupported;
  for (const auto& c : out.candidates)
    if (!c.supported && !c.joint_supported && c.fit.joint == top.fit.joint)
      unsupported.push_back(to_string(c.fit.kind));
  if (!unsupported.empty())
    out.verdict += fmt::format(" Not supported on joint {}: {}.", s.joint_names[top.fit.joint],
                               fmt::join(unsupported, ", "));
  // Weak evidence: a different effect explains nearly as much, or the best explains little.
  for (std::size_t c = 1; c < out.candidates.size(); ++c) {
    const auto& r = out.candidates[c];
    if (!r.supported) break;
    if (std::find(lead.begin(), lead.end(), c) != lead.end()) continue;
    if (top.shrinkage_percent - r.shrinkage_percent < 5.0)
      out.measure_next.push_back(
          fmt::format("{} explains nearly as much ({:.0f} % vs {:.0f} %); to tell them apart: {}",
                      candidate_label(s, r.fit), r.shrinkage_percent, top.shrinkage_percent,
                      separating_measurement(s, top.fit, r.fit)));
  }
  if (top.shrinkage_percent < 30.0)
    out.measure_next.push_back(
        fmt::format("the best candidate explains only {:.0f} % of the gap: measure {}",
                    top.shrinkage_percent, what_to_measure(top.fit.kind)));
}

}  // namespace imscal::eval
