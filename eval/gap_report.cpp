#include "eval/gap_report.hpp"
#include "core/units.hpp"

#include <fmt/format.h>

namespace imscal::eval {
namespace {

nlohmann::json shares_json(const std::vector<GapShare>& shares) {
  nlohmann::json a = nlohmann::json::array();
  for (const auto& s : shares) {
    nlohmann::json o = {{"label", s.label},
                        {"energy_share", s.energy_share},
                        {"time_share", s.time_share},
                        {"rms_rad", s.rms_rad}};
    if (s.outside_identified_range) o["outside_identified_range"] = true;
    a.push_back(o);
  }
  return a;
}

// Each joint's own test (eval/gap_joint_significance.hpp), one line per joint.
std::string significance_text(const GapSignals& s, const Diagnosis& d) {
  std::string t;
  t += "\nSignificance per joint (gap RMS against its noise reference; its leading candidate at "
       "the Sidak level over the joints)\n";
  for (const auto& js : d.joint_significance)
    t += fmt::format(
        "  {:<4} RMS {:.3g} rad, {:.3g} times its noise reference {:.3g} rad (floor "
        "{:.3g} rad); leader p {:.4f} at level {:.4f}  {}\n",
        s.joint_names[js.joint], js.rms_rad, js.excess, js.noise_reference_rad, js.noise_floor_rad,
        js.leader_p_value, js.corrected_alpha,
        js.significant() ? "significant" : "not significant");
  return t;
}

}  // namespace

nlohmann::json diagnosis_json(const GapSignals& s, const Diagnosis& d) {
  using nlohmann::json;
  json joints = json::array();
  for (const auto& j : d.where.joints)
    joints.push_back({{"joint", j.joint},
                      {"rms_rad", j.rms_rad},
                      {"energy_share", j.energy_share},
                      {"direction_offset_rad", j.direction_offset_rad},
                      {"by_phase", shares_json(j.by_phase)},
                      {"by_band", shares_json(j.by_band)},
                      {"by_cell", shares_json(j.by_cell)},
                      {"by_direction", shares_json(j.by_direction)}});
  json candidates = json::array();
  for (const auto& c : d.candidates) {
    json params = json::array();
    for (Eigen::Index i = 0; i < c.fit.parameters.size(); ++i)
      params.push_back({{"name", c.fit.parameter_names[std::size_t(i)]},
                        {"value", c.fit.parameters[i]},
                        {"sigma", c.fit.sigma[i]}});
    json coupled = json::array();
    for (std::size_t j : c.fit.coupled_joints) coupled.push_back(s.joint_names[j]);
    candidates.push_back(
        {{"effect", to_string(c.fit.kind)},
         {"joint", s.joint_names[c.fit.joint]},
         {"shape", c.fit.shape},
         {"coupled_joints", coupled},
         {"coupling", c.fit.coupling},
         {"parameters", params},
         {"size", c.fit.size_text},
         {"training_rms_rad", c.fit.training_rms_rad},
         {"heldout_shrinkage_percent", c.shrinkage_percent},
         {"heldout_joint_shrinkage_percent", c.joint_shrinkage_percent},
         {"p_value", c.p_value},
         {"supported", c.supported},
         {"joint_p_value", c.joint_p_value},
         {"joint_supported", c.joint_supported},
         {"ambiguity_group", c.ambiguity_group >= 0 ? json(c.ambiguity_group) : json(nullptr)}});
  }
  const auto labels = [&](const std::vector<std::size_t>& members) {
    json a = json::array();
    for (std::size_t m : members) a.push_back(candidate_label(s, d.candidates[m].fit));
    return a;
  };
  json groups = json::array();
  for (const auto& g : d.ambiguity_groups)
    groups.push_back({{"members", labels(g.members)},
                      {"difference_rms_rad", g.difference_rms_rad},
                      {"residual_rms_rad", g.residual_rms_rad},
                      {"separate_by", g.separate_by}});
  json findings = json::array();
  for (const auto& f : d.joint_findings) {
    const CandidateResult& leader = d.candidates[f.leading.front()];
    findings.push_back({{"joint", s.joint_names[f.joint]},
                        {"leading", labels(f.leading)},
                        {"heldout_joint_shrinkage_percent", leader.joint_shrinkage_percent},
                        {"joint_p_value", leader.joint_p_value},
                        {"supported", f.supported},
                        {"separate_by", f.separate_by}});
  }
  json model_error = json::array();
  for (std::size_t j = 0; j < d.model_error.size(); ++j) {
    const ModelErrorModel& m = d.model_error[j];
    json response = json::array();
    for (const auto& p : m.response)
      response.push_back({{"frequency_hz", p.frequency_hz},
                          {"magnitude_rad_per_rad", p.magnitude},
                          {"phase_rad", p.phase_rad},
                          {"magnitude_sigma", p.magnitude_sigma},
                          {"band_lower", p.lower},
                          {"band_upper", p.upper},
                          {"significant", p.significant}});
    std::vector<double> taps(m.taps.data(), m.taps.data() + m.taps.size()),
        tap_sigma(m.tap_sigma.data(), m.tap_sigma.data() + m.tap_sigma.size());
    model_error.push_back({{"joint", s.joint_names[j]},
                           {"input", "q_desired_rad"},
                           {"tap_period_s", m.tap_period_s},
                           {"taps_rad_per_rad", taps},
                           {"tap_sigma", tap_sigma},
                           {"offset_rad", m.offset_rad},
                           {"heldout_explained_percent", m.heldout_explained_percent},
                           {"significant", m.significant},
                           {"frequency_response", response}});
  }
  json combination = json::array();
  for (const auto& c : d.combination)
    combination.push_back({{"added", c.label},
                           {"heldout_shrinkage_percent", c.shrinkage_percent},
                           {"p_value", c.p_value}});
  json significance = json::array();
  for (const auto& js : d.joint_significance)
    significance.push_back({{"joint", s.joint_names[js.joint]},
                            {"rms_rad", js.rms_rad},
                            {"noise_floor_rad", js.noise_floor_rad},
                            {"noise_reference_rad", js.noise_reference_rad},
                            {"excess", js.excess},
                            {"corrected_alpha", js.corrected_alpha},
                            {"leader_p_value", js.leader_p_value},
                            {"leader_shrinkage_percent", js.leader_shrinkage_percent},
                            {"by_candidate", js.by_candidate},
                            {"far_above_noise", js.far_above_noise},
                            {"significant", js.significant()}});
  json per_joint = json::object();
  for (const auto& j : d.where.joints) per_joint[j.joint] = j.rms_rad;
  json not_supported = json::array();
  for (const auto& c : d.candidates)
    if (!c.supported) not_supported.push_back(candidate_label(s, c.fit));
  return {{"schema", "imscal-gap-diagnosis"},
          {"schema_version", 2},
          {"samples", s.sample_count()},
          {"cycle_s", s.cycle_s},
          {"gap_rms_rad", d.where.rms_rad},
          {"gap_rms_per_joint_rad", per_joint},
          {"heldout_gap_rms_rad", d.heldout_rms_rad},
          {"heldout_gap_rms_modelled_rad", d.heldout_rms_modelled_rad},
          {"significant_gap", d.significant_gap},
          {"measurement", measurement_json(s, d.measurement)},
          {"refinement",
           {{"applied", d.refinement.applied},
            {"heldout_shrinkage_percent", d.refinement.shrinkage_percent},
            {"changes", d.refinement.changes},
            {"simulations", d.refinement.simulations}}},
          {"verdict", d.verdict},
          {"measure_next", d.measure_next},
          {"band_edges_hz", d.where.band_edges_hz},
          {"where", joints},
          {"model_error", model_error},
          {"candidates", candidates},
          {"combination", combination},
          {"leading_group", labels(leading_group(d))},
          {"ambiguity_groups", groups},
          {"joint_findings", findings},
          {"joint_significance", significance},
          {"not_supported", not_supported}};
}

std::string diagnosis_text(const GapSignals& s, const Diagnosis& d) {
  std::string t = "imscal gap diagnosis\n====================\n\nGap RMS per joint:";
  for (const auto& j : d.where.joints)
    t += fmt::format(" {} {:.3g} rad ({:.1f} arcsec);", j.joint, j.rms_rad,
                     j.rms_rad * kArcsecPerRad);
  t += "\n\n" + d.verdict + "\n";
  for (const auto& m : d.measure_next) t += "  - measure next: " + m + "\n";
  t += fmt::format("\nWhere (gap RMS {:.3g} rad = {:.2f} arcsec, {} samples)\n", d.where.rms_rad,
                   d.where.rms_rad * kArcsecPerRad, s.sample_count());
  for (const auto& j : d.where.joints) {
    t += fmt::format(
        "  {:<4} RMS {:.3g} rad, {:5.1f} % of the gap energy, direction offset {:.3g} rad\n",
        j.joint, j.rms_rad, 100.0 * j.energy_share, j.direction_offset_rad);
    auto line = [&](const char* what, const std::vector<GapShare>& v) {
      t += fmt::format("       {:<10}", what);
      for (const auto& x : v)
        t += fmt::format(" {}{} {:.0f}%/{:.0f}%t", x.label,
                         x.outside_identified_range ? " (outside)" : "", 100.0 * x.energy_share,
                         100.0 * x.time_share);
      t += "\n";
    };
    line("phase", j.by_phase);
    line("band", j.by_band);
    line("cell", j.by_cell);
    line("direction", j.by_direction);
  }
  t += "\nModel-error model (FIR from q_d to the gap; response |G| in rad/rad with its 2-sigma "
       "band)\n";
  for (std::size_t j = 0; j < d.model_error.size(); ++j) {
    const ModelErrorModel& m = d.model_error[j];
    std::vector<std::string> significant;
    double peak = 0.0, f_peak = 0.0;
    for (const auto& p : m.response) {
      if (p.significant) significant.push_back(fmt::format("{:.2g}", p.frequency_hz));
      if (p.magnitude > peak) peak = p.magnitude, f_peak = p.frequency_hz;
    }
    t += fmt::format("  {:<4} explains {:5.1f} % of the held-out gap; ", s.joint_names[j],
                     m.heldout_explained_percent);
    t += significant.empty()
             ? std::string("G differs from 0 at no frequency (no linear dynamic gap)")
             : fmt::format("significant at {} Hz", fmt::join(significant, ", "));
    t += fmt::format("; peak |G| {:.3g} at {:.2g} Hz\n", peak, f_peak);
  }
  t += "\nCandidates (held-out shrinkage of the gap, all joints; best first; [g] its ambiguity "
       "group)\n";
  for (const auto& c : d.candidates)
    t += fmt::format("  {:<36} {:6.1f} % (own joint {:6.1f} %)  p {:.3f}  {}{}  [{}] {}{}\n",
                     candidate_label(s, c.fit), c.shrinkage_percent, c.joint_shrinkage_percent,
                     c.p_value, c.supported ? "supported    " : "not supported",
                     c.ambiguity_group >= 0 ? fmt::format(" [{}]", c.ambiguity_group) : "",
                     c.fit.shape, c.fit.size_text,
                     c.fit.coupling.empty() ? "" : "; coupled " + c.fit.coupling);
  t += "\nAmbiguity groups (modelled gaps the data cannot tell apart: they differ by at most a "
       "tenth of what they leave)\n";
  if (d.ambiguity_groups.empty()) t += "  none\n";
  for (std::size_t g = 0; g < d.ambiguity_groups.size(); ++g) {
    const auto& grp = d.ambiguity_groups[g];
    std::vector<std::string> l;
    for (std::size_t m : grp.members) l.push_back(candidate_label(s, d.candidates[m].fit));
    t += fmt::format("  [{}] {}: differ by {:.3g} rad RMS, leave {:.3g} rad; to tell apart: {}\n",
                     g, fmt::join(l, " / "), grp.difference_rms_rad, grp.residual_rms_rad,
                     grp.separate_by);
  }
  t += "\nPer joint (its candidates ranked on its own held-out gap)\n";
  for (const auto& f : d.joint_findings) {
    const CandidateResult& leader = d.candidates[f.leading.front()];
    std::vector<std::string> l;
    for (std::size_t m : f.leading) l.push_back(candidate_label(s, d.candidates[m].fit));
    t += fmt::format("  {:<4} {:<44} {:6.1f} % of its gap  p {:.3f}  {}\n", s.joint_names[f.joint],
                     fmt::format("{}", fmt::join(l, " / ")), leader.joint_shrinkage_percent,
                     leader.joint_p_value, f.supported ? "supported" : "not supported");
  }
  t += significance_text(s, d);
  t += "\nJoint model (forward-backward selection)\n";
  for (const auto& c : d.combination)
    t += fmt::format("  + {:<34} cumulative {:6.1f} %  p {:.3f}\n", c.label, c.shrinkage_percent,
                     c.p_value);
  t += fmt::format("Held-out gap RMS {:.3g} rad -> {:.3g} rad once modelled\n", d.heldout_rms_rad,
                   d.heldout_rms_modelled_rad);
  return t;
}

}  // namespace imscal::eval
