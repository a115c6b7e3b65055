#include "eval/gap_ambiguity.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

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
    case EffectKind::kClockOffset:
      return "sharp starts and stops of several joints with both streams stamped by one clock (a "
             "common offset shifts every joint's error by the same time)";
    case EffectKind::kImsBias:
      return "a longer rest of the IMS before and after the path, and rests during it (the "
             "rests bound the attitude drift)";
  }
  return "";
}

std::string separating_measurement(const GapSignals& s, const CandidateFit& a,
                                   const CandidateFit& b) {
  const auto is = [&](EffectKind x, EffectKind y) {
    return (a.kind == x && b.kind == y) || (a.kind == y && b.kind == x);
  };
  if (is(EffectKind::kBacklash, EffectKind::kZeroOffset) && a.joint == b.joint) {
    const std::string& j = s.joint_names[a.joint];
    return fmt::format(
        "a path on which the gear torque of {} changes sign (its gravity load reversed by another "
        "pose of the arm, or reversals fast enough that their inertia torque outweighs it): "
        "backlash then shows as a step of the full play where the torque reverses, a zero offset "
        "stays the same constant",
        j);
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
