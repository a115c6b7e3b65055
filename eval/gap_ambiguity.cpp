#include "eval/gap_ambiguity.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <utility>

namespace imscal::eval {
namespace {

// The candidate's modelled gap at (joint, sample), 0 where it does not act.
double modelled(const CandidateFit& f, std::size_t joint, std::size_t k) {
  return joint < f.prediction.size() && !f.prediction[joint].empty() ? f.prediction[joint][k] : 0.0;
}

// The parameters a fit spends on its own effect (without the coupling's).
std::size_t own_parameters(const CandidateFit& f) {
  return f.parameter_names.size() - f.coupling_parameter_count;
}

}  // namespace

const char* what_to_measure(EffectKind kind) {
  return effect_definition(kind).what_to_measure;
}

std::string separating_measurement(const GapSignals& s, const CandidateFit& a,
                                   const CandidateFit& b) {
  // A measurement one of the two effects names for the other on the same joint.
  if (a.joint == b.joint)
    for (const auto& [x, y] : {std::pair{&a, &b}, std::pair{&b, &a}}) {
      const auto separate = effect_definition(x->kind).separate_from;
      const std::string text = separate ? separate(y->kind, s.joint_names[a.joint]) : "";
      if (!text.empty()) return text;
    }
  if (a.kind == b.kind)
    return fmt::format("for {} on {} and on {}: {}", to_string(a.kind), s.joint_names[a.joint],
                       s.joint_names[b.joint], what_to_measure(a.kind));
  return fmt::format("for {}: {}; for {}: {}", to_string(a.kind), what_to_measure(a.kind),
                     to_string(b.kind), what_to_measure(b.kind));
}

std::vector<AmbiguityGroup> ambiguity_groups(const GapSignals& s,
                                             const std::vector<const CandidateFit*>& ranked,
                                             const std::vector<bool>& eligible,
                                             const std::vector<std::size_t>& heldout,
                                             std::optional<std::size_t> joint) {
  std::vector<std::size_t> joints;
  for (std::size_t j = 0; j < s.joint_count(); ++j)
    if (!joint || *joint == j) joints.push_back(j);
  std::vector<AmbiguityGroup> groups;
  std::vector<std::size_t> heads;  // ranked indices of the groups' heads (also singletons)
  std::vector<int> group_of_head;
  for (std::size_t c = 0; c < ranked.size(); ++c) {
    if (!eligible[c]) continue;
    const CandidateFit& fc = *ranked[c];
    bool joined = false;
    for (std::size_t h = 0; h < heads.size() && !joined; ++h) {
      const CandidateFit& fh = *ranked[heads[h]];
      if (own_parameters(fc) > own_parameters(fh)) continue;
      double diff = 0.0, residual = 0.0;
      for (std::size_t j : joints)
        for (std::size_t k : heldout) {
          const double ph = modelled(fh, j, k), r = s.gap_rad[j][k] - ph;
          const double d = ph - modelled(fc, j, k);
          diff += d * d;
          residual += r * r;
        }
      if (residual <= 0.0 || diff > kAmbiguityFraction * kAmbiguityFraction * residual) continue;
      const double m = double(std::max<std::size_t>(heldout.size() * joints.size(), 1));
      if (group_of_head[h] < 0) {
        group_of_head[h] = int(groups.size());
        AmbiguityGroup g;
        g.members = {heads[h]};
        g.residual_rms_rad = std::sqrt(residual / m);
        groups.push_back(std::move(g));
      }
      AmbiguityGroup& g = groups[std::size_t(group_of_head[h])];
      g.members.push_back(c);
      g.difference_rms_rad = std::max(g.difference_rms_rad, std::sqrt(diff / m));
      joined = true;
    }
    if (!joined) {
      heads.push_back(c);
      group_of_head.push_back(-1);
    }
  }
  for (AmbiguityGroup& g : groups) {
    std::vector<std::string> ways;
    for (std::size_t i = 1; i < g.members.size(); ++i)
      ways.push_back(separating_measurement(s, *ranked[g.members[0]], *ranked[g.members[i]]));
    g.separate_by = fmt::format("{}", fmt::join(ways, "; "));
  }
  return groups;
}

}  // namespace imscal::eval
