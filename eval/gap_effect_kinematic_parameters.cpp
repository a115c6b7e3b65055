// Kinematic parameters, an error of the IMS chain (columns of GapSignals::ims_chain_columns, only
// with a robot model; the joint-space map -Jb^-1 of a flange pose error, eval/gap_signals.hpp):
// DH a, alpha, d of one link i = 1..6 (3 parameters, link chosen as the shape; the joint zero
// offsets are zero_offset), the same parameters on all joints, fitted to all joints' gaps at once;
// its joint is the one where its modelled gap is largest.
#include <fmt/format.h>

#include <algorithm>

#include "eval/gap_effect_shapes.hpp"

namespace imscal::eval {
namespace {

std::vector<CandidateShape> shapes(const ShapeContext& x) {
  // One candidate for all joints: only joint 0 returns it.
  if (x.joint != 0 || x.s.ims_chain_columns.size() != x.nj) return {};
  const auto dh = [&](std::size_t j) -> const Eigen::MatrixXd& {
    return x.s.ims_chain_columns[j].dh;
  };
  std::vector<CandidateShape> out;
  for (int link = 0; link < 6; ++link) {
    std::vector<int> cols;
    std::vector<std::string> names;
    const char* what[3] = {"a", "alpha", "d"};
    const char* unit[3] = {"m", "rad", "m"};
    for (int p = 0; p < 3; ++p) {
      // A parameter that moves no joint's gap by 1e-9 rad per unit has no signature here
      // (e.g. d_1 for a base offset along axis 1).
      double largest = 0.0;
      for (std::size_t j = 0; j < x.nj; ++j)
        largest = std::max(largest, rms_of(dh(j).col(3 * link + p)));
      if (largest < 1e-9) continue;
      cols.push_back(3 * link + p);
      names.push_back(fmt::format("d{}{}_{}", what[p], link + 1, unit[p]));
    }
    if (!cols.empty())
      out.push_back(x.shared(fmt::format("DH a/alpha/d of link {}", link + 1), dh, cols, names));
  }
  return out;
}

}  // namespace

const EffectDefinition kKinematicParametersEffect{
    .kind = EffectKind::kKinematicParameters,
    .name = "kinematic_parameters",
    .acts_through_dynamics = false,
    .what_to_measure =
        "static poses spread over the workspace with an external reference (laser "
        "tracker), or a kinematic calibration (the error depends on the pose, not "
        "on the motion)",
    .shapes = shapes,
    .size_in_words = size_of_every_parameter,
};

}  // namespace imscal::eval
