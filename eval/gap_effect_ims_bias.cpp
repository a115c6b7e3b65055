// IMS bias, an error of the IMS chain (as eval/gap_effect_kinematic_parameters.cpp): gyro rate
// bias about the flange axes (3), an attitude drift.
#include "eval/gap_effect_shapes.hpp"

namespace imscal::eval {
namespace {

std::vector<CandidateShape> shapes(const ShapeContext& x) {
  // One candidate for all joints: only joint 0 returns it.
  if (x.joint != 0 || x.s.ims_chain_columns.size() != x.nj) return {};
  const auto b = [&](std::size_t j) -> const Eigen::MatrixXd& {
    return x.s.ims_chain_columns[j].gyro_bias;
  };
  return {x.shared("gyro bias about the flange axes", b, {0, 1, 2},
                   {"bx_rad_s", "by_rad_s", "bz_rad_s"})};
}

}  // namespace

const EffectDefinition kImsBiasEffect{
    .kind = EffectKind::kImsBias,
    .name = "ims_bias",
    .acts_through_dynamics = false,
    .what_to_measure =
        "a longer rest of the IMS before and after the path, and rests during it "
        "(the rests bound the attitude drift)",
    .shapes = shapes,
    .size_in_words = size_of_every_parameter,
};

}  // namespace imscal::eval
